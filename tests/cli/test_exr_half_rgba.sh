#!/bin/sh
# Regression: EXR captures as engines write them (RGBA half, scanline or tiled) are read with each
# channel in its place. OpenEXRCore 3.1's interleaved fast path decoded four HALF channels in the
# file's alphabetical order (A, B, G, R) into R, G, B, A, so `compare` read A as R. Oracle: the
# same constant colour written by oiiotool (OpenImageIO) as float RGB; every channel's error is 0.
bin=${GODRAYS_BINARY:?}
tmp=$(mktemp -d "${GODRAYS_TEST_OUT:-/tmp}/exr_half.XXXXXX")
fail=0
die() { echo "FAIL: $*"; fail=1; }
oiiotool --pattern constant:color=0.25,0.5,0.75 37x21 3 -d float -o "$tmp/f.exr" || die "oiiotool float"
oiiotool --pattern constant:color=0.25,0.5,0.75,1 37x21 4 -d half -o "$tmp/h.exr" || die "oiiotool half"
oiiotool --pattern constant:color=0.25,0.5,0.75,1 37x21 4 -d half --tile 16 16 -o "$tmp/ht.exr" || die "oiiotool tiled"
oiiotool --pattern constant:color=0.25,0.5,0.75,1 37x21 4 -d float -o "$tmp/f4.exr" || die "oiiotool float RGBA"
for t in h ht f4; do
  "$bin" compare "$tmp/f.exr" "$tmp/$t.exr" --json >"$tmp/$t.json" 2>"$tmp/err" || die "compare $t: $(cat "$tmp/err")"
  python3 - "$tmp/$t.json" "$t" <<'PY' || die "$t: channels misplaced"
import json, sys
d = json.load(open(sys.argv[1]))
bad = {c: d["metrics"]["channels"][c]["test_mean"] for c in "RGB" if d["metrics"]["channels"][c]["rmse"] != 0.0}
print(sys.argv[2], "channel means", {c: d["metrics"]["channels"][c]["test_mean"] for c in "RGB"})
sys.exit(1 if bad else 0)
PY
done
[ "$fail" -eq 0 ] && rm -rf "$tmp"
exit $fail
