#!/bin/sh
# Hostile and careless inputs (issue 15, items 6, 7, 8, 10, 11, 12, 14; docs/reliability.md).
# Each case states what main did. Crafted PNGs are built here with python3 (zlib, struct: the
# PNG layout of RFC 2083, CRCs included).
#  8. a FIFO as the scene, as an image of compare, /dev/zero as an image: exit 2 at once
#     (main blocked forever, or spun at 100 % CPU in OpenImageIO's IFF reader);
#  6. reference.batches = 1 is refused by validate (main validated it, then `reference` exited
#     2); a ground truth over the memory limit is refused at once with the estimate (main ran
#     14 s to 3.75 GB at surface_res 4096, then failed);
#  7. compare of a 108 KB EXR of 4096 x 4096 zeros over a 1 GiB limit: exit 2 with the
#     estimate (main took 2.8 GB and 33 s); a 1000000 x 1 data window: exit 2 (main read it);
#  10. an (R, G) image: exit 2 naming the channels (main compared it as grey, G dropped);
#  11. an all-zero reference: exit 2 saying that no metric means anything (main: a silent
#     "perfect" score);
#  12. a scene name with an escape sequence and bytes that are not UTF-8: no ESC byte on the terminal,
#     metrics.json strict UTF-8 JSON (main printed the ESC and wrote invalid UTF-8);
#  14. one stderr line for: a path longer than the message buffer (the reason at its end must
#     survive; main cut it at 1024 bytes), --size 99999999999x1 (main: camera.width=1215752191),
#     --threads abc (main: "--set reference.threads=abc"), a PNG whose IHDR CRC is wrong (main:
#     libpng's own second line), JSON nested 2000 deep (main: "malformed JSON"), a PNG declaring
#     100000 x 100000 pixels (main: exit 1), a PNG whose tEXt chunk claims 1.9 GB (found by
#     fuzzing: main let libpng allocate 2 GB for a 2 KB file).
set -u
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
scene="$src/data/scenes/default.json"
fail=0
bad() { echo "FAIL: $*"; fail=1; }
ok() { echo "ok: $*"; }
# expect CODE TEXT ARGS...: exit CODE within 20 s, exactly one stderr line containing TEXT
expect() {
    code=$1 text=$2
    shift 2
    timeout 20 "$bin" "$@" >out.txt 2>err.txt
    rc=$?
    if [ "$rc" -eq "$code" ] && [ "$(wc -l <err.txt)" -eq 1 ] && grep -qF -- "$text" err.txt; then ok "$(cut -c1-200 err.txt)"
    else bad "godrays $(echo "$*" | cut -c1-100): exit $rc (want $code; 124: hung), stderr: $(cut -c1-300 err.txt)"; fi
}

"$bin" shafts "$scene" --set camera.width=16 --set camera.height=9 -o a.exr -q || { echo "FAIL: cannot render a.exr"; exit 1; }

# ---- 8 ----
mkfifo fifo.json fifo.exr
expect 2 "fifo.json: a FIFO, not a regular file" validate fifo.json
expect 2 "fifo.exr: a FIFO, not a regular file" compare a.exr fifo.exr
expect 2 "/dev/zero: a character device, not a regular file" compare a.exr /dev/zero
head -c 100000 /dev/zero >zeros.png
expect 2 "zeros.png: cannot read as an image" compare a.exr zeros.png

# ---- 6 ----
expect 2 "reference.batches: must be in [2, 1024], got 1" validate "$scene" --set reference.batches=1
expect 2 "needs about" reference "$scene" --set reference.surface_res=4096 --max-memory 1G -o x.exr
GODRAYS_MAX_MEMORY=2G expect 2 "over the memory limit of 2.00 GiB (GODRAYS_MAX_MEMORY)" reference "$scene" --size 16384x16384 -o x.exr
[ ! -e x.exr ] || bad "x.exr written by a refused render"

# ---- 7 ----
if command -v oiiotool >/dev/null 2>&1; then
    oiiotool --create 4096x4096 3 -d half --compression zip -o z4k.exr
    expect 2 "the comparison needs about 6.41 GiB" compare z4k.exr z4k.exr --max-memory 1G
    expect 2 "the comparison needs about 2.66 GiB" compare z4k.exr z4k.exr --max-memory 1G --metric basic
