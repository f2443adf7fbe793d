#!/bin/sh
# The volume techniques on two views where they rendered NaN (found by 48 random views,
# 2026-11-30; docs/volume-techniques.md, "Floating point"): slicing's slab weight h sinh(x) / x
# overflowed to Inf past x = 89 (a long slab in water of sigma_t 9.6 /m) and Inf times the
# middle's attenuation 0 made NaN (the shared Henyey-Greenstein denominator, 1 + g^2 - 2 g cos,
# 0 in float at cos = 1 for g >= 0.9999, was rewritten beside it). Each technique must render both views with
# exit 0 (`render` refuses an image with a non-finite value: exit 1, naming the pixel), and
# the long slab's view must not be black (it sees the glow of the sun in blue water).
set -u
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
for sc in volume_long_slab volume_deep_g9999; do
  for t in slicing light_rays froxel; do
    if "$bin" render "$t" "$src/tests/scenes/$sc.json" -o "$t-$sc.exr" -q >out.txt 2>err.txt; then
      echo "ok: $t on $sc"
    else
      echo "FAIL: $t on $sc: exit $?: $(cat err.txt)"
      fail=1
    fi
  done
done
# not black: compare refuses a reference that is zero everywhere (exit 2)
for t in slicing light_rays froxel; do
  if ! "$bin" compare "$t-volume_long_slab.exr" "$t-volume_long_slab.exr" >out.txt 2>err.txt; then
    echo "FAIL: $t on volume_long_slab is black or unreadable: $(cat err.txt)"
    fail=1
  fi
done
exit $fail
