#!/bin/sh
# `godrays shafts` error handling: bad settings and usage exit 2 with one stderr line that
# names the input; a shader that fails to compile exits 1 with the GLSL log on that line;
# nothing is written in either case.
. "$(dirname "$0")/lib.sh"
cat >"$dir/s.json" <<'JSON'
{"name": "small", "water": {"waves": [{"amplitude_m": 0.1, "wavelength_m": 8, "direction_deg": 30}]},
 "sun": {"elevation_deg": 60, "azimuth_deg": 30},
 "medium": {"absorption_per_m": [0.3, 0.06, 0.03], "scattering_per_m": 0.03, "g": 0.8},
 "camera": {"position_m": [0, -8, 0], "yaw_deg": 30, "pitch_deg": 60, "fov_deg": 60, "width": 64, "height": 36}}
JSON
o="$dir/x.exr"
expect 2 "shafts.N" shafts "$dir/s.json" -o "$o" --set shafts.N=0
expect 2 "shafts.N" shafts "$dir/s.json" -o "$o" --set shafts.N=1
expect 2 "shafts.K" shafts "$dir/s.json" -o "$o" --set shafts.K=0
expect 2 "shafts.K" shafts "$dir/s.json" -o "$o" --set shafts.K=-0.5
expect 2 "shafts.target_scale" shafts "$dir/s.json" -o "$o" --set shafts.target_scale=0
expect 2 "shafts.no_such_key" shafts "$dir/s.json" -o "$o" --set shafts.no_such_key=1
expect 2 "shafts.target_format" shafts "$dir/s.json" -o "$o" --set shafts.target_format=rgb565
expect 2 "--set" shafts "$dir/s.json" -o "$o" --set shafts.K
expect 2 "--frames" shafts "$dir/s.json" -o "$o" --frames 5:1:1
expect 2 "--shader-dir" shafts "$dir/s.json" -o "$o" --shader-dir "$dir/no_such_dir"
expect 2 "no scene" shafts -o "$o"
expect 2 "camera.position_m" shafts "$dir/s.json" -o "$o" --set "camera.position_m=[0, 2, 0]"
expect 2 "shafts.grid_eye_m" shafts "$dir/s.json" -o "$o" --set "shafts.grid_eye_m=[0, 2, 0]"
expect 2 "shafts.grid_eye_m[0]" shafts "$dir/s.json" -o "$o" --set "shafts.grid_eye_m=[1e300, -8, 0]"
# A shader that does not compile: exit 1, the file name and the driver's log on one line.
mkdir "$dir/shaders"
printf '#version 330 core\nout vec4 o;\nvoid main() { o = vec4(undeclared_thing, 1.0); }\n' >"$dir/shaders/shafts_final.frag.glsl"
expect 1 "shafts_final.frag.glsl: GLSL compile failed" shafts "$dir/s.json" -o "$o" --shader-dir "$dir/shaders"
grep -q "undeclared_thing" "$dir/err" || { echo "FAIL: the GLSL log does not name the bad identifier"; fail=1; }
# A shader that compiles but does not link (no main function).
printf '#version 330 core\nout vec4 o;\nvoid not_main() { o = vec4(1.0); }\n' >"$dir/shaders/shafts_final.frag.glsl"
expect 1 "GLSL link failed" shafts "$dir/s.json" -o "$o" --shader-dir "$dir/shaders"
if ls "$dir"/x* >/dev/null 2>&1; then echo "FAIL: a failed run left output files"; fail=1; fi
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