else
    bad "oiiotool (openimageio-tools) is missing"
fi

# crafted PNGs
python3 - <<'EOF' || bad "python3 could not write the crafted PNGs"
import struct, zlib
def chunk(t, d, crc=None):
    c = zlib.crc32(t + d) if crc is None else crc
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", c & 0xffffffff)
sig = b"\x89PNG\r\n\x1a\n"
def png(w, h, ihdr_crc=None, rows=None):
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    raw = rows if rows is not None else b"".join(b"\x00" + b"\x40" * (3 * w) for _ in range(h))
    return sig + chunk(b"IHDR", ihdr, ihdr_crc) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
open("huge.png", "wb").write(png(100000, 100000, rows=b"\x00" * 64))
open("badcrc.png", "wb").write(png(4, 4, ihdr_crc=0x12345678))
open("ok4.png", "wb").write(png(4, 4))
# a tEXt chunk claiming 1.9 GB in a small file (found by fuzzing: libpng allocated it)
ihdr = struct.pack(">IIBBBBB", 16, 9, 8, 4, 0, 0, 0)
open("bigtext.png", "wb").write(sig + chunk(b"IHDR", ihdr) + struct.pack(">I", 0x76000000) + b"tEXt" + b"x" * 64)
EOF
expect 2 "huge.png: declares 100000 x 100000 pixels, over the reader's limit" compare huge.png ok4.png
expect 2 "badcrc.png: cannot read as an image" compare badcrc.png ok4.png
expect 2 "PNG chunk 'tEXt' at byte 33 claims 1979711488 bytes, past the end" compare bigtext.png ok4.png

# ---- 10, 11 ----
if command -v oiiotool >/dev/null 2>&1; then
    oiiotool a.exr --ch R,G -o rg.exr
    expect 2 "2 channels (R, G)" compare rg.exr a.exr
    oiiotool --create 16x9 3 -o zero.exr
    expect 2 "reference zero.exr is zero everywhere: no metric can say anything" compare zero.exr a.exr
fi

# ---- 12 ----
python3 - "$scene" <<'EOF' || bad "python3 could not write evil.json"
import json, sys
s = json.load(open(sys.argv[1]))
s["name"] = "evil\u001b]0;pwned\u0007"
t = json.dumps(s).encode().replace(b"evil", b"evil\xff\xfe", 1)  # bytes that are not UTF-8
open("evil.json", "wb").write(t)
EOF
timeout 120 "$bin" run evil.json --size 32x18 --set reference.surface_res=32 --set reference.bias_probe=false \
    --set reference.spp=4 -o evil_out >out.txt 2>err.txt
rc=$?
esc=$(cat out.txt err.txt | tr -d '\n' | od -An -c | grep -c '033')
# exit 3: the report is complete, a technique failed (at 32 x 18 the radial blurs render black)
if { [ "$rc" -eq 0 ] || [ "$rc" -eq 3 ]; } && [ "$esc" -eq 0 ] &&
   python3 -c "import json,sys; json.loads(open('evil_out/metrics.json','rb').read().decode('utf-8','strict'))" &&
   python3 -c "open('evil_out/index.html','rb').read().decode('utf-8','strict')"; then
    ok "scene name with ESC and non-UTF-8 bytes: terminal clean, metrics.json and index.html valid UTF-8"
else
    bad "scene name: exit $rc, ESC bytes on the terminal: $esc, metrics.json/index.html strict UTF-8: see above"
fi

# ---- 14 ----
long=$(printf 'd%.0s' $(seq 1 200))
deep="$long/$long/$long/$long/$long/$long"
mkdir -p "$deep"
expect 2 "nothere.exr: cannot open: No such file or directory" compare "$deep/nothere.exr" a.exr
expect 2 "--size 99999999999x1: camera.width: must be in [1, 16384], got 99999999999" reference "$scene" --size 99999999999x1 -o x.exr
expect 2 "--threads abc: reference.threads:" reference "$scene" --threads abc -o x.exr
python3 -c "print('[' * 2000 + ']' * 2000)" >deep.json
expect 2 "JSON nested deeper than 1000 levels" validate deep.json
exit $fail
