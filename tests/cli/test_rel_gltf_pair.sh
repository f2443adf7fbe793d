#!/bin/sh
# Issue 31, finding 3 (docs/reliability.md, "Outputs"): a .gltf and the .bin it names are one
# output. Export 10 frames, then 200 frames to the same name, and stop the process (SIGSTOP)
# the moment the new .bin's temporary file appears, send SIGINT and let it go on: the pair left
# behind must be consistent (the .gltf's buffer byteLength is the .bin's size, the animation
# has as many frames as the morph targets the .bin holds), and no temporary file is left.
# main: the new .bin was renamed into place beside the old .gltf (10 frames naming 1/20 of it).
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
small_scene S.json 16 9
"$bin" export S.json --gltf x.gltf --grid 96 --frames 0:9:1 2>err || { echo "FAIL: first export"; cat err; exit 1; }
pair_ok() {
    python3 - "$1" <<'PY'
import json, os, sys
g = json.load(open(sys.argv[1]))
b = g["buffers"][0]
size = os.path.getsize(os.path.join(os.path.dirname(sys.argv[1]) or ".", b["uri"]))
assert b["byteLength"] == size, ("byteLength", b["byteLength"], "bin size", size)
print("pair consistent:", size, "bytes,", len(g["meshes"][0]["primitives"][0].get("targets", [])), "morph targets")
PY
}
pair_ok x.gltf || fail=1
caught=0
for attempt in 1 2 3; do
    "$bin" export S.json --gltf x.gltf --grid 96 --frames 0:199:1 2>err &
    pid=$!
    n=0
    while [ "$n" -lt 20000 ] && kill -0 "$pid" 2>/dev/null; do
        if ls x.bin.tmp-* >/dev/null 2>&1; then
            kill -STOP "$pid" && caught=1
            break
        fi
        n=$((n + 1))
    done
    if [ "$caught" -eq 1 ]; then
        kill -INT "$pid"
        kill -CONT "$pid"
        wait "$pid"
        rc=$?
        break
    fi
    wait "$pid"
done
if [ "$caught" -eq 1 ]; then
    if pair_ok x.gltf && [ -z "$(ls ./*.tmp-* 2>/dev/null)" ]; then
        echo "ok: SIGINT while the .bin was written: a consistent pair, exit $rc"
    else
        echo "FAIL: SIGINT while the .bin was written: exit $rc, a torn pair or temporaries left: $(ls)"; fail=1
    fi
else
    echo "SKIP: the .bin's temporary file was never seen (the write was too quick to catch)"
fi
exit $fail
