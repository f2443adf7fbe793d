#!/bin/sh
# `godrays compare --fit rgb` and the capture warnings on images made with oiiotool:
#   ref.exr    a coloured gradient (four corners), float
#   tint.exr   ref with R x 0.5, G x 1, B x 2: --fit rgb must give R x 2, G x 1, B x 0.5 (1 %)
#   vflip.exr, hflip.exr   ref upside down / mirrored: the flip warnings
#   good.png   ref sRGB-encoded in 8 bits (tagged sRGB): no warning at all
#   clip.png   ref x 3, sRGB, 8 bits: about half the pixels at 255: the clipping warning
#   lin.png    ref's linear values as 8-bit codes tagged sRGB: "values look linear"; good.png
#              read with --no-linearize: "values look sRGB-encoded"
#   dim.exr    ref x 0.02: the fit is x 50, outside [0.1, 10]
# Each warning is one stderr line and one entry of "warnings" in the JSON (and metrics.json).
set -u
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
command -v oiiotool >/dev/null || { echo "FAIL: oiiotool not found (openimageio-tools)"; exit 1; }
command -v python3 >/dev/null || { echo "FAIL: python3 not found"; exit 1; }
oiiotool --pattern fill:topleft=1,0.8,0.6:topright=0.3,0.25,0.2:bottomleft=0.1,0.1,0.12:bottomright=0.02,0.03,0.05 \
    96x54 3 -d float -o ref.exr || exit 1
oiiotool ref.exr --mulc 0.5,1,2 -d float -o tint.exr || exit 1
oiiotool ref.exr --flip -d float -o vflip.exr || exit 1
oiiotool ref.exr --flop -d float -o hflip.exr || exit 1
oiiotool ref.exr --mulc 0.02 -d float -o dim.exr || exit 1
oiiotool ref.exr --colorconvert linear sRGB -d uint8 -o good.png || exit 1
oiiotool ref.exr --mulc 3 --colorconvert linear sRGB -d uint8 -o clip.png || exit 1
oiiotool ref.exr --attrib oiio:ColorSpace sRGB -d uint8 -o lin.png || exit 1

# json FILE EXPR: EXPR (Python, d = the document) must be true
json() {
    python3 -c "import json, sys; d = json.load(open(sys.argv[1])); sys.exit(0 if ($2) else 1)" "$1"
}

# 1. the tint, through the CLI: the three factors within 1 %, and in the text
"$bin" compare ref.exr tint.exr --fit rgb --json >tint.json 2>tint.err
ck "tint: exit 0" [ $? -eq 0 ]
ck "tint: R x 2, G x 1, B x 0.5 within 1 %" json tint.json \
    "abs(d['fitted']['scale_rgb']['R'] / 2 - 1) < 0.01 and abs(d['fitted']['scale_rgb']['G'] - 1) < 0.01 and abs(d['fitted']['scale_rgb']['B'] / 0.5 - 1) < 0.01"
ck "tint: fit_mode rgb" json tint.json "d['fitted']['fit_mode'] == 'rgb'"
ck "tint: no error left after the fit" json tint.json "d['fitted']['channels']['RGB']['rmse'] < 1e-6"
ck "tint: the raw set's factors are 1" json tint.json "d['metrics']['scale_rgb'] == {'R': 1, 'G': 1, 'B': 1}"
ck "tint: no warning" sh -c "[ ! -s tint.err ]"
"$bin" compare ref.exr tint.exr --fit rgb >tint.txt 2>&1
ck "tint: text states the three factors" grep -q "best per-channel fit: test R x 2, G x 1, B x 0.5 " tint.txt
# the single scale (the older spellings too) cannot undo a tint
for spelling in "--fit scale" "--fit-scale" "--fit"; do
    "$bin" compare ref.exr tint.exr $spelling --json >one.json 2>/dev/null
    ck "$spelling: one factor, an error left" json one.json \
        "d['fitted']['fit_mode'] == 'scale' and d['fitted']['scale_rgb']['R'] == d['fitted']['scale_rgb']['B'] and d['fitted']['channels']['RGB']['rmse'] > 0.01"
done
"$bin" compare --fit ref.exr tint.exr --json >bare.json 2>/dev/null
ck "a bare --fit before REF: scale, REF still read" json bare.json "d['fitted']['fit_mode'] == 'scale'"
"$bin" compare ref.exr tint.exr --json >none.json 2>/dev/null
ck "compare's default: no fit" json none.json "'fitted' not in d and d['warnings'] == []"
expect 2 "--fit 'rgbx': use scale" compare ref.exr tint.exr --fit=rgbx

# 2. warnings: code in the JSON, one stderr line naming the file
warns() { # warns NAME CODE TEXT ARGS...: compare ARGS gives exactly the warning CODE
    name=$1 code=$2 text=$3; shift 3
    "$bin" compare "$@" --json >"$name.json" 2>"$name.err"
    ck "$name: exit 0" [ $? -eq 0 ]
    ck "$name: warning $code in the JSON" json "$name.json" "[w['code'] for w in d['warnings']] == ['$code']"
    ck "$name: one stderr line: $text" sh -c "[ \$(wc -l <$name.err) -eq 1 ] && grep -qF -- '$text' $name.err"
    cat "$name.err"
}
warns vflip flipped_vertically "godrays compare: warning: test vflip.exr: matches the reference better upside down" \
    ref.exr vflip.exr
warns hflip flipped_horizontally "warning: test hflip.exr: matches the reference better mirrored left-right" \
    ref.exr hflip.exr
warns clip clipped_test "warning: test clip.png: 47.57 % of the pixels" ref.exr clip.png
warns lin srgb_looks_linear "warning: test lin.png: decoded from sRGB, but its values look linear" ref.exr lin.png
warns nolin linear_looks_srgb "but its values look sRGB-encoded" ref.exr good.png --no-linearize
warns dim scale_out_of_range "the best scale fit is test x 50" ref.exr dim.exr
ck "clip: the fraction among the checks" json clip.json "abs(d['capture_checks']['test_top_code_fraction'] - 2466 / 5184) < 1e-9"

# 3. the correct capture: no warning anywhere, metrics.json says so too
"$bin" compare ref.exr good.png --fit rgb -o res >good.txt 2>good.err
ck "good: exit 0" [ $? -eq 0 ]
ck "good: stderr empty" sh -c "[ ! -s good.err ]"
ck "good: metrics.json has an empty warnings array" json res/metrics.json "d['warnings'] == []"
ck "good: the slope as read is 1" json res/metrics.json "abs(d['capture_checks']['test_log_slope_as_read'] - 1) < 0.02"
ck "good: factors near 1" json res/metrics.json "all(abs(v - 1) < 0.01 for v in d['fitted']['scale_rgb'].values())"
exit $fail
