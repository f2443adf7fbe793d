#!/bin/sh
# `godrays run` end to end on a small, low-quality version of the default scene:
#  - the report folder (index.html, summary.png, metrics.json, pictures, charts, both EXRs);
#  - its metrics are those `godrays compare --fit-scale` computes on the two EXRs it wrote, and
#    its pooled-RGB RMSE, mean error and PSNR agree with OpenImageIO's idiff (independent code);
#  - the ground-truth cache: a miss renders and stores, a hit reuses the same bytes, a changed
#    shaft setting still hits, a changed medium misses, a file whose key attribute does not
#    match is ignored (and replaced), --no-cache neither reads nor writes, an unusable
#    $GODRAYS_CACHE only warns;
#  - the default output folder out/<scene name>.
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/run_cli
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
scene="$src/data/scenes/default.json"
small="--size 160x90 --set reference.surface_res=64 --set reference.sun_samples=2 --set reference.batches=2 --set reference.steps=16"
# runs 2-9 check the cache and the folders, which are the ground truth's and the report's
# whatever is compared: one technique each (the first run has them all)
one="--techniques shafts"
export GODRAYS_CACHE="$out/cache"

# 1. first run: the cache is empty, the ground truth is rendered and stored
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep1 $small >out1.txt 2>err1.txt
rc=$?
cat out1.txt err1.txt
ck "first run exits 0" [ "$rc" -eq 0 ]
ck "first run renders the ground truth" grep -q "rendering the ground truth" err1.txt
ck "summary table printed" grep -q "^  RMSE " out1.txt
ck "summary names the report" grep -q "report: rep1/index.html" out1.txt
# one row per technique in the leaderboard: every technique of the default set (`godrays techniques --json`; by_name_only ones such as eevee are left out)
techs=$("$bin" techniques --json | python3 -c 'import json,sys; print(" ".join(t["name"] for t in json.load(sys.stdin)["techniques"] if not t.get("by_name_only")))')
ck "techniques listed" [ -n "$techs" ]
files="index.html summary.png metrics.json reference.png reference.exr radial_profile.png"
for t in $techs; do
    files="$files $t.png ${t}_raw.png ${t}_diff.png ${t}_diff_signed.png ${t}_flip.png $t.exr ${t}_radial_profile_rgb.png ${t}_error_vs_blur.png"
done
for f in $files; do
    ck "rep1/$f written" [ -s "rep1/$f" ]
done
ck "no temporary files left" sh -c '! ls rep1 | grep -q tmp'
ck "one cache entry" [ "$(ls cache | grep -c '^reference-.*\.exr$')" -eq 1 ]
entry=$(ls cache/reference-*.exr 2>/dev/null | head -n 1)
if command -v iinfo >/dev/null 2>&1 && [ -n "$entry" ]; then
    key=$(basename "$entry" .exr | sed 's/^reference-//')
    ck "cache entry carries its key" sh -c "iinfo -v '$entry' | grep -q 'godrays:cache_key: \"$key\"'"
fi

# 2. the run's metrics are compare's metrics on the EXRs it wrote (same stderr rule, same fit)
"$bin" compare rep1/reference.exr rep1/shafts.exr --fit-scale --scene "$scene" --json >cmp.json 2>cmp.err
ck "compare on the run's EXRs exits 0" [ $? -eq 0 ]
# metrics.json: one entry per technique (schema 2, docs/report.md); the shafts' "compare" block
# is what `godrays compare --json` writes
same() { python3 - rep1/metrics.json cmp.json "$1" <<'PY'
import json, sys
run, cmp, key = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[3]
t = [t for t in run["techniques"] if t["name"] == "shafts"][0]["compare"]
sys.exit(0 if key in cmp and t.get(key) == cmp[key] else 1)
PY
}
ck "raw metrics identical to godrays compare" same metrics
ck "fitted metrics identical to godrays compare" same fitted
ck "one metrics.json entry and one leaderboard row per technique" python3 -c '
import json, sys
d = json.load(open("rep1/metrics.json")); names = sys.argv[1].split()
sys.exit(0 if sorted(t["name"] for t in d["techniques"]) == sorted(names) and sorted(d["leaderboard"]) == sorted(names) else 1)' "$techs"
ck "index.html has the leaderboard" grep -q 'id="leaderboard"' rep1/index.html

