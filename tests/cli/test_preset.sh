#!/bin/sh
# Presets (docs/tuning.md "Presets", src/tune/preset.h): --preset applies a technique's
# settings as overrides. Independent expectation: the same settings given as --set overrides
# render the same pixels (idiff, zero tolerance); a bad preset exits 2 naming the file and
# the JSON path; a later --set wins over the preset; export --constants and render take it;
# render --repeat reports the median after a warm-up with its spread and GL_RENDERER.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
scene="$src/data/scenes/default.json"
small="--size 96x54 --no-preview -q"
# a value that needs 17 digits to read back (1/1.2), a choice, a boolean and an RGB
cat >"$dir/p.json" <<'J'
{"godrays_preset": 1, "technique": "shafts",
 "settings": {"K": 0.83333333333333337, "g": 0.61, "target_format": "rgba16f", "caps": false,
              "extinction": [0.1, 0.2, 0.3]},
 "timed": {"renderer": "llvmpipe", "width": 160, "height": 90}}
J
"$bin" render --preset "$dir/p.json" "$scene" $small -o "$dir/a.exr" || { echo "FAIL: render --preset SCENE exit $?"; fail=1; }
"$bin" render shafts "$scene" $small -o "$dir/b.exr" --set shafts.K=0.83333333333333337 --set shafts.g=0.61 \
  --set 'shafts.target_format="rgba16f"' --set shafts.caps=false --set 'shafts.extinction=[0.1,0.2,0.3]' || fail=1
"$bin" render shafts "$scene" $small -o "$dir/c.exr" || fail=1
if command -v idiff >/dev/null 2>&1; then
  idiff -fail 0 -failpercent 0 -warn 0 "$dir/a.exr" "$dir/b.exr" >"$dir/d" 2>&1 ||
    { echo "FAIL: --preset and the same --set overrides differ:"; cat "$dir/d"; fail=1; }
  idiff -fail 0 -failpercent 0 -warn 0 "$dir/a.exr" "$dir/c.exr" >/dev/null 2>&1 &&
    { echo "FAIL: the preset changed nothing (same image as the scene's settings)"; fail=1; }
  # a later --set wins: the preset with K back to the scene's 1.2 ... differs from a
  "$bin" render shafts --preset "$dir/p.json" "$scene" $small -o "$dir/e.exr" --set shafts.K=1.2 || fail=1
  idiff -fail 0 -failpercent 0 -warn 0 "$dir/a.exr" "$dir/e.exr" >/dev/null 2>&1 &&
    { echo "FAIL: --set after --preset did not win"; fail=1; }
fi
# bad presets: exit 2, one line naming the file and the JSON path
check_bad() { # NAME JSON EXPECTED
  printf '%s\n' "$2" >"$dir/$1.json"
  "$bin" render --preset "$dir/$1.json" "$scene" $small -o "$dir/x.exr" 2>"$dir/err"
  rc=$?
  [ "$rc" -eq 2 ] || { echo "FAIL: $1: exit $rc, expected 2"; fail=1; }
  grep -q "$1.json.*$3" "$dir/err" || { echo "FAIL: $1: message lacks '$3':"; cat "$dir/err"; fail=1; }
}
check_bad badtype '{"technique": "shafts", "settings": {"K": "x"}}' 'settings.K: expected a number'
check_bad badkey '{"technique": "shafts", "settings": {"nope": 1}}' 'settings.nope: not a setting'
check_bad badtech '{"technique": "nope", "settings": {}}' "technique: unknown technique"
check_bad notjson '{"technique": ' 'malformed JSON'
check_bad range '{"technique": "shafts", "settings": {"K": -1}}' 'shafts.K: must be'
"$bin" render radial_blur --preset "$dir/p.json" "$scene" $small -o "$dir/x.exr" 2>"$dir/err"
[ $? -eq 2 ] && grep -q "a preset of technique shafts, not radial_blur" "$dir/err" ||
  { echo "FAIL: a preset of another technique:"; cat "$dir/err"; fail=1; }
# export --constants takes it (K reaches seed 000's constants)
"$bin" export "$scene" --preset "$dir/p.json" --constants "$dir/k.json" || { echo "FAIL: export --preset"; fail=1; }
"$bin" export "$scene" --constants "$dir/k0.json" || fail=1
cmp -s "$dir/k.json" "$dir/k0.json" && { echo "FAIL: export --constants ignored the preset"; fail=1; }
# render --repeat: warm timing (realtime/timing.h)
"$bin" render shafts "$scene" --size 96x54 --no-preview --repeat 3 -o "$dir/r.exr" >"$dir/out" || fail=1
grep -q "median of 3 after 1 warm-up; [0-9.]*-[0-9.]*; " "$dir/out" || { echo "FAIL: render --repeat line:"; cat "$dir/out"; fail=1; }
[ "$fail" -eq 0 ] && echo "preset: all checks passed"
exit "$fail"
