#!/bin/sh
# `godrays run` with techniques that fail (issue 26): a user technique whose fragment shader does
# not compile, one that renders black and one that renders NaN, beside froxel, on a small,
# low-quality default scene:
#  - exit 3 (the report is complete, some technique failed), and every output is written;
#  - each failure is a row of the leaderboard with its one-line reason, in the terminal,
#    index.html and metrics.json (leaderboard_rows, failed); froxel is ranked;
#  - the verdict with its components, the three baselines (black, constant, blurred truth) and
#    froxel's equivalent blur are in all three, the verdict being (rel. RMSE after the fit +
#    structure score) / 2 of froxel's own metrics (recomputed here from metrics.json);
#  - the leaderboard is in verdict order, and the flag follows the rule (by the verdict, else by the
#    error after the fit alone): a technique is flagged
#    exactly when its verdict, or its error after the fit, is not below the constant image's.
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/run_verdict
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
export GODRAYS_CACHE="$out/cache"
te="$src/tests/techniques/gl_errors"
"$bin" run "$src/data/scenes/default.json" -o rep --size 96x54 --set reference.surface_res=64 \
    --set reference.sun_samples=2 --set reference.batches=2 --set reference.steps=16 \
    --technique-dir "$te/compile_error" --technique-dir "$te/black" --technique-dir "$te/nan" \
    --techniques err_compile_error,froxel,err_black,err_nan -q >out.txt 2>err.txt
rc=$?
cat out.txt err.txt
ck "exit 3: the report is complete, some technique failed" [ "$rc" -eq 3 ]
for f in index.html metrics.json summary.png reference.exr froxel.exr froxel.png; do
    ck "rep/$f written" [ -s "rep/$f" ]
done
ck "no EXR for a failed technique" [ ! -e rep/err_compile_error.exr ]

# the terminal
ck "terminal: the failed row with the compiler's reason" grep -q "^  FAIL err_compile_error .*does not compile" out.txt
ck "terminal: the black technique's row" grep -q "^  FAIL err_black .*black" out.txt
ck "terminal: the NaN technique's row" grep -q "^  FAIL err_nan " out.txt
ck "terminal: froxel ranked 1" grep -q "^  1    froxel " out.txt
ck "terminal: the verdict and its components" grep -q "verdict  err. fit structure     FLIP  bp corr  contrast   scale a   eq. blur" out.txt
for b in "black frame" "constant: the truth's mean" "truth blurred, sigma 4 px"; do
    ck "terminal: baseline '$b'" grep -q "^  base ($b)" out.txt
done
ck "terminal: froxel's equivalent blur" sh -c "grep '^  1    froxel ' out.txt | grep -Eq ' (< )?[0-9.]+ px '"
ck "terminal: the exit code is explained" grep -q "3 techniques FAILED" out.txt

# index.html
ck "html: failed rows" sh -c "[ \$(grep -c '<tr class=\"failed\">' rep/index.html) -eq 3 ]"
ck "html: the compiler's reason" grep -q "FAILED: .*does not compile" rep/index.html
ck "html: three baseline rows" sh -c "[ \$(grep -c '<tr class=\"baseline\">' rep/index.html) -eq 3 ]"
for h in "verdict" "error after fit" "structure<br>score" "FLIP" "band-pass<br>corr." "streak<br>contrast ratio" "scale a" "equivalent<br>blur"; do
    ck "html: column '$h'" grep -qF "<th>$h" rep/index.html
done

# metrics.json
ck "metrics.json: rows, baselines, failures, verdict" python3 - rep/metrics.json <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
rows = d["leaderboard_rows"]
kinds = [r["kind"] for r in rows]
assert kinds.count("failed") == 3 and kinds.count("baseline") == 3 and kinds.count("technique") == 1, kinds
assert kinds[-3:] == ["failed"] * 3, kinds
f = {r["name"]: r for r in rows if r["kind"] == "failed"}
assert "does not compile" in f["err_compile_error"]["reason"], f
assert "black" in f["err_black"]["reason"], f
assert sorted(x["name"] for x in d["failed"]) == ["err_black", "err_compile_error", "err_nan"]
scored = [r for r in rows if r["kind"] != "failed"]
v = [r["verdict"] for r in scored]
assert v == sorted(v), v
assert sorted(r["name"] for r in scored if r["kind"] == "baseline") == ["black", "blur", "constant"]
t = d["techniques"][0]
assert t["name"] == "froxel" and d["leaderboard"] == ["froxel"]
e = t["errors_y"]
want = (e["rel_rmse_fit"] + e["structure_fit"]) / 2
assert abs(t["verdict"]["verdict"] - want) <= 1e-9 * want and abs(e["verdict_fit"] - want) <= 1e-9 * want, (t["verdict"], want)
for k in ("rel_rmse_fit", "structure", "flip", "bandpass_corr", "streak_contrast_ratio", "scale", "equivalent_blur_px"):
    assert isinstance(t["verdict"][k], float), k
assert t["verdict"]["equivalent_blur"].endswith(" px")
crow = [r for r in rows if r["name"] == "constant"][0]
const, const_err = crow["verdict"], crow["rel_rmse_fit"]
for r in rows:
    if r["kind"] == "technique":
        want_flag = ("no better than a constant image" if not r["verdict"] < const else
                     "no better than a constant image in error after the fit" if not r["rel_rmse_fit"] < const_err else None)
        assert r["flag"] == want_flag, (r, want_flag)
lad = d["baselines"]["blur_ladder"]
assert lad["sigma_px"][0] == 0.5 and abs(lad["sigma_px"][-1] - 64) < 1e-9
assert all(b >= a for a, b in zip(lad["envelope"], lad["envelope"][1:]))
print("metrics.json ok: froxel verdict %.4f (constant %.4f), equivalent blur %s" % (t["verdict"]["verdict"], const, t["verdict"]["equivalent_blur"]))
PY
exit $fail
