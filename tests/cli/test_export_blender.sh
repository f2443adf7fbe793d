#!/bin/sh
# Blender round trip of `godrays export --gltf` (docs/engines.md, "Blender"): Debian's blender in
# background mode imports the exported default scene (.glb with 3 frames, and .gltf) with its own
# glTF importer; tests/gltf/blender_check.py checks camera and sun within 1e-4 of the scene.
# Needs blender and python3-numpy (scripts/setup.sh installs both).
# Env (set by ctest): GODRAYS_BINARY, GODRAYS_SOURCE_DIR, GODRAYS_TEST_OUT.
bin=${GODRAYS_BINARY:?}
src=${GODRAYS_SOURCE_DIR:?}
tmp=$(mktemp -d "${GODRAYS_TEST_OUT:-/tmp}/export_blender.XXXXXX")
fail=0
die() { echo "FAIL: $*"; fail=1; }
command -v blender >/dev/null 2>&1 || { echo "FAIL: blender missing: run scripts/setup.sh"; exit 1; }

for scene in default low_sun; do
    for ext in glb gltf; do
        out="$tmp/$scene.$ext"
        "$bin" export "$src/data/scenes/$scene.json" --gltf "$out" --grid 32 --frames 0:0.2:0.1 2>"$tmp/err" \
            || die "export $out: $(cat "$tmp/err")"
        blender -b --factory-startup --python "$src/tests/gltf/blender_check.py" -- \
            "$out" "$src/data/scenes/$scene.json" 3 >"$tmp/log" 2>&1
        rc=$?
        grep -E '^(blender_check|FAIL)' "$tmp/log"
        [ "$rc" -eq 0 ] && grep -q '^blender_check: ' "$tmp/log" \
            || { tail -20 "$tmp/log"; die "$scene.$ext: Blender check failed (exit $rc)"; }
    done
done

[ "$fail" -eq 0 ] && rm -rf "$tmp"
exit $fail
