#!/bin/sh
# The ground truth's scaling over threads (issue 30 item 2; docs/reference.md 2.8): renders the
# scene at SIZE with each thread count in THREADS, one after the other, and prints per run the
# wall time (the render's own phases), its CPU time, the speed-up over the first count, the
# serial fraction and the speed-up Amdahl's law predicted from the first run, then each run's
# phase table (`godrays reference --phases`); every image must have the same R, G, B values as
# the first (`godrays compare`: max |t - r| 0), whatever the thread count.
# Made for a machine with many cores that lacks Debian's tools (the lent GPU machine: only the
# binary, packed by ../shared/tools/carry-build, and a POSIX shell with awk are needed).
# Usage: scripts/truth_scaling.sh [BINARY]
# Environment: THREADS ("2 4 8 16"), SIZE (640x360), SCENE (data/scenes/default.json), OUT (a
# folder for the EXR files; default a temporary one, removed).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/build/godrays}
scene=${SCENE:-$here/data/scenes/default.json}
size=${SIZE:-640x360}
threads=${THREADS:-2 4 8 16}
if [ -n "${OUT:-}" ]; then out=$OUT; mkdir -p "$out"; else out=$(mktemp -d); trap 'rm -rf "$out"' EXIT; fi
[ -x "$bin" ] || { echo "truth_scaling.sh: $bin is not an executable (build it, or give BINARY)" >&2; exit 2; }
cores=$(nproc 2>/dev/null || echo "?")
model=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2 | sed 's/^ *//' || true)
echo "machine: ${model:-unknown CPU}, $cores cores; scene $scene at $size; threads: $threads"
echo "| threads | wall s | CPU s | speed-up | serial fraction | Amdahl from the first | same R, G, B as the first |"
echo "|---|---|---|---|---|---|---|"
first=
for n in $threads; do
    "$bin" reference "$scene" --size "$size" --threads "$n" -q --no-preview --phases -o "$out/t$n.exr" >"$out/phases$n.txt"
    # the "all" row: wall and CPU seconds of the phases; the serial fraction's line
    wall=$(awk '$1 == "all" { print $2 }' "$out/phases$n.txt")
    cpu=$(awk '$1 == "all" { print $3 }' "$out/phases$n.txt")
    sf=$(awk '/^serial fraction/ { print $3 / 100 }' "$out/phases$n.txt")
    if [ -z "$first" ]; then
        first=$n wall0=$wall sf0=$sf same="(the first)"
    else
        max=$("$bin" compare "$out/t$first.exr" "$out/t$n.exr" | awk '$1 == "max" { print $NF }')
        if [ "$max" = 0 ]; then same=yes; else same="NO (max |t - r| $max)"; fi
    fi
    echo "$n $wall $cpu $first $wall0 $sf0 $sf" | awk -v same="$same" '{
        n = $1; w = $2; c = $3; n0 = $4; w0 = $5; s0 = $6; s = $7
        pred = 1 / (s0 + (1 - s0) * n0 / n)
        printf "| %d | %.2f | %.1f | %.2fx | %.2f %% | %.2fx | %s |\n", n, w, c, w0 / w, 100 * s, pred, same }'
done
for n in $threads; do
    echo
    echo "--threads $n:"
    cat "$out/phases$n.txt"
done
