#!/bin/sh
# Issue 31, finding 9 (docs/tuning.md, "Budgets"): sweep, tune and pareto count the renders they
# plan before the ground truths; over 20000 they need --yes (exit 2 at once otherwise, naming
# the count); below it they print the count and, after the first render, an estimate of the
# whole. main: two 1000-value axes started 10^6 renders without a word.
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
small_scene S.json 32 18
bin_t=$bin
printf '#!/bin/sh\nexec timeout 60 "%s" "$@"\n' "$bin_t" >tbin # main started the renders: stopped after a minute
chmod +x tbin
bin=$dir/tbin
expect 2 "1000000 grid points: over the 20000 renders that start without --yes" \
    sweep S.json --param shafts.K=0.5:2:1000 --param shafts.shaft_length_m=1:10:1000 -o sw
expect 2 "40000 grid points x 3 cases = 120000 renders: over the 20000" \
    sweep S.json --param shafts.K=0.5:2:200 --param shafts.shaft_length_m=1:10:200 --frames 0:2:1 -o sw
expect 2 "evaluations: over the 20000 renders that start without --yes" tune S.json --params shafts.K --max-evals 100000 -o tu
expect 2 "renders: over the 20000 renders that start without --yes" pareto S.json --repeat 1000 -o pa
ck "nothing created" test ! -e sw -a ! -e tu -a ! -e pa
bin=$bin_t
# below the threshold: the count, then the estimate
"$bin" sweep S.json --param shafts.K=0.5:2:6 -o sw >out 2>err
rc=$?
if [ $rc -eq 0 ] && grep -qF "godrays sweep: 6 grid points planned" err &&
    grep -q "godrays sweep: the first 1 of 6 grid points took .*: about .* for all" err; then
    echo "ok: sweep: $(grep -F planned err); $(grep -F 'for all' err)"
else echo "FAIL: sweep of 6 points: exit $rc, no count or estimate:"; cat err; fail=1; fi
# --yes passes the count (the impossible output folder then stops it before any work)
"$bin" sweep S.json --param shafts.K=0.5:2:200 --param shafts.shaft_length_m=1:10:200 --frames 0:2:1 --yes \
    -o /dev/null/x >out 2>err
grep -qF -- "--yes" err && { echo "FAIL: --yes still refused: $(cat err)"; fail=1; } || echo "ok: --yes accepted ($(cat err))"
exit $fail
