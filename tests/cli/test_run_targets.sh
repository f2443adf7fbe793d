#!/bin/sh
# `run --save-targets` (issue 29, item 3): the report shows each technique's intermediate
# render targets as a strip. For tests/techniques/light_blur at 64x36 the strip holds the
# harness's sun_light (its manifest's scale 0.5: 32x18) and its target out (64x36), 4 px
# apart, top-aligned: 100 x 36 pixels (docs/techniques.md "Seeing every target"). Without the
# option (the default) no strip is written or shown.
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
set -- run "$src/data/scenes/default.json" --size 64x36 --set reference.surface_res=64 --set reference.sun_samples=2 \
    --set reference.batches=2 --set reference.steps=16 --technique-dir "$src/tests/techniques/light_blur" \
    --techniques light_blur -q
"$bin" "$@" --save-targets -o "$dir/a" >"$dir/out" 2>"$dir/err"
ck "run --save-targets exits 0" [ $? -eq 0 ]
ck "the strip is 100 x 36 (sun_light 32x18, 4 px, out 64x36)" sh -c \
    "file '$dir/a/light_blur_targets.png' | grep -q 'PNG image data, 100 x 36,'"
ck "the page shows it" grep -q '<img src="light_blur_targets.png" alt="render targets" width="100" height="36">' \
    "$dir/a/index.html"
"$bin" "$@" -o "$dir/b" >"$dir/out" 2>"$dir/err"
ck "run without it exits 0" [ $? -eq 0 ]
ck "... writes no strip" [ ! -e "$dir/b/light_blur_targets.png" ]
ck "... and the page has none" sh -c "! grep -q 'render targets' '$dir/b/index.html'"
exit $fail
