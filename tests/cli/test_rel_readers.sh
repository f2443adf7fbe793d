#!/bin/sh
# Readers and memory (issue 31, findings 5, 7, 11; docs/reliability.md, "Issue 31: readers and
# memory"). Each case states what main did. TIFFs are built here with python3 (struct: the
# baseline TIFF 6.0 layout, one 8-bit grey strip); other images with oiiotool. The part-file
# cases are in tests/unit/test_rel_parts.c.
#  7. a 138-byte TIFF whose strip lies past the end of the file: exit 2 naming libtiff's read
#     error (main read it as zeros, exit 0); a 138-byte TIFF declaring 8192 x 8192 pixels:
#     exit 2 at once (main took 720 MB and 3 s before the comparison's own estimate); one over
#     GODRAYS_MAX_MEMORY: exit 2 with the estimate; a multi-part EXR: exit 2 naming its part
#     count (main used the first part without a word); a lone R channel: exit 2 like (R, G)
#     (main copied R into G and B); a grey (Y) image: compared, the grey stated on stderr;
#  5. `export --frames 0:199:1` under GODRAYS_MAX_MEMORY=1G: exit 2 at once with the estimate
#     (main took 1.4 GB); `export --gltf x.glb --frames 0:999:1`: exit 2 at once (main ran
#     160 s to 6.3 GB before saying that a .glb cannot hold 4 GiB);
#  4. a FIFO given to `merge` as a part file: exit 2 at once (main blocked forever opening it);
#  11. `merge PART -o x.png`: exit 2 (main wrote EXR bytes into x.png); `render --size
#     16384x16384`: exit 2 naming the GL limit where this GL cannot hold the target (main:
#     "framebuffer incomplete (0x8cd6)", exit 1), or a render where it can.
set -u
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
scene="$src/data/scenes/default.json"
bad() { echo "FAIL: $*"; fail=1; }

# ---- 7: TIFFs ----
python3 - <<'EOF' || { echo "FAIL: python3 cannot build the TIFFs"; exit 1; }
import struct
def tiff(w, h, off=None, nbytes=None, data=None):
    n = 9
    start = 8 + 2 + n * 12 + 4
    data = bytes(100 + i % 50 for i in range(w * h)) if data is None else data
    e = [(256, 4, w), (257, 4, h), (258, 3, 8), (259, 3, 1), (262, 3, 1), (273, 4, start if off is None else off),
         (277, 3, 1), (278, 4, h), (279, 4, len(data) if nbytes is None else nbytes)]
    b = b'II' + struct.pack('<HI', 42, 8) + struct.pack('<H', n)
    for tag, typ, v in e:
        b += struct.pack('<HHIHH', tag, typ, 1, v, 0) if typ == 3 else struct.pack('<HHII', tag, typ, 1, v)
    return b + struct.pack('<I', 0) + data
open('ok.tif', 'wb').write(tiff(4, 4))
open('past.tif', 'wb').write(tiff(4, 4, off=1000))
open('huge.tif', 'wb').write(tiff(8192, 8192, nbytes=16, data=bytes(16)))
open('big.tif', 'wb').write(tiff(512, 512))
EOF
ck "an honest 4 x 4 TIFF compares" "$bin" compare ok.tif ok.tif -o tif
expect 2 "past.tif: reading pixels (truncated or damaged file): TIFFReadEncodedStrip failed" compare ok.tif past.tif
expect 2 "huge.tif: declares 8192 x 8192 pixels" compare huge.tif huge.tif
GODRAYS_MAX_MEMORY=512K expect 2 "reading big.tif needs about" compare big.tif big.tif

# ---- 7: EXR parts and channels ----
oiiotool --pattern fill:top=0.2:bottom=0.8 16x8 3 -o rgb.exr &&
  oiiotool rgb.exr --ch R -o r1.exr && oiiotool rgb.exr --ch Y=G -o y1.exr &&
  oiiotool rgb.exr rgb.exr --siappend -o multi.exr || { echo "FAIL: oiiotool cannot build the EXRs"; exit 1; }
expect 2 "multi.exr: a multi-part EXR file of 2 parts" compare rgb.exr multi.exr
expect 2 "test r1.exr: 1 channel (R): neither grey" compare rgb.exr r1.exr
timeout 20 "$bin" compare rgb.exr y1.exr >out.txt 2>err.txt
rc=$?
if [ "$rc" -eq 0 ] && grep -qF "test y1.exr: grey (channel Y), compared in R, G and B alike" err.txt; then echo "ok: grey stated"
else bad "compare of a grey image: exit $rc, stderr: $(cat err.txt)"; fi

# ---- 5: export estimates ----
GODRAYS_MAX_MEMORY=1G expect 2 "the glTF export needs about 1.20 GiB" export "$scene" --gltf x.gltf --frames 0:199:1
[ ! -e x.gltf ] && [ ! -e x.bin ] || bad "x.gltf written by a refused export"
expect 2 "over the 4 GiB a .glb can hold" export "$scene" --gltf x.glb --frames 0:999:1
[ ! -e x.glb ] || bad "x.glb written by a refused export"

# ---- 11: merge's output, the GL target ----
"$bin" reference "$src/data/scenes/flat.json" --size 4x2 --spp 1 --set reference.sun_samples=2 \
  --set reference.batches=2 --threads 1 -q --tile 0/1 -o p.part || bad "cannot render a part"
expect 2 "-o x.png: the merged ground truth is an EXR file" merge p.part -o x.png
[ ! -e x.png ] || bad "x.png written"
timeout 300 "$bin" render shafts "$scene" --size 16384x16384 -o big.exr -q >out.txt 2>err.txt
rc=$?
if grep -q "framebuffer incomplete" err.txt; then bad "16384 x 16384: $(cat err.txt)"
elif [ "$rc" -eq 2 ] && grep -qF "camera.width/height: a 16384x16384 render target" err.txt; then echo "ok: $(cat err.txt)"
elif [ "$rc" -eq 0 ]; then echo "ok: 16384 x 16384 rendered (this GL holds it)"
else bad "16384 x 16384: exit $rc, stderr: $(cat err.txt)"; fi
rm -f big.exr big.png
# ---- 4: a FIFO as a part file (timeout: main blocked forever in its open) ----
mkfifo part.fifo
t0=$(date +%s)
timeout 20 "$bin" merge part.fifo -o fifo_merged.exr >out.txt 2>err.txt
rc=$?
if [ "$rc" -eq 2 ] && grep -q "part.fifo: a FIFO, not a regular file" err.txt; then
    echo "ok: FIFO part refused in $(($(date +%s) - t0)) s: $(cat err.txt)"
else
    bad "FIFO part file: exit $rc (124: hung): $(cat err.txt)"
fi

exit $fail
