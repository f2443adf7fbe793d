#!/bin/sh
# Issue 31, findings 4 and 5 at run time (docs/reliability.md, "Issue 31: user techniques and
# time limit"):
#   - a user shader with a 65535-step loop drawn many times (minutes of llvmpipe work) fails
#     at the per-render time limit with one line naming the technique, the pass and the limit
#     (GODRAYS_TIME_LIMIT or --time-limit; exit 1), instead of running for minutes with no
#     output: `timeout` turns the old behaviour into a failure here;
#   - `run` shows such a technique as a failed row and still compares the others (exit 3: the
#     report is complete, some technique failed; docs/report.md);
#   - a user technique whose render targets exceed GODRAYS_MAX_MEMORY is refused (exit 2)
#     before any is made (five 8192^2 rgba32f targets passed a 1 GB limit; ulimit -v keeps the
#     old binary from taking the 5 GB).
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
# the durations below are llvmpipe's (a GPU would finish the slow shader within the limit)
export GODRAYS_GL_PLATFORM=surfaceless LIBGL_ALWAYS_SOFTWARE=1

# a fragment loop of up to 65535 steps drawn many times (tests/techniques/slow_loop)
slow="$dir/slow"
cp -r "${GODRAYS_SOURCE_DIR:?}/tests/techniques/slow_loop" "$slow"
scene="$dir/scene.json"
small_scene "$scene" 32 18 '"reference": {"surface_res": 64, "sun_samples": 2, "batches": 2, "steps": 16, "spp": 1}'

# render: 3000 copies of 65535 steps on 32 x 18 pixels are minutes of llvmpipe work
t0=$(date +%s)
GODRAYS_TIME_LIMIT=2 timeout 60 "$bin" render slow_loop "$scene" --technique-dir "$slow" -o "$dir/s.exr" \
    >"$dir/out" 2>"$dir/err"
rc=$?
t1=$(date +%s)
if [ $rc -eq 1 ] && [ "$(wc -l <"$dir/err")" -eq 1 ] && [ ! -e "$dir/s.exr" ] &&
    grep -qF "slow_loop: passes[0] 'spin': not done after the time limit of 2 s (GODRAYS_TIME_LIMIT" "$dir/err" &&
    [ $((t1 - t0)) -le 20 ]; then
    echo "ok: render stopped after $((t1 - t0)) s: $(cat "$dir/err")"
else
    echo "FAIL: render with GODRAYS_TIME_LIMIT=2: exit $rc (want 1; 124 = no limit) after $((t1 - t0)) s:"
    cat "$dir/err"; fail=1
fi
timeout 60 "$bin" render slow_loop "$scene" --technique-dir "$slow" --time-limit 1.5 -o "$dir/s.exr" \
    >"$dir/out" 2>"$dir/err"
rc=$?
if [ $rc -eq 1 ] && grep -qF "not done after the time limit of 1.5 s (--time-limit" "$dir/err"; then
    echo "ok: --time-limit 1.5: $(cat "$dir/err")"
else
    echo "FAIL: --time-limit 1.5: exit $rc"; cat "$dir/err"; fail=1
fi
expect 2 "--time-limit 0: expected a number of seconds" render slow_loop "$scene" --technique-dir "$slow" --time-limit 0 -o "$dir/s.exr"
GODRAYS_TIME_LIMIT=soon expect 2 "GODRAYS_TIME_LIMIT soon: expected a number of seconds" \
    render slow_loop "$scene" --technique-dir "$slow" -o "$dir/s.exr"
# a render well within the limit is unaffected
"$bin" render slow_loop "$scene" --technique-dir "$slow" --set slow_loop.copies=1 --set slow_loop.loops=16 \
    --time-limit 30 -o "$dir/fast.exr" >"$dir/out" 2>"$dir/err"
ck "a short render within the limit" test -s "$dir/fast.exr"

# run: the failed technique is a row of its own, the others are compared (copies=100: about
# 12 s of work, left running in the background while the ground truth renders)
GODRAYS_TIME_LIMIT=1 timeout 300 "$bin" run "$scene" --technique-dir "$slow" --techniques shafts,slow_loop \
    --set slow_loop.copies=100 -q -o "$dir/rep" >"$dir/out" 2>"$dir/err"
rc=$?
ck "run exits 3 with a failed technique (got $rc)" [ $rc -eq 3 ]
ck "run warns about the failed technique, even with -q" grep -qF "godrays run: warning: slow_loop FAILED: slow_loop: passes[0] 'spin': not done after the time limit of 1 s" "$dir/err"
ck "run's summary has a failed row" grep -qE "^  FAIL slow_loop .*not done after the time limit" "$dir/out"
ck "run still ranks shafts" grep -qE "^  1    shafts" "$dir/out"
ck "run still writes the report" test -s "$dir/rep/index.html"
ck "run writes no image of the failed technique" test ! -e "$dir/rep/slow_loop.exr"

# memory: five 8192^2 rgba32f targets (5 GiB) under a 1 GiB limit
big="$dir/big"
mkdir -p "$big"
cat >"$big/manifest.json" <<'JSON'
{"version": 1, "name": "big_targets", "description": "five 8192^2 rgba32f targets",
 "targets": {"a": {"size": [8192, 8192], "format": "rgba32f"}, "b": {"size": [8192, 8192], "format": "rgba32f"},
             "c": {"size": [8192, 8192], "format": "rgba32f"}, "d": {"size": [8192, 8192], "format": "rgba32f"},
             "e": {"size": [8192, 8192], "format": "rgba32f"}, "out": {"format": "rgba32f"}},
 "passes": [{"name": "only", "fragment": "f.frag", "target": "out"}]}
JSON
printf 'out vec4 o_color;\nvoid main() { o_color = vec4(1.0); }\n' >"$big/f.frag"
# ulimit -v keeps a binary without the check from taking the 5 GB; a sanitizer build reserves
# terabytes of shadow address space and aborts under any such limit, so it runs without one
# (the check refuses before anything is allocated either way)
asan=0
ldd "$bin" 2>/dev/null | grep -q libasan && asan=1
(
    [ $asan -eq 1 ] || ulimit -v 3000000
    GODRAYS_MAX_MEMORY=1G "$bin" render big_targets "$scene" --technique-dir "$big" -o "$dir/b.exr" >"$dir/out" 2>"$dir/err"
    echo $? >"$dir/rc"
)
rc=$(cat "$dir/rc")
if [ "$rc" -eq 2 ] && grep -qF "technique big_targets needs about 5.00 GiB (6 render targets, readback and harness inputs), over the memory limit of 1.00 GiB (GODRAYS_MAX_MEMORY)" "$dir/err"; then
    echo "ok: $(cat "$dir/err")"
else
    echo "FAIL: big targets under GODRAYS_MAX_MEMORY=1G: exit $rc (want 2)"; cat "$dir/err"; fail=1
fi
exit $fail
