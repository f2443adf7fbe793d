#!/bin/sh
# The ground truth against the reference main of issue 30 (docs/benchmarks.md, "Issue 30"):
# builds commit BASE (default 1eea25b, "today's main" of the issue) from source beside this
# tree's build, renders the default scene with both, interleaved (main, this, main, this, ...)
# on the same machine, and prints each run's CPU time (user + sys: the figure on a shared
# VM, whose wall time drifts), the CPU-time ratio (medians), both renders' quality figures
# from their own metadata (pixels with stderr <= 1 %, surface bias), their agreement with
# each other, and this tree's per-phase table (godrays:phase.*, serial fraction).
# Usage: scripts/bench_truth.sh [RUNS (2)] [SIZE (640x360)] [extra godrays reference options]
# Environment: BASE (commit), BENCH_DIR (where the base is built; kept between runs), BIN (this
# tree's binary; default build/godrays, built if missing), SCENE, THIS_OPTS (options for this
# tree's renders only, e.g. settings the base does not have: THIS_OPTS="--set
# reference.batches=4 --set reference.antithetic=true").
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-2}
size=${2:-640x360}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] && shift
base=${BASE:-1eea25b}
dir=${BENCH_DIR:-${TMPDIR:-/tmp}/godrays-bench-truth-$base}
bin=${BIN:-$here/build/godrays}
scene=${SCENE:-$here/data/scenes/default.json}
export GODRAYS_CACHE="$dir/cache" # never a cached truth: renders only (reference does not read it)

if [ ! -x "$dir/build/godrays" ]; then
    echo "building $base in $dir (the godrays target only)" >&2
    mkdir -p "$dir/src"
    git -C "$here" archive "$base" | tar -x -C "$dir/src"
    cmake -S "$dir/src" -B "$dir/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$dir/build" --target godrays -j2 >/dev/null
fi
if [ ! -x "$bin" ]; then
    cmake -S "$here" -B "$here/build" -G Ninja >/dev/null
    cmake --build "$here/build" --target godrays -j2 >/dev/null
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
meta() { iinfo -v "$1" | awk -v k="godrays:$2:" '$1 == k { print $2 }'; }

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores; load at start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "| run | binary | CPU s (user+sys) | wall s | peak RSS MB | within 1 % | bias est. / measured order | steps/ray |"
echo "|---|---|---|---|---|---|---|---|"
i=1
while [ "$i" -le "$runs" ]; do
    for which in main this; do
        b=$dir/build/godrays
        extra=
        [ "$which" = this ] && b=$bin && extra=${THIS_OPTS:-}
        # shellcheck disable=SC2086 # THIS_OPTS is a list of words
        /usr/bin/time -f "%U %S %e %M" -o "$out/time" "$b" reference "$scene" --size "$size" -q --no-preview \
            -o "$out/$which$i.exr" "$@" $extra >/dev/null 2>&1
        read -r u s e m <"$out/time"
        cpu=$(echo "$u $s" | awk '{ printf "%.2f", $1 + $2 }')
        echo "$cpu" >>"$out/cpu_$which"
        f=$out/$which$i.exr
        echo "| $i | $which | $cpu | $e | $((m / 1024)) | $(meta "$f" frac_pixels_stderr_le_1pct) | $(meta "$f" bias_surface_rel_est) / $(meta "$f" bias_surface_rel_measured_order) | $(meta "$f" steps_mean) |"
    done
    i=$((i + 1))
done
median() { sort -n "$1" | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
mm=$(median "$out/cpu_main")
mt=$(median "$out/cpu_this")
echo
echo "CPU-time ratio this / main (medians): $(echo "$mt $mm" | awk '{ printf "%.3f (%.2f s / %.2f s)", $1 / $2, $1, $2 }')"
# the two images against each other (R, G, B): idiff's mean and largest differences
if command -v oiiotool >/dev/null; then
    echo "image means: main $(meta "$out/main1.exr" image_mean), this $(meta "$out/this1.exr" image_mean)"
    oiiotool "$out/main1.exr" --ch R,G,B -o "$out/a.exr" >/dev/null 2>&1 &&
        oiiotool "$out/this1.exr" --ch R,G,B -o "$out/b.exr" >/dev/null 2>&1 &&
        { idiff -fail 1 -warn 1 "$out/a.exr" "$out/b.exr" 2>&1 | grep -E 'Mean error|Max error' | sed 's/^ */  this vs main: /' || true; }
fi
echo
f=$out/this$runs.exr
echo "per phase (this tree, run $runs): | phase | wall s | CPU s | serial s |"
echo "|---|---|---|---|"
for p in beams grid pilot march probe stats other; do
    echo "| $p | $(meta "$f" "phase.$p.wall_s") | $(meta "$f" "phase.$p.cpu_s") | $(meta "$f" "phase.$p.serial_s") |"
done
echo "| all | $(meta "$f" phases_wall_s) | $(meta "$f" phases_cpu_s) | $(meta "$f" serial_s) |"
echo "this tree's error bars: $(meta "$f" stderr_dof) degrees of freedom${THIS_OPTS:+ (THIS_OPTS: $THIS_OPTS)}"
echo "serial fraction (wall with at most one thread busy / wall): $(meta "$f" serial_fraction); 8x8 block noise (max at pixel x y, p99, p95, median): $(meta "$f" block8_rel_stderr_max) at $(meta "$f" block8_rel_stderr_max_x) $(meta "$f" block8_rel_stderr_max_y), $(meta "$f" block8_rel_stderr_p99), $(meta "$f" block8_rel_stderr_p95), $(meta "$f" block8_rel_stderr_median)"
