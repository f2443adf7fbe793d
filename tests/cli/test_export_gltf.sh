#!/bin/sh
# `godrays export --gltf`: the exported default scene (.gltf + .bin, and .glb with --frames)
# passes Khronos' glTF-Validator with zero errors; a second reader (tests/gltf/check_gltf.mjs,
# its own JSON/GLB parsing) finds the water vertices on the Gerstner surface recomputed from the
# exported wave constants within 1e-5 m and the camera and sun where the scene's angles put
# them. Bad input: exit 2 with one line, nothing written.
# Needs node and build-tools/node_modules/gltf-validator (scripts/setup.sh installs both).
# Env (set by ctest): GODRAYS_BINARY, GODRAYS_SOURCE_DIR, GODRAYS_TEST_OUT.
bin=${GODRAYS_BINARY:?}
src=${GODRAYS_SOURCE_DIR:?}
tmp=$(mktemp -d "${GODRAYS_TEST_OUT:-/tmp}/export_gltf.XXXXXX")
tools="$src/build-tools"
fail=0
die() { echo "FAIL: $*"; fail=1; }
scene="$src/data/scenes/default.json"

if [ ! -f "$tools/node_modules/gltf-validator/package.json" ] || ! command -v node >/dev/null 2>&1; then
    echo "FAIL: node or $tools/node_modules/gltf-validator missing: run scripts/setup.sh"
    exit 1
fi

# 1. the default scene as .gltf + .bin, default mesh (512 cells)
"$bin" export "$scene" --gltf "$tmp/default.gltf" >"$tmp/out" 2>"$tmp/err" || die "export .gltf: $(cat "$tmp/err")"
[ -s "$tmp/default.bin" ] || die ".gltf export wrote no default.bin"
node "$src/tests/gltf/check_gltf.mjs" "$tools" "$tmp/default.gltf" 1e-5 >"$tmp/gltf.json" || die "default.gltf: check_gltf failed"

# 2. .glb with an animation of 6 frames as morph targets (a coarser mesh keeps it short)
"$bin" export "$scene" --gltf "$tmp/anim.glb" --frames 0:0.5:0.1 --grid 128 >"$tmp/out" 2>"$tmp/err" \
    || die "export .glb --frames: $(cat "$tmp/err")"
node "$src/tests/gltf/check_gltf.mjs" "$tools" "$tmp/anim.glb" 1e-5 >"$tmp/glb.json" || die "anim.glb: check_gltf failed"
grep -aq '"water_times_s":\[0,0.1,0.2,0.3,0.4,0.5\]' "$tmp/anim.glb" || die "anim.glb: frame times not 0:0.5:0.1"

# 3. a scene far from the origin (1e5 m) keeps its surface within 1e-5 m (node translation +
#    float offsets)
"$bin" export "$src/data/scenes/hard/far_offset.json" --gltf "$tmp/far.glb" --grid 64 >"$tmp/out" 2>"$tmp/err" \
    || die "export far_offset: $(cat "$tmp/err")"
node "$src/tests/gltf/check_gltf.mjs" "$tools" "$tmp/far.glb" 1e-5 >/dev/null || die "far.glb: check_gltf failed"

# 4. bad input: exit 2, one line naming the problem, no output file
expect2() { # WHAT OUTFILE ARGS...: exit 2, one stderr line, OUTFILE absent
    what=$1; outfile=$2; shift 2
    "$bin" export "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    [ "$rc" -eq 2 ] || die "$what: exit $rc, want 2"
    [ "$(wc -l <"$tmp/err")" -eq 1 ] || die "$what: stderr has $(wc -l <"$tmp/err") lines, want 1"
    grep -q '^godrays export: ' "$tmp/err" || die "$what: stderr is not 'godrays export: ...': $(cat "$tmp/err")"
    [ -s "$tmp/out" ] && die "$what: stdout not empty"
    [ -e "$outfile" ] && die "$what: wrote $outfile"
    echo "$what: $(cat "$tmp/err")"
}
expect2 "unknown extension" "$tmp/x.obj" "$scene" --gltf "$tmp/x.obj"
grep -q 'unknown extension' "$tmp/err" || die "unknown extension: message lacks the reason"
expect2 "unwritable path" "$tmp/no/such/dir/x.gltf" "$scene" --gltf "$tmp/no/such/dir/x.gltf"
grep -q 'no/such/dir' "$tmp/err" || die "unwritable path: message does not name the path"
expect2 "frames B < A" "$tmp/f1.glb" "$scene" --gltf "$tmp/f1.glb" --frames 1:0:0.1
expect2 "frames S = 0" "$tmp/f2.glb" "$scene" --gltf "$tmp/f2.glb" --frames 0:1:0
expect2 "frames not numbers" "$tmp/f3.glb" "$scene" --gltf "$tmp/f3.glb" --frames a:b:c
expect2 "frames too many" "$tmp/f4.glb" "$scene" --gltf "$tmp/f4.glb" --frames 0:100:0.01
grep -q -- '--frames' "$tmp/err" || die "frames: message does not name --frames"
expect2 "frames without --gltf" "$tmp/c.json" "$scene" --constants "$tmp/c.json" --frames 0:1:0.5
expect2 "nothing to export" "$tmp/none" "$scene"
expect2 "bad grid" "$tmp/g.glb" "$scene" --gltf "$tmp/g.glb" --grid 0
expect2 "bad scene override" "$tmp/s.glb" "$scene" --gltf "$tmp/s.glb" --set medium.g=2
expect2 "camera above water for --constants" "$tmp/a.json" "$scene" --constants "$tmp/a.json" \
    --set 'camera.position_m=[0,5,0]'
grep -q 'camera.position_m' "$tmp/err" || die "camera above water: message does not name camera.position_m"

# nothing half-written anywhere: no temporary files left behind
ls "$tmp" | grep -q 'tmp-' && die "temporary files left: $(ls "$tmp" | grep 'tmp-')"

[ "$fail" -eq 0 ] && rm -rf "$tmp"
exit $fail
