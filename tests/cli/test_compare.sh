#!/bin/sh
# `godrays compare` end to end: an EXR with stderr channels against a PNG with RGBA (different
# channel layouts), a mask, the stderr exclusion count, the scale fit, -o DIR outputs, and the
# errors (size mismatch, unreadable file, bad option) with exit code 2 and one stderr line.
# Inputs are made with oiiotool (openimageio-tools), values chosen so the results are known:
#   ref: R, G, B = 0.2, 0.4, 0.6, stderr 0.01 (0.5 in the 16 leftmost columns: relative stderr
#        of luminance 0.5 / 0.3719 > 0.5, so those 768 pixels are not scored)
#   test PNG read as code/255 (--no-linearize): 51, 102, 204 -> 0.2, 0.4, 0.8: B is off by 0.2
#   mask: 1 in the 32 leftmost columns, 0 elsewhere (1536 pixels masked out)
set -u
. "$(dirname "$0")/lib.sh"
out=${GODRAYS_TEST_OUT:-/tmp}/compare_cli
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
command -v oiiotool >/dev/null || { echo "FAIL: oiiotool not found (openimageio-tools)"; exit 1; }

oiiotool --create 64x48 6 --chnames R,G,B,stderr.R,stderr.G,stderr.B \
    --fill:color=0.2,0.4,0.6,0.01,0.01,0.01 64x48 \
    --fill:color=0.2,0.4,0.6,0.5,0.5,0.5 16x48+0+0 -d float -o ref.exr || exit 1
oiiotool --create 64x48 4 --fill:color=0.2,0.4,0.8,1 64x48 -d uint8 -o test.png || exit 1
oiiotool --create 64x48 1 --fill:color=1 32x48+0+0 -d uint8 -o mask.png || exit 1
oiiotool --create 64x48 3 --fill:color=0.1,0.2,0.3 64x48 -d float -o half.exr || exit 1
oiiotool --create 32x48 3 -d float -o small.exr || exit 1
printf 'not an image\n' > garbage.exr

# 1. EXR RGB+stderr against PNG RGBA, with -o: table, files, counts, known bias.
"$bin" compare ref.exr test.png --no-linearize -o res >stdout.txt 2>stderr.txt
rc=$?
ck "exit 0 on a good pair" [ "$rc" -eq 0 ]
ck "stderr empty" [ ! -s stderr.txt ]
ck "table states the stderr exclusion" grep -q "768 NOT SCORED: reference relative stderr (luminance) > 0.5" stdout.txt
ck "metrics.json written" [ -s res/metrics.json ]
ck "diff.png written" [ -s res/diff.png ]
ck "diff_signed.png written" [ -s res/diff_signed.png ]
ck "flip.png written" [ -s res/flip.png ]
ck "no temporary file left" [ -z "$(ls res | grep -v -e '^metrics.json$' -e '^diff.png$' -e '^diff_signed.png$' -e '^flip.png$')" ]
ck "json: FLIP of a constant pair (ref is .exr: HDR)" grep -q '"mode":[[:space:]]*"hdr"' res/metrics.json
ck "diff.png is the image plus its colorbar (256 x 88)" sh -c 'iinfo res/diff.png | grep -q "256 x   88"'
ck "json: 2304 scored" grep -q '"scored_pixels":[[:space:]]*2304,' res/metrics.json
ck "json: 768 excluded" grep -q '"stderr_excluded_pixels":[[:space:]]*768,' res/metrics.json
ck "json: stderr found" grep -q '"reference_has_stderr":[[:space:]]*true' res/metrics.json
ck "json: B bias 0.2" grep -q '"bias":[[:space:]]*0\.200000' res/metrics.json
ck "json: Y bias 0.0722 * 0.2" grep -q '"bias":[[:space:]]*0\.01444' res/metrics.json
ck "json: test channels are R, G, B of the RGBA file" \
    sh -c "tr -d ' \t\n' < res/metrics.json | grep -q '\"test\":{\"channels_compared\":\\[\"R\",\"G\",\"B\"\\],\"path\":\"test.png\",\"channels\":4}'"
