#!/bin/sh
# The radial blurs through the CLI: `godrays techniques` lists both; `godrays render` writes a
# finite EXR for each; bad settings (scene section or --set) exit 2 with one stderr line naming
# the setting, through the scene loader; a shader that fails to compile exits 1 with its GLSL
# log; nothing is written then.
. "$(dirname "$0")/lib.sh"
small_scene "$dir/s.json" 64 36 '"radial_blur": {"samples": 40, "decay": 0.95}'
list=$("$bin" techniques) || { echo "FAIL: techniques exits $?"; fail=1; }
for t in radial_blur radial_blur_local; do
  echo "$list" | grep -q "^$t\b\|^ *$t " || { echo "FAIL: techniques does not list $t"; fail=1; }
  "$bin" render $t "$dir/s.json" -o "$dir/$t.exr" >"$dir/out" 2>"$dir/err" || { echo "FAIL: render $t: $(cat "$dir/err")"; fail=1; }
  [ -s "$dir/$t.exr" ] || { echo "FAIL: render $t wrote no EXR"; fail=1; }
done
o="$dir/bad.exr"
expect 2 "radial_blur.decay" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.decay=0
expect 2 "radial_blur.decay" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.decay=1.5
expect 2 "radial_blur.samples" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.samples=0
expect 2 "radial_blur.density" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.density=-1
expect 2 "radial_blur.target_format" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.target_format=rgb565
expect 2 "radial_blur.no_such_key" render radial_blur "$dir/s.json" -o "$o" --set radial_blur.no_such_key=1
expect 2 "radial_blur_local.lights" render radial_blur_local "$dir/s.json" -o "$o" --set radial_blur_local.lights=0
expect 2 "radial_blur_local.quad_size" render radial_blur_local "$dir/s.json" -o "$o" --set radial_blur_local.quad_size=0
expect 2 "radial_blur_local.falloff" validate "$dir/s.json" --set radial_blur_local.falloff=-2
sed 's/"samples": 40, "decay": 0.95/"samples": 40, "decay": 2/' "$dir/s.json" >"$dir/section.json"
expect 2 "section.json: radial_blur.decay" render radial_blur "$dir/section.json" -o "$o"
expect 2 "camera.position_m" render radial_blur "$dir/s.json" -o "$o" --set "camera.position_m=[0, 2, 0]"
# A blur shader that does not compile (--shader-dir): exit 1, the file and the GLSL log on one line.
mkdir "$dir/shaders"
printf '#version 330 core\nout vec4 o;\nvoid main() { o = vec4(undeclared_thing, 1.0); }\n' >"$dir/shaders/radial_blur.frag.glsl"
expect 1 "radial_blur.frag.glsl: GLSL compile failed" render radial_blur "$dir/s.json" -o "$o" --shader-dir "$dir/shaders"
grep -q "undeclared_thing" "$dir/err" || { echo "FAIL: the GLSL log does not name the bad identifier"; fail=1; }
if ls "$dir"/bad* >/dev/null 2>&1; then echo "FAIL: a failed run left output files"; fail=1; fi
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
