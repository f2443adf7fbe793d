#!/bin/sh
# `godrays pareto --quick` on a small scene: exit 0, pareto.csv with the documented columns and
# one row per point (2 ground-truth levels + for each technique of `godrays techniques --json`
# the quick levels of its ladder, or one point at the scene's settings without a ladder; for
# the shafts 2 N x 2 target scales x 2 formats = 8), times and errors positive and finite,
# each family with at least one point on its front, and the lowest time and the lowest error
# of each family on its front (a property of any Pareto front); and the warning about a coarse
# high-quality ground truth (its surface bias estimate above 1 %).
# The folder's parent holds the files of a `godrays run` report (index.html, metrics.json;
# stand-ins here), so the page links back to it (cli.report_links checks the rest).
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export GODRAYS_CACHE="$dir/cache"
cat >"$dir/s.json" <<'JSON'
{"name": "small", "water": {"waves": [{"amplitude_m": 0.1, "wavelength_m": 8, "direction_deg": 30}]},
 "sun": {"elevation_deg": 60, "azimuth_deg": 30},
 "medium": {"absorption_per_m": [0.3, 0.06, 0.03], "scattering_per_m": 0.03, "g": 0.8},
 "camera": {"position_m": [0, -8, 0], "yaw_deg": 30, "pitch_deg": 40, "fov_deg": 60, "width": 48, "height": 27}}
JSON
echo '<!DOCTYPE html><title>run</title>' >"$dir/index.html"
echo '{}' >"$dir/metrics.json"
"$bin" pareto "$dir/s.json" -q --quick --size 40x24 --repeat 2 -o "$dir/p" >"$dir/out" 2>"$dir/err"
rc=$?
cat "$dir/err"
if [ $rc -ne 0 ]; then echo "FAIL: pareto exit $rc"; exit 1; fi
cat "$dir/out"
[ -s "$dir/p/pareto.png" ] && [ -s "$dir/p/index.html" ] || { echo "FAIL: no pareto.png or index.html"; exit 1; }
grep -qF '<a href="../index.html">' "$dir/p/index.html" || { echo "FAIL: pareto page does not link ../index.html"; exit 1; }
"$bin" techniques --json >"$dir/techniques.json" || { echo "FAIL: godrays techniques --json"; exit 1; }
python3 - "$dir/p/pareto.csv" "$dir/techniques.json" <<'PY'
import csv, json, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
techs = [t for t in json.load(open(sys.argv[2]))["techniques"] if not t.get("by_name_only")]  # the default set (eevee: by name only)
assert list(rows[0].keys()) == ["family", "label", "settings", "time_s", "gpu_s", "cost_s", "error", "on_front"], rows[0].keys()
want = [("reference", 2)]
for t in techs:
    want.append((t["name"], sum(1 for l in t["ladder"] if l["quick"]) if t["ladder"] else 1))
assert dict(want).get("shafts", 8) == 8, want
assert len(rows) == sum(n for _, n in want), (len(rows), want)
for fam, n in want:
    pts = [r for r in rows if r["family"] == fam]
    assert len(pts) == n, (fam, len(pts))
    for r in pts:
        t, e = float(r["time_s"]), float(r["error"])
        assert math.isfinite(t) and t > 0 and math.isfinite(e) and e >= 0, r
    front = [r for r in pts if r["on_front"] == "1"]
    assert front, fam
    tmin = min(float(r["time_s"]) for r in pts)
    emin = min(float(r["error"]) for r in pts)
    assert any(float(r["time_s"]) == tmin for r in front), (fam, "fastest not on front")
    assert any(float(r["error"]) == emin for r in front), (fam, "most accurate not on front")
print("pareto.csv ok")
PY
rc_csv=$?
# a coarse high-quality ground truth (the scene's 32 cells, 48 in the high-quality truth: its
# surface bias estimate above 1 %; docs/reference.md 4, "Views with a wide lit region"): one
# warning line with the remedy in the scene's own setting (twice its 32); none under -q (above)
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
"$bin" pareto "$src/data/scenes/default.json" --quick --technique shafts --repeat 1 --size 32x18 \
  --set reference.surface_res=32 -o "$dir/pc" >"$dir/out_c" 2>"$dir/err_c" || { echo "FAIL: coarse pareto exit $?"; exit 1; }
grep "tessellation" "$dir/err_c"
[ "$(grep -c "godrays pareto: warning: the high-quality ground truth: its surface tessellation's bias is about .* reference.surface_res 64$" "$dir/err_c")" = 1 ] ||
  { echo "FAIL: no single coarse-truth warning naming reference.surface_res 64"; exit 1; }
grep -q "tessellation" "$dir/err" && { echo "FAIL: a coarse-truth warning under -q"; exit 1; }
echo "ok: a coarse high-quality truth warned about, with the remedy"
exit $rc_csv
