#!/bin/sh
# A user technique through the CLI (docs/techniques.md): `techniques --technique-dir` lists the
# shipped example under its manifest's name with its settings; `render` writes its layer
# (the render itself refuses NaN, nothing drawn and all-zero layers) and takes --set on its
# settings (out of range: exit 2 naming NAME.KEY); run-time failures exit 1 with one line:
# an all-zero layer, a
# NaN layer and a pass that drew nothing each say so. Nothing is written on failure.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
ex="$src/data/techniques/shadow_march"
errs="$src/tests/techniques/gl_errors"
scene="$src/data/scenes/default.json"
fail=0

"$bin" techniques --technique-dir "$ex" >"$dir/out" 2>"$dir/err" || { echo "FAIL: techniques exit $?"; cat "$dir/err"; fail=1; }
for word in shadow_march extinction_scale caustics steps resolution_scale; do
  grep -qF "$word" "$dir/out" || { echo "FAIL: techniques output lacks $word"; fail=1; }
done
"$bin" techniques --json --technique-dir "$ex" >"$dir/json" 2>"$dir/err" || { echo "FAIL: techniques --json exit $?"; fail=1; }
grep -qF '"shadow_march"' "$dir/json" || { echo "FAIL: techniques --json lacks shadow_march"; fail=1; }

# a small, fast render: 64x36, 8 steps
"$bin" render shadow_march "$scene" --technique-dir "$ex" --size 64x36 --set shadow_march.steps=8 \
    -o "$dir/x.exr" >"$dir/out" 2>"$dir/err"
rc=$?
if [ $rc -ne 0 ] || [ ! -s "$dir/x.exr" ]; then echo "FAIL: render exit $rc"; cat "$dir/err"; fail=1; else echo "ok: render"; fi

# the walkthrough's port of GPU Gems 3's radial blur (docs/techniques.md) compiles and renders
"$bin" render walkthrough_radial "$scene" --technique-dir "$src/tests/techniques/walkthrough_radial" --size 64x36 \
    --set walkthrough_radial.samples=16 -o "$dir/w.exr" >"$dir/out" 2>"$dir/err"
rc=$?
if [ $rc -ne 0 ] || [ ! -s "$dir/w.exr" ]; then echo "FAIL: walkthrough render exit $rc"; cat "$dir/err"; fail=1; else echo "ok: walkthrough render"; fi

# expect CODE TEXT ARGS...: exit CODE, exactly one stderr line containing TEXT, empty stdout, no output file
expect() {
  want=$1; text=$2; shift 2
  rm -f "$dir/y.exr"
  "$bin" "$@" >"$dir/out" 2>"$dir/err"
  rc=$?
  lines=$(wc -l <"$dir/err")
  if [ "$rc" -ne "$want" ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$text" "$dir/err" || [ -s "$dir/out" ] || [ -e "$dir/y.exr" ]; then
    echo "FAIL: $*: exit $rc (want $want), $lines stderr line(s) (want 1 containing '$text'):"
    cat "$dir/err"; fail=1
  else
    echo "ok: $(cat "$dir/err")"
  fi
}
o="$dir/y.exr"
expect 2 "shadow_march.steps" render shadow_march "$scene" --technique-dir "$ex" --size 64x36 --set shadow_march.steps=0 -o "$o"
expect 2 "shadow_march.caustics" render shadow_march "$scene" --technique-dir "$ex" --size 64x36 --set shadow_march.caustics=2 -o "$o"
expect 2 "shadow_march.no_such" render shadow_march "$scene" --technique-dir "$ex" --size 64x36 --set shadow_march.no_such=1 -o "$o"
# GLSL compile errors (a log of several lines): cli.usertech_glsl
expect 1 "err_black: output 'out' is all zero" render err_black "$scene" --technique-dir "$errs/black" --size 64x36 -o "$o"
expect 1 "NaN or infinite" render err_nan "$scene" --technique-dir "$errs/nan" --size 64x36 -o "$o"
expect 1 "drew no fragment" render err_nothing_drawn "$scene" --technique-dir "$errs/nothing_drawn" --size 64x36 -o "$o"
exit $fail
