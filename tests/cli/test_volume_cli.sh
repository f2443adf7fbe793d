#!/bin/sh
# The volume techniques (slicing, froxel) through the CLI: listed by `godrays techniques`;
# `render` writes an EXR; bad settings exit 2 with one stderr line naming the setting
# (through the scene loader's table, file or --set), nothing written; `tune` runs on each
# (tiny image, 1 start, few evaluations).
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat >"$dir/s.json" <<'JSON'
{"name": "small", "water": {"waves": [{"amplitude_m": 0.1, "wavelength_m": 8, "direction_deg": 30}]},
 "sun": {"elevation_deg": 60, "azimuth_deg": 30},
 "medium": {"absorption_per_m": [0.3, 0.06, 0.03], "scattering_per_m": 0.03, "g": 0.8},
 "camera": {"position_m": [0, -8, 0], "yaw_deg": 30, "pitch_deg": 60, "fov_deg": 60, "width": 48, "height": 27},
 "occluders": [{"type": "sphere", "center_m": [-1.5, -3.5, 6], "radius_m": 1.2}],
 "slicing": {"slices": 16, "texture_size": 64, "grid": 32},
 "froxel": {"grid_x": 24, "grid_y": 14, "grid_z": 16, "texture_size": 64, "grid": 32}}
JSON
fail=0
list=$("$bin" techniques) || { echo "FAIL: techniques exits $?"; fail=1; }
for t in slicing froxel; do
  echo "$list" | grep -q "^$t\b\|^ *$t " || { echo "FAIL: techniques does not list $t"; fail=1; }
  "$bin" render $t "$dir/s.json" -o "$dir/$t.exr" >"$dir/out" 2>"$dir/err" || { echo "FAIL: render $t: $(cat "$dir/err")"; fail=1; }
  [ -s "$dir/$t.exr" ] || { echo "FAIL: render $t wrote no EXR"; fail=1; }
done
expect() {
  want=$1; text=$2; shift 2
  "$bin" "$@" >"$dir/out" 2>"$dir/err"
  rc=$?
  lines=$(wc -l <"$dir/err")
  if [ "$rc" -ne "$want" ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$text" "$dir/err" || [ -s "$dir/out" ]; then
    echo "FAIL: $*: exit $rc (want $want), $lines stderr line(s) (want 1 containing '$text'):"
    cat "$dir/err"; fail=1
  else
    echo "ok: $*: $(cat "$dir/err")"
  fi
}
o="$dir/bad.exr"
expect 2 "slicing.slices" render slicing "$dir/s.json" -o "$o" --set slicing.slices=0
expect 2 "slicing.distribution" render slicing "$dir/s.json" -o "$o" --set slicing.distribution=cubic
expect 2 "slicing.g" render slicing "$dir/s.json" -o "$o" --set slicing.g=1
expect 2 "slicing.caustic_depths" render slicing "$dir/s.json" -o "$o" --set slicing.caustic_depths=65
expect 2 "slicing.caustic_last_m" render slicing "$dir/s.json" -o "$o" --set slicing.caustic_last_m=0.5
expect 2 "froxel.grid_z" render froxel "$dir/s.json" -o "$o" --set froxel.grid_z=0
expect 2 "froxel.near_m" render froxel "$dir/s.json" -o "$o" --set froxel.near_m=-1
expect 2 "froxel.jitter" render froxel "$dir/s.json" -o "$o" --set froxel.jitter=3
sed 's/"grid_z": 16/"grid_z": 1000/' "$dir/s.json" >"$dir/section.json"
expect 2 "section.json: froxel.grid_z" render froxel "$dir/section.json" -o "$o"
if ls "$dir"/bad* >/dev/null 2>&1; then echo "FAIL: a failed run left output files"; fail=1; fi
for p in slicing.extinction froxel.g; do
  if "$bin" tune "$dir/s.json" --params $p --starts 1 --max-evals 4 --size 32x18 --no-cache \
       --set reference.spp=1 --set reference.steps=16 -o "$dir/tune_$p" >"$dir/out" 2>"$dir/err"; then
    [ -s "$dir/tune_$p/tune.json" ] || { echo "FAIL: tune $p wrote no tune.json"; fail=1; }
    echo "ok: tune $p"
  else
    echo "FAIL: tune $p: $(tail -3 "$dir/err")"; fail=1
  fi
done
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
