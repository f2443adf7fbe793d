#!/bin/sh
# `godrays pareto --suite SUITE --tune --budgets` on a tiny suite (3 views of a small scene,
# 2 train + 1 test, 32 x 18; shafts' quick ladder, a short search): exit 0; fronts.csv with an
# untuned and a tuned row per ladder point; each tuned point's train error <= its untuned one
# (the search starts at the untuned settings: a property of any such search); the times headed
# as CPU-rasterizer times on llvmpipe with GL_RENDERER named; a budget nothing fits says so;
# the preset of a budget row, applied with `run --preset` to the test view, gives the test
# error the table states (the verdict `run` computes on its own), and `render --preset`
# reproduces one image byte for byte across runs; --budgets without --suite is refused; the
# page's interactive chart in headless Chromium (below).
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export GODRAYS_CACHE="$dir/cache"
fail=0
cat >"$dir/s.json" <<'JSON'
{"name": "small", "water": {"waves": [{"amplitude_m": 0.1, "wavelength_m": 8, "direction_deg": 30}]},
 "sun": {"elevation_deg": 60, "azimuth_deg": 30},
 "medium": {"absorption_per_m": [0.3, 0.06, 0.03], "scattering_per_m": 0.03, "g": 0.8},
 "camera": {"position_m": [0, -8, 0], "yaw_deg": 30, "pitch_deg": 40, "fov_deg": 60, "width": 48, "height": 27}}
JSON
cat >"$dir/suite.json" <<'JSON'
{"name": "tiny", "size": "32x18", "cases": [
 {"name": "up", "split": "train", "scene": "s.json"},
 {"name": "side", "split": "train", "scene": "s.json", "camera": {"yaw_deg": 55}, "water": {"time_s": 0.5}},
 {"name": "late", "split": "test", "scene": "s.json", "camera": {"yaw_deg": 10}, "water": {"time_s": 1.0}}]}
JSON
"$bin" pareto --suite "$dir/suite.json" --tune --techniques shafts --quick --max-evals 6 --budgets 0.0001,100000 \
  --timing-size 32x18 --repeat 1 -q -o "$dir/p" >"$dir/out" 2>"$dir/err"
rc=$?
cat "$dir/out" "$dir/err"
[ "$rc" -eq 0 ] || { echo "FAIL: exit $rc"; fail=1; }
f="$dir/p/fronts.csv"
[ "$(sed -n 1p "$f" | cut -d, -f1-3)" = "technique,tuned,ladder" ] || { echo "FAIL: fronts.csv header"; fail=1; }
[ "$(grep -c '^shafts,0,' "$f")" -eq 8 ] && [ "$(grep -c '^shafts,1,' "$f")" -eq 8 ] ||
  { echo "FAIL: expected 8 untuned and 8 tuned rows (the quick ladder)"; fail=1; }
# each tuned row follows its untuned one: train error (column 10) not higher
awk -F, 'NR > 1 && $2 == 0 {u = $10} NR > 1 && $2 == 1 && !($10 <= u + 1e-12) {bad = 1} END {exit bad}' "$f" ||
  { echo "FAIL: a tuned point's train error exceeds its untuned one"; fail=1; }
if grep -q llvmpipe "$dir/out"; then
  grep -q "budget table (times on llvmpipe.*CPU-rasterizer wall times.*do NOT stand for a GPU" "$dir/out" ||
    { echo "FAIL: the budget table is not headed as CPU-rasterizer times"; fail=1; }
fi
grep -q "0.0001  (no point within the budget)" "$dir/out" || { echo "FAIL: an impossible budget not reported"; fail=1; }
preset="$dir/p/presets/budget_100000ms.json"
[ -s "$preset" ] || { echo "FAIL: no preset for the budget row"; fail=1; }
test_err=$(awk -F, '$1 == 100000 {print $6}' "$dir/p/budgets.csv")
"$bin" run "$dir/s.json" --preset "$preset" --techniques shafts --size 32x18 --set camera.yaw_deg=10 \
  --set water.time_s=1.0 -q -o "$dir/run" >"$dir/run.out" 2>&1
