#!/bin/sh
# Piped `run` says what it waits for (issue 29, item 6): while a user technique's render is
# long, a line "godrays run: NAME: still rendering (PASS), elapsed S s of its time limit ..."
# every 10 s ($GODRAYS_PROGRESS_SECONDS: 1 here, so that a render of a few seconds shows it):
# tests/techniques/slow_loop (a long fragment loop drawn many times) stopped by a 2.5 s time
# limit prints at least 2 such lines, with stderr a file (not a terminal); -q prints none.
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
export GODRAYS_GL_PLATFORM=surfaceless LIBGL_ALWAYS_SOFTWARE=1 # llvmpipe's durations
scene="$dir/scene.json"
small_scene "$scene" 32 18 '"reference": {"surface_res": 64, "sun_samples": 2, "batches": 2, "steps": 16, "spp": 1}'
set -- run "$scene" --technique-dir "$src/tests/techniques/slow_loop" --techniques slow_loop --set slow_loop.copies=400 \
    --time-limit 2.5
GODRAYS_PROGRESS_SECONDS=1 timeout 120 "$bin" "$@" -o "$dir/rep" >"$dir/out" 2>"$dir/err"
rc=$?
ck "run exits 3 (the technique failed at its time limit; got $rc)" [ $rc -eq 3 ]
n=$(grep -c "^godrays run: slow_loop: still rendering (passes\[0\] 'spin'), elapsed [0-9]* s of its time limit of 2.5 s$" "$dir/err")
ck "at least 2 'still rendering' lines in the pipe (got $n)" [ "$n" -ge 2 ]
grep "still rendering" "$dir/err"
GODRAYS_PROGRESS_SECONDS=1 timeout 120 "$bin" "$@" -q -o "$dir/rep2" >"$dir/out" 2>"$dir/err"
ck "-q: no 'still rendering' line" sh -c "! grep -q 'still rendering' '$dir/err'"
exit $fail
