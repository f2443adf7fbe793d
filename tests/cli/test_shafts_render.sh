#!/bin/sh
# `godrays shafts` end to end on a small scene: an EXR and a PNG preview, timings printed
# and stored in the EXR metadata, --set reaching the renderer, --shader-dir overriding a
# shader, and --frames writing one numbered file per frame whose images differ as the
# waves move.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
small="--set camera.width=96 --set camera.height=54"
"$bin" shafts "$src/data/scenes/default.json" -o "$dir/a.exr" $small --set shafts.K=0.7 >"$dir/out" 2>"$dir/err"
rc=$?
cat "$dir/out" "$dir/err"
[ "$rc" -eq 0 ] || { echo "FAIL: exit $rc"; fail=1; }
[ -s "$dir/a.exr" ] || { echo "FAIL: no EXR"; fail=1; }
[ -s "$dir/a.png" ] || { echo "FAIL: no PNG preview beside the EXR"; fail=1; }
grep -q "GPU ms: shadow" "$dir/out" || { echo "FAIL: no timings printed"; fail=1; }
grep -q "fragments [1-9]" "$dir/out" || { echo "FAIL: no fragment count printed"; fail=1; }
if command -v iinfo >/dev/null 2>&1; then
  iinfo -v "$dir/a.exr" >"$dir/info" 2>&1
  for key in godrays:renderer godrays:scene_hash godrays:gpu_ns.shadow godrays:gpu_ns.shafts godrays:gpu_ns.final \
             godrays:cpu_ms godrays:fragments_blended godrays:vertices_submitted godrays:shafts.N godrays:shafts.extinction; do
    grep -q "$key" "$dir/info" || { echo "FAIL: EXR metadata lacks $key"; fail=1; }
  done
  grep -q 'godrays:shafts.K: 0.7' "$dir/info" || { echo "FAIL: --set shafts.K=0.7 is not in the metadata"; grep 'shafts.K' "$dir/info"; fail=1; }
  iinfo "$dir/a.exr" | grep -q "96 x   54" || { echo "FAIL: EXR is not 96 x 54: $(iinfo "$dir/a.exr")"; fail=1; }
fi
# --shader-dir: a modified final pass (everything 0.25) must show in the image.
mkdir "$dir/shaders"
printf '#version 330 core\nin vec4 v_uv[2];\nin vec4 v_view;\nout vec4 o;\nvoid main() { o = vec4(0.25); }\n' \
  >"$dir/shaders/shafts_final.frag.glsl"
"$bin" shafts "$src/data/scenes/default.json" -o "$dir/m.exr" $small --shader-dir "$dir/shaders" -q || { echo "FAIL: --shader-dir run"; fail=1; }
if command -v oiiotool >/dev/null 2>&1; then
  oiiotool "$dir/m.exr" --printstats 2>/dev/null | grep -q "Max: 0.250* 0.250* 0.250*" ||
    { echo "FAIL: the overriding shader did not run:"; oiiotool "$dir/m.exr" --printstats | grep -E "Min|Max"; fail=1; }
fi
# --frames: three numbered files at t = 0, 0.5, 1 s (fps 2), not all the same.
"$bin" shafts "$src/data/scenes/default.json" -o "$dir/f.exr" $small --frames 0:4:2 --fps 4 --no-preview -q ||
  { echo "FAIL: --frames run"; fail=1; }
for f in 0000 0002 0004; do [ -s "$dir/f.$f.exr" ] || { echo "FAIL: no f.$f.exr"; fail=1; }; done
[ -e "$dir/f.0001.exr" ] && { echo "FAIL: frame 1 written with step 2"; fail=1; }
[ -e "$dir/f.0000.png" ] && { echo "FAIL: --no-preview wrote a PNG"; fail=1; }
if cmp -s "$dir/f.0000.exr" "$dir/f.0004.exr"; then echo "FAIL: frames 0 and 4 are identical"; fail=1; fi
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
