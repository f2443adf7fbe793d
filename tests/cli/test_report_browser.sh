#!/bin/sh
# The report opens in a real browser: headless Chromium (Debian's `chromium`) loads
# DIR/index.html from file:// with
#  - no console message (Chromium logs every console message to stderr with
#    --enable-logging=stderr; a page without scripts has none unless something fails);
#  - every <img> decoded (an instrumented copy of the page in the same folder checks each
#    image's naturalWidth after the load event and writes the result into the DOM, which
#    --dump-dom prints), as many images as the page has <img> tags, all local files;
#  - no reference to anything outside the folder (http:, https:, //, absolute paths);
#  - the leaderboard as the browser lays it out (its innerText, written into the DOM by the
#    same script): the verdict and its components, the equivalent blur, the three baselines
#    and a failed row for a user technique whose shader does not compile (the run exits 3).
# A screenshot of the page is kept as the test's artifact: $GODRAYS_TEST_OUT/report_browser/
# index.png. The report comes from a small, low-quality render (a few seconds).
# Chromium is installed by scripts/setup.sh; without it the test is skipped with a message,
# except in CI (CI=true), where a missing browser is a failure.
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/report_browser
browser=""
for b in chromium chromium-browser; do
    if command -v "$b" >/dev/null 2>&1; then browser=$b; break; fi
done
if [ -z "$browser" ]; then
    if [ "${CI:-}" = "true" ]; then
        echo "FAIL: chromium is not installed (scripts/setup.sh installs it; CI must run this test)"
        exit 1
    fi
    echo "SKIP: chromium is not installed here (apt-get install chromium, or run scripts/setup.sh as root)"
    exit 0
fi
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
GODRAYS_CACHE="$out/cache" "$bin" run "$src/data/scenes/default.json" -o report --size 160x90 \
    --set reference.surface_res=64 --set reference.sun_samples=2 --set reference.batches=2 \
    --set reference.steps=16 --technique-dir "$src/tests/techniques/gl_errors/compile_error" \
    --techniques err_compile_error,froxel,shafts -q >run.txt 2>&1
rc=$?
ck "godrays run exits 3 (a technique failed) and made the report" [ "$rc" -eq 3 ]
ck "godrays run made the report" [ -s report/index.html ]
[ -s report/index.html ] || { cat run.txt; exit 1; }

# Static checks of the page: local, relative links only.
ck "no external URL" sh -c "! grep -Eq '(src|href)=\"(https?:|//|/|file:)' report/index.html"
n_img=$(grep -o '<img ' report/index.html | wc -l)
ck "page has at least the 5 pictures ($n_img <img>)" [ "$n_img" -ge 5 ]
grep -o '<img src="[^"]*"' report/index.html | sed 's/<img src="//; s/"$//' >srcs.txt
while read -r f; do ck "image file $f exists" [ -s "report/$f" ]; done <srcs.txt

profile=$(mktemp -d)
trap 'rm -rf "$profile" "$dir"' EXIT
# Flags from the project's notes (dependencies.md): no sandbox (root in CI), no GPU, nothing
# fetched in the background. A fresh profile directory per run.
flags="--headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking
       --disable-component-update --disable-sync --user-data-dir=$profile --enable-logging=stderr --v=0"
url="file://$out/report/index.html"

# 1. the page itself: screenshot (the artifact) and the console messages
# shellcheck disable=SC2086
timeout 120 "$browser" $flags --hide-scrollbars --window-size=1400,3600 --screenshot="$out/index.png" "$url" \
    >shot.out 2>shot.err
ck "chromium took the screenshot" [ -s "$out/index.png" ]
grep ':CONSOLE' shot.err >console.txt
ck "no console messages" [ ! -s console.txt ]
[ -s console.txt ] && cat console.txt

# 2. an instrumented copy in the same folder (same relative links): after the load event a
#    script counts the images and those that failed to decode, and collects any error event
#    (resource errors do not bubble: listen in the capture phase), into a <pre> in the DOM.
hook='<script>window.__grErr=[];window.addEventListener("error",function(e){var t=e.target;
window.__grErr.push(t&&t.src?"load failed: "+t.src:String(e.message));},true);
window.addEventListener("load",function(){var im=document.images,bad=[];for(var i=0;i<im.length;i++)
{if(!im[i].complete||im[i].naturalWidth===0)bad.push(im[i].getAttribute("src"));}
var p=document.createElement("pre");p.id="grcheck";p.textContent="GRCHECK images="+im.length+" broken="+
bad.length+" errors="+window.__grErr.length+" ["+bad.concat(window.__grErr).join(" ")+"] END";
document.body.appendChild(p);var lb=document.querySelector("table.lb"),q=document.createElement("pre");
q.id="grlb";q.textContent="GRLB "+(lb?lb.innerText.replace(/\s+/g," "):"none")+" LBEND";document.body.appendChild(q);});</script>'
printf '%s\n' "$hook" >hook.html
sed '/<head>/r hook.html' report/index.html >report/check.html
ck "the check script is in the copy" grep -q '__grErr' report/check.html
# shellcheck disable=SC2086
timeout 120 "$browser" $flags --virtual-time-budget=15000 --dump-dom "file://$out/report/check.html" \
    >dom.html 2>dom.err
result=$(grep -o 'GRCHECK[^<]*END' dom.html)
echo "browser: $result"
ck "the check script ran" [ -n "$result" ]
ck "every image loaded ($n_img expected)" sh -c "echo '$result' | grep -q 'GRCHECK images=$n_img broken=0 errors=0 '"
lbtext=$(grep -o 'id="grlb">GRLB[^<]*LBEND' dom.html)
echo "leaderboard as laid out: $lbtext"
for w in "verdict" "error after fit" "structure score" "FLIP" "band-pass corr." "streak contrast ratio" "scale a" \
    "equivalent blur" "baseline: black frame" "baseline: constant: the truth's mean" \
    "baseline: truth blurred, sigma 4 px" "failed err_compile_error" "FAILED: " "does not compile"; do
    ck "the laid-out leaderboard shows '$w'" sh -c 'printf "%s" "$1" | grep -qF -- "$2"' _ "$lbtext" "$w"
done
ck "the laid-out leaderboard shows an equivalent blur in px for froxel" sh -c \
    'printf "%s" "$1" | grep -Eq "froxel .* [0-9.]+ px "' _ "$lbtext"
grep ':CONSOLE' dom.err >console2.txt
ck "no console messages in the instrumented copy" [ ! -s console2.txt ]
rm -f report/check.html

[ "$fail" -eq 0 ] && echo "all checks passed (screenshot: $out/index.png)"
exit $fail
