#!/bin/sh
# docs/engines.md's worked example as a test: `godrays export` gives the engine the scene, "the
# engine" (here `godrays shafts`) renders the god-ray layer at the scene's size and camera, the
# capture is stored the way engines write it (EXR, RGBA, half float, via OpenImageIO's oiiotool),
# and `godrays compare TRUTH CAPTURE` scores it. Oracle: the same comparison of the float32
# original; every metric of the half-float RGBA capture must agree with it within half-float
# rounding (relative 2e-3), the fitted scale too; a capture of another size exits 2.
# Env (set by ctest): GODRAYS_BINARY, GODRAYS_SOURCE_DIR, GODRAYS_TEST_OUT.
bin=${GODRAYS_BINARY:?}
src=${GODRAYS_SOURCE_DIR:?}
tmp=$(mktemp -d "${GODRAYS_TEST_OUT:-/tmp}/export_compare.XXXXXX")
fail=0
die() { echo "FAIL: $*"; fail=1; }
scene="$src/data/scenes/default.json"
size="--set camera.width=96 --set camera.height=54"

# 1. export: the constants the engine needs (and the glTF), at the capture's size
"$bin" export "$scene" $size --constants "$tmp/constants.json" --gltf "$tmp/scene.glb" --grid 64 2>"$tmp/err" \
    || die "export: $(cat "$tmp/err")"
grep -q '"width":	96' "$tmp/constants.json" || die "constants.json: width is not the capture's 96"

# 2. the truth (reduced settings: this test is about the file path, not accuracy)
"$bin" reference "$scene" $size -o "$tmp/truth.exr" --spp 2 --surface-res 64 --steps 32 \
    --set reference.bias_probe=false --quiet --no-preview 2>"$tmp/err" || die "reference: $(cat "$tmp/err")"

# 3. "the engine": a float32 RGB layer, then the capture as engines write it: RGBA half
"$bin" shafts "$scene" $size -o "$tmp/engine_f32.exr" -q --no-preview 2>"$tmp/err" || die "shafts: $(cat "$tmp/err")"
oiiotool "$tmp/engine_f32.exr" --ch R,G,B,A=1.0 -d half -o "$tmp/capture.exr" || die "oiiotool conversion failed"
info=$(oiiotool --info "$tmp/capture.exr")
echo "capture: $info"
echo "$info" | grep -q '96 x   54, 4 channel, half openexr' || die "capture is not a 96x54 RGBA half EXR: $info"

# 4. compare both against the truth, with the fitted scale (an engine's units may differ)
"$bin" compare "$tmp/truth.exr" "$tmp/capture.exr" --fit-scale --json >"$tmp/half.json" 2>"$tmp/err" \
    || die "compare (half RGBA capture): $(cat "$tmp/err")"
"$bin" compare "$tmp/truth.exr" "$tmp/engine_f32.exr" --fit-scale --json >"$tmp/f32.json" 2>"$tmp/err" \
    || die "compare (float original): $(cat "$tmp/err")"
"$bin" compare "$tmp/truth.exr" "$tmp/capture.exr" --fit-scale >"$tmp/table.txt" 2>&1 || die "compare table"
grep -q 'mean ref' "$tmp/table.txt" || die "compare printed no table"
node -e '
const h = require(process.argv[1]), f = require(process.argv[2]);
let worst = 0, what = "";
function cmp(a, b, path) {
  for (const k of ["rmse", "mae", "bias", "ref_mean", "test_mean", "max_abs_error"]) {
    const r = Math.abs(a[k] - b[k]) / Math.max(Math.abs(b[k]), 1e-6);
    if (!(r <= worst)) { worst = r; what = path + "." + k; }
  }
}
for (const set of ["metrics", "fitted"])
  for (const c of ["R", "G", "B", "RGB", "Y"]) cmp(h[set].channels[c], f[set].channels[c], set + "." + c);
const rs = Math.abs(h.fitted.scale - f.fitted.scale) / f.fitted.scale;
console.log(`half RGBA capture vs float32: worst relative metric difference ${worst.toExponential(2)} (${what}), ` +
            `fitted scale ${h.fitted.scale} vs ${f.fitted.scale}`);
if (!(h.scored_pixels === 96 * 54 && f.scored_pixels === h.scored_pixels)) { console.log("FAIL: pixel counts"); process.exit(1); }
if (!(worst <= 2e-3 && rs <= 2e-3)) { console.log("FAIL: metrics differ by more than half-float rounding"); process.exit(1); }
' "$tmp/half.json" "$tmp/f32.json" || die "half capture metrics differ from the float original's"

# 5. a capture at another resolution is refused (exit 2, one line)
oiiotool "$tmp/capture.exr" --resize 48x27 -o "$tmp/small.exr" || die "oiiotool resize failed"
"$bin" compare "$tmp/truth.exr" "$tmp/small.exr" >"$tmp/out" 2>"$tmp/err"
rc=$?
[ "$rc" -eq 2 ] || die "size mismatch: exit $rc, want 2"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || die "size mismatch: $(wc -l <"$tmp/err") stderr lines"
echo "size mismatch: $(cat "$tmp/err")"

[ "$fail" -eq 0 ] && rm -rf "$tmp"
exit $fail
