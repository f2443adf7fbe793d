#!/bin/sh
# The interactive comparison in godrays run's index.html (src/report/viewer.c), in a real
# browser: headless Chromium driven through the DevTools protocol by report_viewer_cdp.js
# (Node, no npm package): a click on the image flips truth -> technique, the space bar flips
# back, a click on the exposure slider brightens the image, the wipe slider puts the truth's
# columns left of the line and the technique's right of it, the wheel zooms, a drag pans, m shows
# the FLIP map; screenshots differ; no console message. The page's decoded linear floats are
# checked against oiiotool --dumpdata of reference.exr (independent reader). Screenshots are
# kept in $GODRAYS_TEST_OUT/report_viewer/. Skipped without chromium or node, except in CI.
set -u
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/report_viewer
browser=""
for b in chromium chromium-browser; do
    if command -v "$b" >/dev/null 2>&1; then browser=$b; break; fi
done
for tool in "$browser" node oiiotool; do
    if [ -z "$tool" ] || ! command -v "$tool" >/dev/null 2>&1; then
        if [ "${CI:-}" = "true" ]; then
            echo "FAIL: ${tool:-chromium} is not installed (scripts/setup.sh installs it; CI must run this test)"
            exit 1
        fi
        echo "SKIP: ${tool:-chromium} is not installed here"
        exit 0
    fi
done
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
GODRAYS_CACHE="$out/cache" "$bin" run "$src/data/scenes/default.json" -o report --size 160x90 \
    --set reference.surface_res=64 --set reference.sun_samples=2 --set reference.batches=2 \
    --set reference.steps=16 -q >run.txt 2>&1
if [ ! -s report/index.html ]; then
    echo "FAIL: godrays run made no report"
    cat run.txt
    exit 1
fi
fail=0
for f in report/*.exr; do
    case $f in report/reference.exr) continue ;; esac
    t=$(basename "$f" .exr)
    if [ -s "report/${t}_flip.png" ]; then echo "ok: ${t}_flip.png written"; else echo "FAIL: no ${t}_flip.png"; fail=1; fi
done
if grep -Eq '(src|href)="(https?:|//|/|file:)' report/index.html; then echo "FAIL: external URL"; fail=1; fi
oiiotool --dumpdata report/reference.exr >dump.txt || { echo "FAIL: oiiotool --dumpdata"; exit 1; }
timeout 280 node "$src/tests/cli/report_viewer_cdp.js" "$browser" "file://$out/report/index.html" "$out" dump.txt \
    || fail=1
exit $fail
