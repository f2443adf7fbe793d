#!/bin/sh
# Issue 31, finding 11 (part): numbers from the command line and from files are printed with
# bounded precision (%g-style), never with hundreds of digits; `run --frames` interrupted in a
# later frame's ground truth says which frames are cached (main: "nothing cached", though the
# earlier frames were).
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
small_scene S.json 16 9
short() { [ "$(wc -c <"$1")" -lt "$2" ] || { echo "FAIL: $3: $(wc -c <"$1") bytes (want < $2): $(head -c 300 "$1")"; fail=1; }; }
# export --frames with a tiny step: 1e300 frames, said in a few digits (main: 301 digits)
expect 2 "--frames 0:1:1e-300: 1e+300 frames, at most 1000" export S.json --gltf x.gltf --frames 0:1:1e-300
short err 200 "export --frames 0:1:1e-300's message"
# merge: a part whose provenance says wall_s 1e308 (main: a 309-digit wall time and metadata line)
fast="--set reference.surface_res=16 --set reference.bias_probe=false --set reference.spp=1 --set reference.sun_samples=2 --set reference.batches=2"
"$bin" reference S.json $fast --tile 0/2 -q -o a.part 2>/dev/null &&
    "$bin" reference S.json $fast --tile 1/2 -q -o b.part 2>/dev/null || { echo "FAIL: parts"; exit 1; }
python3 - a.part <<'PY'
import json, sys
p = sys.argv[1]
data = open(p, "rb").read()
magic, rest = data.split(b"\n", 1)
hn, rest = rest.split(b"\n", 1)
h = json.loads(rest[: int(hn)])
h["provenance"]["wall_s"] = 1e308
ht = json.dumps(h).encode()
open(p, "wb").write(magic + b"\n" + str(len(ht)).encode() + b"\n" + ht + rest[int(hn):])
PY
"$bin" merge a.part b.part --no-preview -o m.exr >out 2>err
rc=$?
if [ $rc -eq 0 ]; then
    short err 400 "merge's summary with wall_s 1e308"
    oiiotool --info -v m.exr 2>/dev/null | grep "godrays:part.0" >meta.txt
    short meta.txt 400 "godrays:part.0 with wall_s 1e308"
    echo "ok: merge with wall_s 1e308: $(cat err)"
else
    # refusing such a part is as good as printing it briefly
    short err 400 "merge's refusal of wall_s 1e308"
    echo "ok: merge refused wall_s 1e308: $(cat err)"
fi
# run --frames: SIGINT during the second frame's ground truth
slow="--set reference.surface_res=32 --set reference.bias_probe=false --set reference.spp=64"
"$bin" run S.json --size 32x18 $slow --frames 0:1:1 --techniques shafts -o r >out 2>err &
pid=$!
n=0
until grep -q "frame 2 of 2" err 2>/dev/null; do
    n=$((n + 1))
    if [ "$n" -gt 2400 ] || ! kill -0 "$pid" 2>/dev/null; then break; fi
    sleep 0.05
done
sleep 0.3
kill -INT "$pid" 2>/dev/null
wait "$pid"
rc=$?
cached=$(ls cache/reference-*.exr 2>/dev/null | wc -l)
last=$(tail -n 1 err)
if [ "$rc" -eq 1 ] && [ "$cached" -eq 1 ] && ! echo "$last" | grep -q "nothing cached" && echo "$last" | grep -q "1 frame before it cached"; then
    echo "ok: run --frames interrupted in frame 2: $last"
else
    echo "FAIL: run --frames interrupted in frame 2: exit $rc (want 1), $cached cached truth(s) (want 1), message: $last"
    fail=1
fi
exit $fail