# 3. idiff on the RGB channels (idiff compares every channel: strip the stderr ones)
if command -v idiff >/dev/null 2>&1 && command -v oiiotool >/dev/null 2>&1; then
    if grep -q '"stderr_excluded_pixels":	0,' cmp.json; then
        oiiotool rep1/reference.exr --ch R,G,B -o ref_rgb.exr
        idiff -a ref_rgb.exr rep1/shafts.exr >idiff.txt 2>&1
        cat idiff.txt
        # the RGB row of the raw metrics: first "rmse", "mae", "psnr_idiff_db" after "RGB"
        val() { python3 -c 'import json,sys; d=json.load(open("rep1/metrics.json")); t=[t for t in d["techniques"] if t["name"]=="shafts"][0]; print(t["compare"]["metrics"]["channels"]["RGB"][sys.argv[1]])' "$1"; }
        rel() { awk -v a="$1" -v b="$2" 'BEGIN{d=a-b; if(d<0)d=-d; s=b<0?-b:b; exit !(d <= 2e-6*s + 1e-12)}'; }
        rms_ours=$(val rmse); mae_ours=$(val mae); psnr_ours=$(val psnr_idiff_db)
        rms_idiff=$(sed -n 's/^ *RMS error = \([0-9.eE+-]*\).*/\1/p' idiff.txt)
        mae_idiff=$(sed -n 's/^ *Mean error = \([0-9.eE+-]*\).*/\1/p' idiff.txt)
        psnr_idiff=$(sed -n 's/^ *Peak SNR = \([0-9.eE+-]*\).*/\1/p' idiff.txt)
        echo "ours: RMS $rms_ours, mean $mae_ours, PSNR $psnr_ours; idiff: RMS $rms_idiff, mean $mae_idiff, PSNR $psnr_idiff"
        # idiff prints 6 significant digits: agreement to its printed precision
        ck "RGB RMSE agrees with idiff" rel "$rms_ours" "$rms_idiff"
        ck "RGB mean error agrees with idiff" rel "$mae_ours" "$mae_idiff"
        ck "PSNR (idiff peak) agrees with idiff" rel "$psnr_ours" "$psnr_idiff"
    else
        echo "note: the reference has pixels excluded by its stderr: idiff (which scores all) is not comparable"
    fi
fi

# 4. a changed shaft setting reuses the cached ground truth, byte for byte
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep2 $small $one --set shafts.K=0.7 >out2.txt 2>err2.txt
ck "second run exits 0" [ $? -eq 0 ]
ck "second run reads the cache" grep -q "ground truth from the cache" err2.txt
ck "summary says so" grep -q "from the cache" out2.txt
ck "still one cache entry" [ "$(ls cache | grep -c '^reference-.*\.exr$')" -eq 1 ]
if command -v idiff >/dev/null 2>&1; then
    ck "cached reference is identical to the rendered one" idiff -q -fail 0 -warn 0 rep1/reference.exr rep2/reference.exr
fi
ck "report says the reference came from the cache" grep -q "Read from the cache" rep2/index.html

# 5. a cache file whose key attribute does not match is ignored, re-rendered and replaced
cp rep1/shafts.exr "$entry"
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep3 $small $one >out3.txt 2>err3.txt
ck "run over a bad cache entry exits 0" [ $? -eq 0 ]
ck "bad cache entry reported as ignored" grep -q "ignored: .*does not match" err3.txt
ck "bad cache entry re-rendered" grep -q "rendering the ground truth" err3.txt
if command -v iinfo >/dev/null 2>&1; then
    ck "bad cache entry replaced" sh -c "iinfo -v '$entry' | grep -q 'godrays:cache_key'"
fi

# 6. a change the ground truth sees is a new entry
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep4 $small $one --set medium.g=0.8 -q >out4.txt 2>err4.txt
ck "medium change exits 0" [ $? -eq 0 ]
ck "-q prints nothing on stderr" [ ! -s err4.txt ]
ck "medium change makes a second cache entry" [ "$(ls cache | grep -c '^reference-.*\.exr$')" -eq 2 ]

# 7. --no-cache neither reads nor writes
export GODRAYS_CACHE="$out/cache_empty"
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep5 $small $one --no-cache >out5.txt 2>err5.txt
ck "--no-cache exits 0" [ $? -eq 0 ]
ck "--no-cache renders" grep -q "not cached" err5.txt
ck "--no-cache writes no cache" [ ! -e cache_empty ] || [ -z "$(ls cache_empty)" ]

# 8. an unusable cache directory only warns
: >not_a_dir
export GODRAYS_CACHE="$out/not_a_dir/sub"
# shellcheck disable=SC2086
"$bin" run "$scene" -o rep6 $small $one >out6.txt 2>err6.txt
ck "unusable GODRAYS_CACHE: exit 0" [ $? -eq 0 ]
ck "unusable GODRAYS_CACHE: one warning naming it" grep -q "warning: cache off: GODRAYS_CACHE=" err6.txt

# 9. default output folder: out/<scene name>
export GODRAYS_CACHE="$out/cache"
mkdir -p cwd && cd cwd || exit 1
# shellcheck disable=SC2086
"$bin" run "$scene" $small $one -q >/dev/null 2>&1
ck "default folder out/default" [ -s out/default/index.html ]
cd "$out" || exit 1

[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
