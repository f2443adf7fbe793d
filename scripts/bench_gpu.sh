#!/bin/sh
# GPU benchmark of every real-time technique (docs/benchmarks.md, "Cost counters and ladders"):
# renders each technique's `pareto` ladder (`godrays techniques --json`) and its scene defaults at
# SIZE with `godrays render --repeat` (warm medians: the first render of a context is dropped by
# the median of REPEAT renders) and prints GL_RENDERER, then one line per point: GPU ms per pass
# (GL_TIME_ELAPSED), wall ms and the cost counters per pass (docs/techniques.md "Cost counters";
# '*' marks a counter read from a GL query). Nothing here needs a GPU: on llvmpipe the times are
# the CPU rasterizer's, the counters the same as on any GPU.
#
# Usage: scripts/bench_gpu.sh [BINARY] [extra render options, e.g. --gl-platform device]
# Environment: SIZE (1920x1080), REPEAT (30), SCENE (data/scenes/default.json), TECHS (a
# space-separated subset; default: every technique), QUICK=1 (only the ladders' quick points),
# DEFAULTS_ONLY=1 (only the scene defaults), BASE=BINARY (also render each technique's defaults
# with BINARY in the same run, alternating, and print the wall-time ratio new / base).
# On a machine without Debian's libraries (../shared/tools/carry-build packs build/godrays with
# its own library closure): build with `cmake -DGODRAYS_OIIO_MODULE=OFF` first, so that
# OpenImageIO is in that closure rather than in the module loaded on demand (docs/images.md).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/build/godrays}
[ $# -gt 0 ] && shift
size=${SIZE:-1920x1080}
repeat=${REPEAT:-30}
scene=${SCENE:-$here/data/scenes/default.json}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" info 2>/dev/null | grep -E '^OpenGL (renderer|version)' || true
echo "size $size, median of $repeat renders per point, scene $scene"
"$bin" techniques --json >"$tmp/t.json"
python3 - "$tmp/t.json" "${TECHS:-}" "${QUICK:-0}" "${DEFAULTS_ONLY:-0}" >"$tmp/points" <<'PY'
import json, sys
techs = json.load(open(sys.argv[1]))["techniques"]
only = sys.argv[2].split()
for t in techs:
    if only and t["name"] not in only:
        continue
    print(t["name"], "-")  # the scene's defaults
    if sys.argv[4] == "1":
        continue
    for l in t["ladder"] or []:
        if sys.argv[3] != "1" or l["quick"]:
            print(t["name"], l["settings"])
PY
# wall ms of a render line ("...; wall 12.345 ms; ...")
wall() { sed -n 's/.*; wall \([0-9.]*\) ms.*/\1/p'; }
while read -r tech settings; do
    sets=""
    if [ "$settings" != "-" ]; then
        for kv in $(echo "$settings" | tr ',' ' '); do sets="$sets --set $tech.$kv"; done
    fi
    # shellcheck disable=SC2086
    line=$("$bin" render "$tech" "$scene" --size "$size" --repeat "$repeat" --no-preview -o "$tmp/o.exr" $sets "$@" 2>&1 |
           tail -1) || line="FAILED: $line"
    echo "$tech [${settings}]: ${line#*: }"
    if [ -n "${BASE:-}" ] && [ "$settings" = "-" ]; then
        # shellcheck disable=SC2086
        bl=$("$BASE" render "$tech" "$scene" --size "$size" --repeat "$repeat" --no-preview -o "$tmp/b.exr" "$@" 2>&1 | tail -1)
        nw=$(echo "$line" | wall)
        bw=$(echo "$bl" | wall)
        echo "$tech [base]: wall $bw ms (base) vs $nw ms (new): ratio new / base $(awk -v a="$nw" -v b="$bw" 'BEGIN { if (b > 0) printf "%.3f", a / b; else print "n/a" }')"
    fi
done <"$tmp/points"
