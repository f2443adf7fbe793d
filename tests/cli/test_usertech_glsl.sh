#!/bin/sh
# Shared GLSL and compiler errors of a user technique (docs/techniques.md "Shared GLSL",
# "Errors"; issue 29). A technique whose colour comes from three "defines" and two nested
# #include files renders exactly (0.25, 1, 0.5) (oiiotool's stats: an independent reader). A
# compile error exits 1 with a summary line and then one "FILE:LINE:COL: message" line per
# diagnostic, with the user's own file (an included one too) and the line in that file; an
# undeclared harness texture hints at the pass's inputs; a misspelt setting uniform gets "did
# you mean". Nothing is written on failure. --save-target writes every target in one strip.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
scene="$src/data/scenes/default.json"
errs="$src/tests/techniques/gl_errors"
fail=0

"$bin" render include_defines "$scene" --technique-dir "$src/tests/techniques/include_defines" --size 16x9 -q \
    --no-preview -o "$dir/x.exr" >/dev/null 2>"$dir/err" || { echo "FAIL: include_defines render"; cat "$dir/err"; fail=1; }
if command -v oiiotool >/dev/null 2>&1; then
  oiiotool --stats "$dir/x.exr" >"$dir/stats" 2>&1
  for row in "Stats Min: 0.250000 1.000000 0.500000" "Stats Max: 0.250000 1.000000 0.500000"; do
    grep -qF "$row" "$dir/stats" || { echo "FAIL: include_defines: no '$row' in:"; cat "$dir/stats"; fail=1; }
  done
  [ $fail -eq 0 ] && echo "ok: #include (nested) and defines give (0.25, 1, 0.5)"
fi

# glsl NAME LINE2 [MORE...]: render err_NAME exits 1, stderr's first line is the summary, its
# second line starts with LINE2 (a path relative to the folder), MORE appear somewhere
glsl() {
  name=$1; want=$2; shift 2
  rm -f "$dir/y.exr"
  "$bin" render "err_$name" "$scene" --technique-dir "$errs/$name" --size 16x9 -o "$dir/y.exr" >"$dir/out" 2>"$dir/err"
  rc=$?
  first=$(sed -n 1p "$dir/err"); second=$(sed -n 2p "$dir/err")
  ok=1
  [ $rc -eq 1 ] || ok=0
  case "$first" in *"passes[0] 'only': fragment shader does not compile ("*) ;; *) ok=0 ;; esac
  case "$second" in "  $errs/$name/$want"*) ;; *) ok=0 ;; esac
  for more in "$@"; do grep -qF -- "$more" "$dir/err" || ok=0; done
  [ -s "$dir/out" ] && ok=0
  [ -e "$dir/y.exr" ] && ok=0
  if [ $ok -eq 1 ]; then echo "ok: $name: $second"; else echo "FAIL: $name (exit $rc, want 1; second line '$want...'):"; cat "$dir/err"; fail=1; fi
}
glsl compile_error "f.frag:5:"
glsl include_error "lib/common.glsl:3:28: error: \`missing_factor' undeclared"
glsl undeclared_input "f.frag:3:25: error: \`t_eye_depth' undeclared" 'hint: add "eye_depth" to passes[0].inputs' \
    "candidate overloads listed by the driver left out"
glsl misspelt_uniform "f.frag:3:17: error: \`u_set_gian' undeclared (did you mean u_set_gain?)"

# --save-target: every target side by side (sun_light 8x5, 4 px, out 16x9): the strip's right
# part is the layer itself
if command -v oiiotool >/dev/null 2>&1 && command -v idiff >/dev/null 2>&1; then
  "$bin" render light_blur "$scene" --technique-dir "$src/tests/techniques/light_blur" --size 16x9 -q --no-preview \
      -o "$dir/lb.exr" --save-target "$dir/lbt.exr" 2>"$dir/err" || { echo "FAIL: --save-target render"; cat "$dir/err"; fail=1; }
  oiiotool --info "$dir/lbt.exr" | grep -q "28 x    9, 4 channel" || { echo "FAIL: --save-target strip size"; oiiotool --info "$dir/lbt.exr"; fail=1; }
  oiiotool "$dir/lbt.exr" --cut 16x9+12+0 --ch R,G,B -o "$dir/cut.exr" && oiiotool "$dir/lb.exr" --ch R,G,B -o "$dir/lb3.exr" &&
    idiff -fail 0 -failpercent 0 -warn 0 "$dir/cut.exr" "$dir/lb3.exr" >/dev/null 2>&1 \
    && echo "ok: --save-target: every target in a strip" || { echo "FAIL: --save-target: the strip's output part differs"; fail=1; }
fi

# techniques: the manifest's own type names, and NAME filters
"$bin" techniques shadow_march --technique-dir "$src/data/techniques/shadow_march" >"$dir/t" 2>&1 || { echo "FAIL: techniques NAME"; fail=1; }
grep -q "^shadow_march " "$dir/t" && ! grep -q "^radial_blur " "$dir/t" || { echo "FAIL: techniques shadow_march is not filtered"; fail=1; }
grep -q "shadow_march.steps  *int " "$dir/t" && grep -q "shadow_march.jitter  *bool " "$dir/t" \
    || { echo "FAIL: techniques does not print int/bool"; cat "$dir/t"; fail=1; }
"$bin" techniques no_such_technique >/dev/null 2>"$dir/err"; rc=$?
[ $rc -eq 2 ] && grep -qF "unknown technique 'no_such_technique'" "$dir/err" || { echo "FAIL: techniques NAME unknown: exit $rc"; fail=1; }
[ $fail -eq 0 ] && echo "ok: techniques NAME, int/bool"
exit $fail