# B differs by 0.2 > 2 * 0.01 everywhere: 0 % not significant; R, G by ~0: 100 %; RGB 2/3;
# Y: |dY| = 0.0722 * 0.2 = 0.0144 <= 2 * stderr_Y = 2 * 0.01: 100 %
ck "significance row" grep -q "not signif. (<=2se) %         100.00      100.00        0.00       66.67      100.00" stdout.txt

# 2. mask: 1536 masked out, then 768 of the rest excluded by stderr: 768 scored.
"$bin" compare ref.exr test.png --no-linearize --mask mask.png --json >mask.json 2>stderr.txt
ck "mask: exit 0" [ $? -eq 0 ]
ck "mask: counts" sh -c 'grep -q "\"masked_out_pixels\":[[:space:]]*1536," mask.json &&
    grep -q "\"scored_pixels\":[[:space:]]*768," mask.json'
ck "--json prints JSON" sh -c 'head -c 1 mask.json | grep -q "{"'
# no bound: everything in the mask is scored
"$bin" compare ref.exr test.png --no-linearize --mask mask.png --stderr-bound inf --json >nobound.json
ck "no bound: 1536 scored" grep -q '"scored_pixels":[[:space:]]*1536,' nobound.json

# 3. best scale fit recovers the factor 2 exactly.
"$bin" compare ref.exr half.exr --fit-scale >fit.txt 2>&1
ck "fit: exit 0" [ $? -eq 0 ]
ck "fit: factor 2" grep -q "best scale fit: test x 2 " fit.txt

# 4. errors: exit 2, exactly one line on stderr naming the inputs, nothing on stdout,
#    nothing written.
expect_error() { # expect_error TEXT ARGS...
    text=$1; shift
    "$bin" compare "$@" >err_out.txt 2>err_err.txt
    erc=$?
    ck "exit 2 for: $*" [ "$erc" -eq 2 ]
    ck "one stderr line for: $*" [ "$(wc -l <err_err.txt)" -eq 1 ]
    ck "stderr names it ($text)" grep -qF -- "$text" err_err.txt
    ck "stdout empty for: $*" [ ! -s err_out.txt ]
    cat err_err.txt
}
expect_error "size mismatch: reference ref.exr is 64 x 48, test small.exr is 32 x 48" ref.exr small.exr -o bad
ck "nothing written on a size mismatch" [ ! -e bad ]
expect_error "missing.png" ref.exr missing.png -o bad
expect_error "garbage.exr" garbage.exr test.png
expect_error "size mismatch: mask" ref.exr test.png --mask small.exr
expect_error "unknown option '--bogus'" ref.exr test.png --bogus
expect_error "need two images" ref.exr
expect_error "--stderr-bound" ref.exr test.png --stderr-bound -1
expect_error "--metric structure needs the vanishing point" ref.exr test.png --metric structure
expect_error "--metric 'flop'" ref.exr test.png --metric flop
expect_error "--vp '1'" ref.exr test.png --vp 1
expect_error "--set needs --scene" ref.exr test.png --set camera.yaw_deg=3
expect_error "--flip-mode 'x'" ref.exr test.png --flip-mode x
expect_error "--exposures" ref.exr test.png --exposures 3:1:2
expect_error "--scene missing.json" ref.exr test.png --scene missing.json
ck "nothing written on a missing file" [ ! -e bad ]

# 5. FLIP and structure selected alone: identical images give FLIP 0; a flat pair has no
#    structure (contrast 0, correlation 0).
"$bin" compare ref.exr ref.exr --metric flip,structure --vp 32,24 --json >fs.json 2>fs.err
ck "flip+structure: exit 0" [ $? -eq 0 ]
ck "flip of identical images is 0" sh -c "tr -d ' \t\n' < fs.json | grep -q '\"flip\":{[^}]*\"mean\":0,'"
ck "structure: correlation 0 for flat images" grep -q '"bandpass_correlation":[[:space:]]*0,' fs.json
"$bin" compare ref.exr test.png --no-linearize --metric flip --flip-mode ldr >ldr.txt 2>&1
ck "LDR-FLIP selected: no basic table" sh -c '! grep -q "RMSE" ldr.txt && grep -q "LDR-FLIP" ldr.txt'
exit $fail
