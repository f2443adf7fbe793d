#!/bin/sh
# OpenImageIO as a module loaded on first use (docs/images.md, "Loading OpenImageIO"): the
# binary does not link it; image calls load build/libgodrays_oiio.so; a missing or wrong
# module is one line naming what was tried and why (exit 1), and EXR-only work (a ground truth
# without a preview, compare of two EXR files without -o) never needs it.
# A build with OpenImageIO linked in (-DGODRAYS_OIIO_MODULE=OFF; the sanitizer build's
# default) is told by ldd and checked for what it promises instead: no module, images work,
# GODRAYS_OIIO_MODULE is not read.
. "$(dirname "$0")/lib.sh"
command -v oiiotool >/dev/null || { echo "FAIL: oiiotool not found (openimageio-tools)"; exit 1; }
cd "$dir" || exit 1
oiiotool --create 32x24 3 --fill:color=0.2,0.4,0.8 32x24 -d float -o ref.exr >/dev/null || exit 1
oiiotool --create 32x24 3 --fill:color=0.25,0.4,0.8 32x24 -d uint8 -o test.png >/dev/null || exit 1

if ldd "$bin" | grep -q 'libOpenImageIO'; then
    echo "ok: $bin links libOpenImageIO (built with GODRAYS_OIIO_MODULE=OFF): the linked-in checks"
    GODRAYS_OIIO_MODULE=$dir/none.so "$bin" compare ref.exr test.png --no-linearize -o res >out.txt 2>err.txt
    rc=$?
    ck "compare of a PNG, GODRAYS_OIIO_MODULE not read (exit $rc: $(head -c 300 err.txt))" test "$rc" -eq 0
    ck "its diff.png" test -s res/diff.png
    GODRAYS_OIIO_MODULE=$dir/none.so "$bin" info >info.txt 2>&1
    ck "info names OpenImageIO's version" grep -Eq '^OpenImageIO +[0-9]+\.[0-9]+' info.txt
    exit $fail
fi
echo "ok: $bin does not link libOpenImageIO"
ck "the module beside the binary" test -f "$(dirname "$bin")/libgodrays_oiio.so"

# loaded on demand: a PNG read and PNG outputs
"$bin" compare ref.exr test.png --no-linearize -o res >out.txt 2>err.txt
rc=$?
ck "compare of a PNG through the module (exit $rc: $(head -c 300 err.txt))" test "$rc" -eq 0
ck "its diff.png" test -s res/diff.png
"$bin" info >info.txt 2>&1
ck "info names OpenImageIO's version" grep -Eq '^OpenImageIO +[0-9]+\.[0-9]+' info.txt

# a module that is not there: one line with the place tried and the loader's reason
GODRAYS_OIIO_MODULE=$dir/none.so expect 1 "$dir/none.so: " compare ref.exr test.png -o res2
ck "nothing written by the failed compare" test ! -e res2/metrics.json
GODRAYS_OIIO_MODULE=$dir/none.so expect 1 "set GODRAYS_OIIO_MODULE to its path" compare ref.exr test.png -o res2
# a shared library that is not the module
libm=$(ldd "$bin" | awk '$1 ~ /^libm\.so/ { print $3 }')
if [ -n "$libm" ]; then
    GODRAYS_OIIO_MODULE=$libm expect 1 "no gr_oiio_module_open in it" compare ref.exr test.png -o res3
else
    echo "FAIL: no libm in ldd's output"; fail=1
fi
GODRAYS_OIIO_MODULE=$dir/none.so "$bin" info >info2.txt 2>&1
ck "info without the module: exit 0, 'not loaded'" grep -Eq '^OpenImageIO +not loaded' info2.txt
# EXR in and out never load it: a tiny ground truth without a preview
small_scene scene.json 16 9
GODRAYS_OIIO_MODULE=$dir/none.so "$bin" reference scene.json -o t.exr --no-preview -q \
    --set reference.batches=2 --set reference.sun_samples=2 >ref_out.txt 2>&1
rc=$?
ck "reference to EXR without the module (exit $rc: $(head -c 300 ref_out.txt))" test "$rc" -eq 0
ck "its EXR" test -s t.exr
# nor do PNG previews (image/png.c, libpng): the same ground truth with its preview, and a
# technique's render with its preview; the preview's codes read back through the module are
# those of the EXR's pixels (docs/images.md, "PNG previews"), checked in unit.oiio
GODRAYS_OIIO_MODULE=$dir/none.so "$bin" reference scene.json -o tp.exr -q \
    --set reference.batches=2 --set reference.sun_samples=2 >refp_out.txt 2>&1
rc=$?
ck "reference with its PNG preview without the module (exit $rc: $(head -c 300 refp_out.txt))" test "$rc" -eq 0
ck "its preview is a PNG" sh -c "head -c 8 tp.png | od -An -tx1 | tr -d ' \n' | grep -q '^89504e470d0a1a0a\$'"
first=$("$bin" techniques --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["techniques"][0]["name"])')
GODRAYS_OIIO_MODULE=$dir/none.so "$bin" render "$first" scene.json -o r.exr -q >render_out.txt 2>&1
rc=$?
ck "render $first with its PNG preview without the module (exit $rc: $(head -c 300 render_out.txt))" test "$rc" -eq 0
ck "its preview" test -s r.png
# compare of two EXR files without -o reads them with the project's reader, without the module;
# its metrics are those of the same float pixels read through OpenImageIO (float TIFF copies)
oiiotool --create 32x24 3 --fill:color=0.3,0.1,0.05 16x12 -d float -o test.exr >/dev/null || exit 1
oiiotool ref.exr -d float -o ref.tif >/dev/null && oiiotool test.exr -d float -o test.tif >/dev/null || exit 1
GODRAYS_OIIO_MODULE=$dir/none.so "$bin" compare ref.exr test.exr --json >exr.json 2>exr.err
rc=$?
ck "compare of two EXR files without the module (exit $rc: $(head -c 300 exr.err))" test "$rc" -eq 0
"$bin" compare ref.tif test.tif --json >tif.json 2>tif.err
ck "the same metrics as OpenImageIO's reading of the same pixels" python3 - exr.json tif.json <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["metrics"] == b["metrics"] and a["metrics"], (a["metrics"], b["metrics"])
PY
exit $fail
