#!/bin/sh
# The harness's light texture (docs/techniques.md "Harness textures", issue 29): a user
# technique that runs radial_blur's blur over the "sun_light" input (tests/techniques/light_blur)
# gives radial_blur's image byte for byte, at the defaults and with other blur settings, on two
# scenes (one under GODRAYS_TEST_REDUCED): the light is the same program (realtime/toolkit.h gr_light_pass) and u_sun_light_units
# the same scale. The oracle is OpenImageIO's idiff at zero tolerance. Then compare --scene
# on a scene with light_blur's section works with --technique-dir.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
tech="$src/tests/techniques/light_blur"
fail=0
same() { # NAME SCENE [SETTINGS...]: radial_blur and light_blur with the same settings
  name=$1; scene=$2; shift 2
  rb="" lb=""
  for kv in "$@"; do rb="$rb --set radial_blur.$kv"; lb="$lb --set light_blur.$kv"; done
  # shellcheck disable=SC2086
  "$bin" render radial_blur "$src/data/scenes/$scene.json" --size 96x54 -q --no-preview $rb -o "$dir/rb.exr" \
      >/dev/null 2>"$dir/err" || { echo "FAIL: $name: radial_blur render"; cat "$dir/err"; fail=1; return; }
  # shellcheck disable=SC2086
  "$bin" render light_blur "$src/data/scenes/$scene.json" --technique-dir "$tech" --size 96x54 -q --no-preview $lb \
      -o "$dir/lb.exr" >/dev/null 2>"$dir/err" || { echo "FAIL: $name: light_blur render"; cat "$dir/err"; fail=1; return; }
  if idiff -fail 0 -failpercent 0 -warn 0 "$dir/rb.exr" "$dir/lb.exr" >"$dir/idiff" 2>&1; then
    echo "ok: $name: identical"
  else
    echo "FAIL: $name: light_blur differs from radial_blur"; tail -4 "$dir/idiff"; fail=1
  fi
}
same "default scene, defaults" default
[ -n "${GODRAYS_TEST_REDUCED:-}" ] || same "murky_coastal, defaults" murky_coastal
same "default scene, 16 taps, no dither, intensity 2" default samples=16 dither=false intensity=2

# compare --scene with a scene holding the user technique's section: needs --technique-dir
# (exit 2 naming it without), then works (issue 29)
sed '0,/{/s//{"light_blur": {"samples": 50},/' "$src/data/scenes/default.json" >"$dir/scene.json"
"$bin" compare "$dir/rb.exr" "$dir/lb.exr" --scene "$dir/scene.json" --set camera.width=96 --set camera.height=54 \
    >/dev/null 2>"$dir/err"; rc=$?
[ $rc -eq 2 ] && grep -qF -- "--technique-dir" "$dir/err" || { echo "FAIL: compare --scene without --technique-dir: exit $rc"; cat "$dir/err"; fail=1; }
"$bin" compare "$dir/rb.exr" "$dir/lb.exr" --scene "$dir/scene.json" --set camera.width=96 --set camera.height=54 \
    --technique-dir "$tech" >/dev/null 2>"$dir/err" && echo "ok: compare --scene --technique-dir" \
    || { echo "FAIL: compare --scene --technique-dir"; cat "$dir/err"; fail=1; }
exit $fail
