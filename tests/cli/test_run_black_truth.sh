#!/bin/sh
# A ground truth that is black everywhere (extinction 15 /m at 8 m deep: the light left,
# below 1e-50, is 0 in float; found by random views, 2026-11-30). HDR-FLIP derives its
# exposures from the reference's luminance maximum and median, which are 0: `run` used to
# fail the whole job there with exit 2 ("FLIP exposures: ... give the exposures explicitly",
# an option run does not have) and no report. Now FLIP is left out (NaN, said in the report),
# the run writes its report and warns that the truth is zero, and exits 3 for the techniques
# that rendered black, as for any failed technique. compare still refuses a black reference.
# (surface_res 64: the truth is black whatever its cells, and its builds cost 4x less.)
set -u
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
"$bin" run "$src/data/scenes/default.json" -o r --techniques shafts,slicing --size 32x18 \
  --set "medium.absorption_per_m=[15,15,15]" --set reference.surface_res=64 -q >out.txt 2>err.txt
rc=$?
[ "$rc" = 3 ] || { echo "FAIL: run exit $rc (want 3): $(cat err.txt)"; fail=1; }
grep -q "FLIP exposures" err.txt && { echo "FAIL: FLIP's exposures failed the run: $(cat err.txt)"; fail=1; }
grep -q "the ground truth is zero everywhere scored" err.txt || { echo "FAIL: no warning that the truth is zero"; fail=1; }
grep -q "slicing FAILED: rendered a black image" err.txt || { echo "FAIL: slicing not failed as black"; fail=1; }
[ -s r/index.html ] && [ -s r/metrics.json ] && [ -s r/shafts_flip.png ] || { echo "FAIL: no report"; ls r; fail=1; }
grep -q "The ground truth is zero everywhere" r/index.html || { echo "FAIL: the report does not warn that the truth is zero"; fail=1; }
grep -q "HDR-FLIP of a x shafts against the ground truth: not computed" r/index.html || {
  echo "FAIL: the report does not say that FLIP was not computed"; fail=1; }
python3 -c "
import json, sys
m = json.load(open('r/metrics.json'))
s = json.dumps(m)
sys.exit(0 if 'NaN' not in s and 'Infinity' not in s else 1)
" || { echo "FAIL: metrics.json is not strict JSON"; fail=1; }
"$bin" compare r/reference.exr r/shafts.exr >c.txt 2>&1
[ $? = 2 ] || { echo "FAIL: compare accepted a black reference"; fail=1; }
[ $fail = 0 ] && echo "ok: a black ground truth: report written, FLIP left out, exit 3"
exit $fail
