#!/bin/sh
# godrays run --frames A:B:S: the sequence report (src/report/sequence.c), at a small size with
# reduced reference settings (a few seconds per frame):
#  - DIR/sequence/index.html, one animated GIF per technique holding one frame per rendered
#    frame (counted by oiiotool, an independent reader), the charts (PLplot builds);
#  - metrics.json "sequence": the frames' water times are the scene's water.time_s + frame / fps
#    (read from the scene file here), the per-pair arrays have n - 1 entries, the truth changes
#    between frames (its noise taken out), and the summary's flicker ratio is
#    sqrt(sum test_diff_rms^2 / sum truth_diff_rms^2) of the pairs (compare/temporal.h);
#  - frame 0 of the sequence is the frame index.html compares (same rel. RMSE after the fit);
#  - index.html links the sequence page; bad --frames/--times/--fps are usage errors (exit 2).
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/run_sequence
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
scene="$src/data/scenes/default.json"
small="--size 96x54 --set reference.surface_res=64 --set reference.sun_samples=2 --set reference.batches=2
       --set reference.steps=16"
# two techniques, a rasterized one and a volume one: the sequence report is the same code for
# every technique (each technique's frames are cli.techniques' and cli.capture_own's checks)
two="--techniques shafts,light_rays"
# shellcheck disable=SC2086
GODRAYS_CACHE="$out/cache" "$bin" run "$scene" -o rep --frames 0:10:5 --fps 15 $small $two -q >run.txt 2>&1
rc=$?
ck "godrays run --frames exits 0 (rc $rc)" [ "$rc" -eq 0 ]
[ "$rc" -eq 0 ] || { cat run.txt; exit 1; }
ck "sequence/index.html written" [ -s rep/sequence/index.html ]
ck "index.html links the sequence page" grep -q 'href="sequence/index.html"' rep/index.html
ck "the summary names the sequence report" grep -q 'sequence report: rep/sequence/index.html' run.txt
grep -o '<img src="[^"]*"' rep/sequence/index.html | sed 's/<img src="//; s/"$//' >srcs.txt
ck "the sequence page shows pictures ($(wc -l <srcs.txt))" [ "$(wc -l <srcs.txt)" -ge 4 ]
while read -r f; do ck "sequence page image $f exists" [ -s "rep/sequence/$f" ]; done <srcs.txt
ck "no escaped markup shows on the page" sh -c "! grep -q '&lt;h1&gt;' rep/sequence/index.html"
ck "the sequence page links back to the run's page" grep -q 'href="../index.html"' rep/sequence/index.html
for f in rep/*.exr; do
    case $f in rep/reference.exr) continue ;; esac
    t=$(basename "$f" .exr)
    n=$(oiiotool --info -v "rep/sequence/$t.gif" 2>/dev/null | sed -n 's/^ *\([0-9]*\) subimages.*/\1/p')
    ck "$t.gif holds 3 frames (oiiotool: ${n:-none})" [ "${n:-0}" -eq 3 ]
done
if grep -q '"drawn":[[:space:]]*0' rep/metrics.json; then
    echo "note: no PLplot in this build: charts not checked"
else
    for c in rel_rmse ssim flip structure diff_error flicker; do
        ck "chart seq_$c.png" [ -s "rep/sequence/seq_$c.png" ]
    done
fi
ck "metrics.json: the sequence's numbers" python3 - "$scene" rep/metrics.json <<'PY'
import json, math, sys
scene = json.load(open(sys.argv[1]))
d = json.load(open(sys.argv[2]))
s = d["sequence"]
t0 = scene.get("water", {}).get("time_s", 0.0)
want = [t0 + f / 15.0 for f in (0, 5, 10)]
assert s["n_frames"] == 3 and s["frames"] == [0, 5, 10], s["frames"]
assert all(abs(a - b) < 1e-9 for a, b in zip(s["times_s"], want)), (s["times_s"], want)
lead = {t["name"]: t for t in d["techniques"]}
for t in s["techniques"]:
    p = t["pairs"]
    for k, v in p.items():
        assert len(v) == 2, k
    assert all(x > 0 for x in p["truth_diff_rms"]), "the truth does not change between frames"
    fl = math.sqrt(sum(x * x for x in p["test_diff_rms"]) / sum(x * x for x in p["truth_diff_rms"]))
    assert abs(fl - t["temporal"]["flicker_ratio"]) <= 1e-9 * max(1, fl), (fl, t["temporal"])
    assert all(len(v) == 3 for v in t["per_frame"].values())
    assert all(0 <= x <= 1 for x in t["per_frame"]["flip_hdr_mean"])
    print(t["name"], "flicker", fl, "frame-0 rel RMSE", t["per_frame"]["rel_rmse_y_fit"][0])
PY
ck "frame 0's rel. RMSE after the fit equals the leaderboard's" python3 - rep/metrics.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for t in d["sequence"]["techniques"]:
    lt = [x for x in d["techniques"] if x["name"] == t["name"]][0]
    want = lt["errors_y"]["rel_rmse_fit"]
    got = t["per_frame"]["rel_rmse_y_fit"][0]
    assert abs(got - want) <= 1e-9 * want, (t["name"], got, want)
PY
# usage errors: exit 2, nothing rendered
for bad in "--frames 3:1:1" "--frames 0:0:1" "--times 0.5" "--frames 0:4:2 --times 1,2" "--fps 0 --frames 0:2:1"; do
    # shellcheck disable=SC2086
    "$bin" run "$scene" -o bad $bad -q >bad.txt 2>&1
    r=$?
    ck "run $bad: exit 2 (got $r: $(head -c 160 bad.txt))" [ "$r" -eq 2 ]
done
ck "no folder for the bad runs" [ ! -e bad ]
exit $fail