run_err=$(awk '$1 == "1" && $2 == "shafts" {print $3}' "$dir/run.out")
awk -v a="$test_err" -v b="$run_err" 'BEGIN {d = a - b; if (d < 0) d = -d; exit !(b != "" && d <= 1e-3 * a)}' ||
  { echo "FAIL: run --preset verdict '$run_err' != the table's test error '$test_err'"; cat "$dir/run.out"; fail=1; }
"$bin" render --preset "$preset" "$dir/s.json" --size 32x18 --no-preview -q -o "$dir/a.exr" &&
  "$bin" render --preset "$preset" "$dir/s.json" --size 32x18 --no-preview -q -o "$dir/b.exr" || fail=1
if command -v idiff >/dev/null 2>&1; then
  idiff -fail 0 -failpercent 0 -warn 0 "$dir/a.exr" "$dir/b.exr" >/dev/null 2>&1 || { echo "FAIL: preset renders differ"; fail=1; }
fi
# The report page in headless Chromium (as tests/cli/test_report_browser.sh drives it), offline
# from file://: Chart.js inlined (no external script or link), the chart drawn with as many
# points as fronts.csv has rows (the page's script marks its status element data-ready and
# data-points), no console message; hovering the budget row shows the tooltip of its point
# with its settings and its thumbnail decoded (an instrumented copy reports it into the DOM).
page="$dir/p/index.html"
browser=""
for b in chromium chromium-browser; do command -v "$b" >/dev/null 2>&1 && { browser=$b; break; }; done
if [ -z "$browser" ] && [ "${CI:-}" = "true" ]; then echo "FAIL: chromium is not installed (CI must run this)"; fail=1; fi
if [ -n "$browser" ]; then
  grep -q 'Chart.js v3' "$page" || { echo "FAIL: Chart.js is not inlined in index.html"; fail=1; }
  grep -Eq '(src|href)="(https?:|//|/|file:)' "$page" && { echo "FAIL: the page links outside its folder"; fail=1; }
  n_rows=$(($(wc -l <"$f") - 1))
  sed 's#</body>#<script>addEventListener("load",function(){var r=document.querySelector("tr[data-gr-chart]"),o="none";\
if(r){r.dispatchEvent(new MouseEvent("mouseenter"));var t=document.getElementById("fronts-tip"),i=t.querySelector("img");\
o="tip="+t.style.display+" img="+(i?i.naturalWidth:-1)+" text="+t.textContent;}\
var p=document.createElement("pre");p.id="grhover";p.textContent="GR"+"HOVER "+o+" HOVER"+"END";document.body.appendChild(p);});</script></body>#' \
    "$page" >"$dir/p/check.html"
  prof="$dir/chromium"
  # shellcheck disable=SC2086
  timeout 120 "$browser" --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --user-data-dir="$prof" --enable-logging=stderr --v=0 \
    --virtual-time-budget=10000 --dump-dom "file://$dir/p/check.html" >"$dir/dom.html" 2>"$dir/dom.err"
  grep -q "id=\"fronts-status\" data-ready=\"1\" data-points=\"$n_rows\"" "$dir/dom.html" ||
    { echo "FAIL: the chart is not drawn with the $n_rows points of fronts.csv:"; grep -o 'id="fronts-status"[^<]*' "$dir/dom.html"; fail=1; }
  hover=$(grep -o 'GRHOVER[^<]*HOVEREND' "$dir/dom.html")
  echo "browser: $hover"
  echo "$hover" | grep -Eq 'tip=block img=[1-9][0-9]* text=shafts, (un)?tuned.*test error: ' ||
    { echo "FAIL: hovering the budget row does not show its point's tooltip with a decoded thumbnail"; fail=1; }
  grep ':CONSOLE' "$dir/dom.err" && { echo "FAIL: console messages in the report page"; fail=1; }
fi

"$bin" pareto "$dir/s.json" --budgets 1 2>"$dir/err2"
[ $? -eq 2 ] && grep -q "need --suite" "$dir/err2" || { echo "FAIL: --budgets without --suite"; cat "$dir/err2"; fail=1; }
[ "$fail" -eq 0 ] && echo "pareto_suite: all checks passed"
exit "$fail"
