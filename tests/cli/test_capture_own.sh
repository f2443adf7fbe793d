#!/bin/sh
# No false alarm on the project's own renders: `godrays compare` of the default scene's ground
# truth (96 x 54) against each built-in technique rendered at the same view says nothing about
# flips (docs/metrics.md, "Capture warnings"). The truth's own sRGB preview PNG gives no flip,
# transfer or scale warning (its exposure clips the sun's core by design: that one is said).
set -u
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
cd "$dir" || exit 1
command -v python3 >/dev/null || { echo "FAIL: python3 not found"; exit 1; }
scene="$src/data/scenes/default.json"
"$bin" reference "$scene" --size 96x54 -q -o truth.exr >/dev/null 2>ref.err || { cat ref.err; echo "FAIL: reference"; exit 1; }
n=0
for t in $("$bin" techniques 2>/dev/null | awk '$2 == "(built-in)" {print $1}'); do
    n=$((n + 1))
    "$bin" render "$t" "$scene" --size 96x54 -q --no-preview -o "$t.exr" >/dev/null 2>"$t.render.err" ||
        { cat "$t.render.err"; echo "FAIL: render $t"; fail=1; continue; }
    "$bin" compare truth.exr "$t.exr" --metric basic --json >"$t.json" 2>"$t.err"
    ck "$t: exit 0" [ $? -eq 0 ]
    ck "$t: no flip warning (stderr)" sh -c "! grep -q 'flipped\|upside down\|mirrored' $t.err"
    ck "$t: no flip warning (JSON)" python3 -c "
import json, sys
d = json.load(open('$t.json'))
codes = [w['code'] for w in d['warnings']]
c = d['capture_checks']
print('  $t: warnings', codes, 'as given %.3f, upside down %.3f, mirrored %.3f' % (
    c['rel_rmse_y_fit_as_given'], c['rel_rmse_y_fit_flipped_vertically'], c['rel_rmse_y_fit_flipped_horizontally']))
sys.exit(0 if not [k for k in codes if k.startswith('flipped')] else 1)"
done
ck "six built-in techniques or more" [ "$n" -ge 6 ]
"$bin" compare truth.exr truth.png --json >png.json 2>png.err
ck "the truth's preview PNG: exit 0" [ $? -eq 0 ]
ck "the truth's preview PNG: no warning but clipping, the right transfer" python3 -c "
import json, sys
d = json.load(open('png.json'))
print('  preview:', d['warnings'], d['capture_checks'])
sys.exit(0 if [w['code'] for w in d['warnings'] if w['code'] != 'clipped_test'] == [] and
         abs(d['capture_checks']['test_log_slope_as_read'] - 1) < 0.05 else 1)"
exit $fail
