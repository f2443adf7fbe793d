#!/bin/sh
# Every command that renders a ground truth does it through reference/truth.h, so `tune`,
# `sweep` and `pareto` keep the promises `reference` makes (docs/reliability.md):
#  a. the memory preflight: a ground truth estimated over --max-memory (or $GODRAYS_MAX_MEMORY)
#     is refused before any beam is built: exit 2, one line "the ground truth needs about ...
#     over the memory limit" (main: tune, sweep and pareto skipped the check and started);
#  b. Ctrl-C (SIGINT) or SIGTERM during their ground truth stops it within seconds: exit 1,
#     "interrupted while rendering the ground truth", nothing stored in the cache, no temporary
#     file left (main: killed at once with 130, the signal was not held).
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
small_scene s.json 16 9
pid=
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$dir"' EXIT

# ---- a: the memory preflight (surface_res 4096: about 18 GiB of beams) ----------------------
fine="--set reference.surface_res=4096"
expect 2 "over the memory limit of 1.00 GiB (--max-memory)" tune s.json -q -o t --params shafts.K $fine --max-memory 1G
expect 2 "the ground truth needs about" sweep s.json -q -o sw --param shafts.K=0.5:1:2 $fine --max-memory 1G
expect 2 "the ground truth needs about" pareto s.json -q -o p --quick --techniques shafts $fine --max-memory 1G
expect 2 "the ground truth needs about" run s.json -q -o r --techniques shafts $fine --max-memory 1G
GODRAYS_MAX_MEMORY=1G expect 2 "over the memory limit of 1.00 GiB (GODRAYS_MAX_MEMORY)" \
    tune s.json -q -o t --params shafts.K $fine
expect 2 "--max-memory lots: " tune s.json -q -o t --params shafts.K --max-memory lots
ck "no cache entry from a refused render" sh -c '! ls cache/reference-*.exr >/dev/null 2>&1'

# ---- b: a signal during the ground truth ---------------------------------------------------
# 8 x 8 pixels at 65536 samples per pixel per pass: a render of minutes
slow="--size 8x8 --set reference.spp=65536 --set reference.bias_probe=false"
. "$(dirname "$0")/wait.sh" # wait_gone, wait_for
signal_case() { # NAME SIGNAL ARGS...: NAME's message before its ground truth, then the signal
    name=$1 sig=$2
    shift 2
    "$bin" "$@" >out.txt 2>err.txt &
    pid=$!
    if ! wait_for "ground truth" err.txt 60; then
        fail=1
        echo "FAIL: $name: no ground truth started: $(cat err.txt)"
        kill -9 "$pid"
        pid=
        return
    fi
    sleep 1 # inside the render: its beams and first pixels take well under a second here
    kill -"$sig" "$pid"
    if wait_gone "$pid" 10; then
        wait "$pid"
        rc=$?
        if [ "$rc" -eq 1 ] && grep -q "interrupted while rendering the ground truth" err.txt &&
           ! ls cache/reference-*.exr >/dev/null 2>&1 && [ -z "$(find . -name '*.tmp*')" ]; then
            echo "ok: $name: SIG$sig stopped its ground truth: $(tail -n 1 err.txt)"
        else
            fail=1
            echo "FAIL: $name: SIG$sig: exit $rc (want 1), cache: $(ls cache 2>&1), stderr: $(cat err.txt)"
        fi
    else
        fail=1
        echo "FAIL: $name: still running 10 s after SIG$sig"
        kill -9 "$pid"
    fi
    pid=
}
signal_case tune INT tune s.json -o t --params shafts.K $slow
signal_case sweep TERM sweep s.json -o sw --param shafts.K=0.5:1:2 $slow
signal_case pareto INT pareto s.json -o p --quick --techniques shafts $slow
exit $fail
