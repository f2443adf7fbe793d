#!/bin/sh
# Benchmark of the real-time shafts (docs/benchmarks.md, "Real-time shafts"): renders the
# default scene in several variants, each 10 times in one GL context, and prints one
# markdown table row per variant from the medians `godrays shafts --repeat` reports.
# Usage: scripts/bench_shafts.sh [BINARY] [extra godrays shafts options, e.g. --gl-platform device]
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/build/godrays}
[ $# -gt 0 ] && shift
scene=$here/data/scenes/default.json
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" info 2>/dev/null | grep -i -E '^ *(OpenGL|GL)' || true
echo "| variant | shafts | target | shadow ms | shafts ms | final ms | wall ms / render | fragments (overdraw) | VS invocations |"
echo "|---|---|---|---|---|---|---|---|---|"
row() {
    name=$1
    shift
    line=$("$bin" shafts "$scene" -o "$tmp/s.exr" --repeat 10 --no-preview "$@" 2>&1 | tail -1)
    echo "$line" | awk -v name="$name" '{
        for (i = 1; i <= NF; i++) {
            if ($(i+1) == "shafts," && $i ~ /^[0-9]+$/) n = $i
            if ($i == "target") tgt = $(i+1)
            if ($i == "shadow") sh = $(i+1)
            if ($i == "shafts" && $(i+1) ~ /^[0-9.]+,?$/) sf = $(i+1)
            if ($i == "final") fi_ = $(i+1)
            if ($i == "CPU" || $i == "wall") cpu = $(i+1)
            if ($i == "fragments" && $(i+1) ~ /^[0-9]/) fr = $(i+1)
            if ($i == "(overdraw") od = $(i+1)
            if ($i == "(VS") vs = $(i+2)
        }
        gsub(/[,;)]/, "", fr); gsub(/[,;)]/, "", sh); gsub(/[,;)]/, "", sf); gsub(/[,;)]/, "", fi_); gsub(/[,;)]/, "", od); gsub(/[,;)]/, "", vs)
        printf "| %s | %s | %s | %s | %s | %s | %s | %s (%s) | %s |\n", name, n, tgt, sh, sf, fi_, cpu, fr, od, vs
    }'
}
row "default (rgba8, N = 11, caps)" "$@"
row "target_format=rgba16f" --set shafts.target_format=rgba16f "$@"
row "caps=false" --set shafts.caps=false "$@"
row "target_scale=1 (full-size target)" --set shafts.target_scale=1 "$@"
row "N=33" --set shafts.N=33 "$@"
row "1280x720" --set camera.width=1280 --set camera.height=720 "$@"
row "1920x1080" --set camera.width=1920 --set camera.height=1080 "$@"
