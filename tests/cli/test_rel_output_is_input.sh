#!/bin/sh
# Issue 31, findings 1 and 2 (docs/reliability.md, "Outputs"): no output may be the same file as
# an input (compared by device and inode, through symlinks and hard links), and no two outputs
# may share a file (the .bin a .gltf names and an EXR's PNG preview included). Each is refused
# with exit 2 and one line naming the flag and the file, and nothing is written or replaced.
# main: `merge a.part b.part -o a.part` replaced its part, `export S --constants S` its scene,
# `--gltf c.gltf --constants c.bin` wrote one over the other, all with exit 0.
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
small_scene S.json 16 9
cp S.json S0.json
fast="--set reference.surface_res=16 --set reference.bias_probe=false --set reference.spp=1 --set reference.sun_samples=2 --set reference.batches=2"
unchanged() { cmp -s "$1" "$2" || { echo "FAIL: $1 was changed"; fail=1; }; }
nothing() { for f in "$@"; do [ ! -e "$f" ] || { echo "FAIL: $f was written"; fail=1; }; done; }

# ---- an output that is an input -------------------------------------------------------------
expect 2 "--constants S.json: the same file as the scene S.json" export S.json --constants S.json
unchanged S.json S0.json
ln -s S.json L.json
expect 2 "--glsl L.json: the same file as the scene S.json" export S.json --glsl L.json
unchanged S.json S0.json
ln S.json H.json
expect 2 "--constants H.json: the same file as the scene S.json" export S.json --constants H.json
unchanged S.json S0.json
expect 2 "-o S.json: the same file as the scene S.json" reference S.json $fast -o S.json
unchanged S.json S0.json
expect 2 "-o S.json: the same file as the scene S.json" run S.json -o S.json
expect 2 "-o S.json: the same file as the scene S.json" sweep S.json --param shafts.K=0.5:1:2 -o S.json
unchanged S.json S0.json

# merge: the output is one of the parts
"$bin" reference S.json $fast --tile 0/2 -q -o a.part 2>/dev/null &&
    "$bin" reference S.json $fast --tile 1/2 -q -o b.part 2>/dev/null || { echo "FAIL: parts"; exit 1; }
cp a.part a0.part
expect 2 "-o a.part: the same file as part a.part" merge a.part b.part -o a.part
unchanged a.part a0.part
expect 2 "-o ./b.part: the same file as part b.part" merge a.part b.part --no-preview -o ./b.part
# (the merge itself works: the same parts into a new file)
"$bin" merge a.part b.part -q -o m.exr 2>err && [ -s m.exr ] && [ -s m.png ] || { echo "FAIL: merge -o m.exr"; cat err; fail=1; }
cp m.png real.png
# an EXR's preview is an output too: m.png beside m.exr must not be a part
cp a.part m.png; cp a.part mp0.part
expect 2 "-o m.exr's preview m.png: the same file as part m.png" merge m.png b.part -o m.exr
unchanged m.png mp0.part

# compare: a file it writes into -o DIR (flip.png) is its reference image
mkdir d
cp real.png d/flip.png
"$bin" compare d/flip.png real.png -o d >out 2>err
rc=$?
if [ $rc -eq 2 ] && grep -qF "d/flip.png: the same file as REF d/flip.png, an input" err && cmp -s d/flip.png real.png; then
    echo "ok: compare REF inside -o DIR: $(cat err)"
else echo "FAIL: compare d/flip.png ... -o d: exit $rc (want 2), d/flip.png kept: $(cmp -s d/flip.png real.png && echo yes || echo NO): $(cat err)"; fail=1; fi

# farm: the scene copy it writes into -o is its scene
mkdir f
cp S.json f/scene.json
expect 2 "-o f/scene.json: the same file as the scene f/scene.json" farm f/scene.json --dry-run --cache c -o f
unchanged f/scene.json S0.json

# ---- outputs that are each other --------------------------------------------------------------
mkdir o
expect 2 "--constants o/x.gltf: the same file as --gltf o/x.gltf" export S.json --gltf o/x.gltf --constants o/x.gltf --glsl o/x.gltf
nothing o/x.gltf o/x.bin
expect 2 "--constants c.bin: the same file as --gltf c.gltf's buffer c.bin" export S.json --gltf c.gltf --constants c.bin --grid 4
nothing c.gltf c.bin
expect 2 "--glsl o/../c.bin: the same file as --gltf c.gltf's buffer c.bin" export S.json --gltf c.gltf --glsl o/../c.bin --grid 4
nothing c.gltf c.bin
expect 2 "--glsl k.json: the same file as --constants k.json" export S.json --constants k.json --glsl k.json
nothing k.json
# (distinct outputs are written)
"$bin" export S.json --gltf c.gltf --constants c.json --glsl c.glsl --grid 4 2>err && [ -s c.gltf ] && [ -s c.bin ] &&
    [ -s c.json ] && [ -s c.glsl ] && echo "ok: distinct outputs written" || { echo "FAIL: export to distinct files"; cat err; fail=1; }
exit $fail
