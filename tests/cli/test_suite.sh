#!/bin/sh
# godrays suite validate|list and run --suite (docs/scene-format.md "Suites", docs/report.md):
# malformed suites exit 2 with one line naming the suite file and the JSON path; `suite list`
# shows each case as the suite file sets it; `run --suite` on a 2-case suite at 32 x 18 writes
# the suite leaderboard whose aggregates (mean over the cases, the worst case) are recomputed
# here from the per-case verdicts it prints, and match metrics.json.
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
small_scene "$dir/s.json" 32 18
case_up='{"name": "up", "split": "train", "scene": "s.json"}'
case_t='{"name": "across", "split": "test", "scene": "s.json", "camera": {"yaw_deg": 120, "pitch_deg": 5}, "water": {"time_s": 0.5}}'
mk() { printf '%s\n' "$2" > "$dir/$1"; }

# malformed suites: one line naming the file and the JSON path, exit 2
mk unknown.json "{\"name\": \"x\", \"size\": \"32x18\", \"cases\": [$case_up, $case_t], \"extra\": 1}"
expect 2 "$dir/unknown.json: extra: unknown key" suite validate "$dir/unknown.json"
mk noscene.json "{\"name\": \"x\", \"cases\": [$case_up, {\"name\": \"t\", \"split\": \"test\", \"scene\": \"gone.json\"}]}"
expect 2 "$dir/noscene.json: cases[1].scene: " suite validate "$dir/noscene.json"
mk dup.json "{\"name\": \"x\", \"cases\": [$case_up, $case_t, $case_up]}"
expect 2 "$dir/dup.json: cases[2].name: 'up' is also the name of cases[0]" suite list "$dir/dup.json"
mk notest.json "{\"name\": \"x\", \"cases\": [$case_up]}"
expect 2 "$dir/notest.json: cases: no test case" suite validate "$dir/notest.json"
mk badov.json "{\"name\": \"x\", \"cases\": [$case_up, {\"name\": \"t\", \"split\": \"test\", \"scene\": \"s.json\", \"set\": [\"sun.elevation_deg=95\"]}]}"
expect 2 "$dir/badov.json: cases[1].set[0]: sun.elevation_deg" suite validate "$dir/badov.json"
mk badcam.json "{\"name\": \"x\", \"cases\": [$case_up, {\"name\": \"t\", \"split\": \"test\", \"scene\": \"s.json\", \"camera\": {\"fov\": 50}}]}"
expect 2 "$dir/badcam.json: cases[1].camera.fov: " suite validate "$dir/badcam.json"
expect 2 "$dir/badcam.json: cases[1].camera.fov: " run --suite "$dir/badcam.json" -o "$dir/never"
ck "a bad suite makes no report folder" test ! -e "$dir/never"
expect 1 "missing.json" suite validate "$dir/missing.json"
expect 2 "no suite file given" suite list
expect 2 "unknown subcommand" suite frobnicate x.json

# a good suite: validate and list show what the file says
mk ok.json "{\"name\": \"tiny\", \"size\": \"32x18\", \"cases\": [$case_up, $case_t]}"
"$bin" suite validate "$dir/ok.json" > "$dir/v.txt" 2>&1
ck "validate: exit 0" test $? -eq 0
ck "validate: 2 cases, 1 train, 1 test" grep -qF "2 cases (1 train, 1 test)" "$dir/v.txt"
"$bin" suite list "$dir/ok.json" --size 24x16 > "$dir/l.txt" 2>&1
ck "list: exit 0" test $? -eq 0
ck "list: the across case: test split, --size, yaw 120, pitch 5, time 0.5" \
    grep -qE "^across +test +s\.json +24x16 +0,-8,0 +120\.0 +5\.0 +60\.0 +60\.0 +30\.0 +0\.5 " "$dir/l.txt"
ck "list: the up case keeps the scene's camera" grep -qE "^up +train +s\.json +24x16 +0,-8,0 +30\.0 +60\.0 " "$dir/l.txt"

# run --suite: two cases, the first registered technique, cheap truths
t1=$("$bin" techniques | awk 'NR == 1 { print $1 }')
"$bin" run --suite "$dir/ok.json" --set reference.spp=1 --set reference.surface_res=64 --set reference.sun_samples=2 \
    --set reference.batches=2 --set reference.steps=16 --techniques "$t1,radial_blur" -q -o "$dir/r" > "$dir/run.txt" 2>"$dir/run.err"
rc=$?
ck "run --suite: exit 0 or 3 (report complete), got $rc" test $rc -eq 0 -o $rc -eq 3
cat "$dir/run.txt"
for f in index.html metrics.json cases/up/index.html cases/across/index.html cases/up/reference.png cases/across/scene.json; do
    ck "run --suite wrote $f" test -s "$dir/r/$f"
done
# the per-case verdicts printed, the mean and worst recomputed here
v_up=$(awk '$1 == "up" && $2 == "train" { print $4 }' "$dir/run.txt")
v_ac=$(awk '$1 == "across" && $2 == "test" { print $4 }' "$dir/run.txt")
p_mean=$(awk '$1 == "mean" && NF == 3 { print $2 }' "$dir/run.txt")
p_worst=$(awk '$1 == "worst" { print $2 }' "$dir/run.txt")
echo "printed: up $v_up, across $v_ac, mean $p_mean, worst $p_worst"
ck "the mean is the mean of the cases" awk -v a="$v_up" -v b="$v_ac" -v m="$p_mean" \
    'BEGIN { e = (a + b) / 2; exit !(a > 0 && b > 0 && (m - e) ^ 2 <= (1e-5 * e) ^ 2) }'
ck "the worst is their max" awk -v a="$v_up" -v b="$v_ac" -v w="$p_worst" \
    'BEGIN { e = a > b ? a : b; exit !((w - e) ^ 2 <= (1e-5 * e) ^ 2) }'
# metrics.json: the same aggregate
# the aggregate entry of the first technique (entries are ranked: find it by name)
agg1=$(tr -d ' \t\n' < "$dir/r/metrics.json" | grep -oE "\"technique\":\"$t1\",\"rank\":[0-9]+,\"mean_verdict\":[-0-9.e+]+,\"worst_verdict\":[-0-9.e+]+")
j_mean=$(echo "$agg1" | grep -oE '"mean_verdict":[-0-9.e+]+' | cut -d: -f2)
j_worst=$(echo "$agg1" | grep -oE '"worst_verdict":[-0-9.e+]+' | cut -d: -f2)
ck "metrics.json mean = the printed mean ($j_mean)" awk -v a="$j_mean" -v b="$p_mean" 'BEGIN { exit !((a - b) ^ 2 <= (1e-5 * b) ^ 2) }'
ck "metrics.json worst = the printed worst ($j_worst)" awk -v a="$j_worst" -v b="$p_worst" 'BEGIN { exit !((a - b) ^ 2 <= (1e-5 * b) ^ 2) }'
ck "metrics.json names the worst case" grep -qE '"worst_case":[[:space:]]*"(up|across)"' "$dir/r/metrics.json"
ck "index.html: thumbnails of both cases" grep -q 'cases/across/reference.png' "$dir/r/index.html"
"$bin" validate "$dir/r/cases/across/scene.json" > /dev/null 2>&1
ck "the test case's scene copy validates" test $? -eq 0
# the across view has the sun behind the camera: the radial blur draws a black frame, which a
# suite scores as the black baseline's verdict (not a failed cell)
rb_ac=$(awk '$1 == "across" && $2 == "test" { print $5 }' "$dir/run.txt")
black_ac=$(tr -d ' \t\n' < "$dir/r/cases/across/metrics.json" | grep -oE '"kind":"baseline","name":"black","label":"[^"]*","verdict":[-0-9.e+]+' | sed 's/.*://')
echo "across: radial blur $rb_ac, black baseline $black_ac"
ck "a black frame in a suite is scored as the black baseline ($rb_ac vs $black_ac)" awk -v a="$rb_ac" -v b="$black_ac" \
    'BEGIN { exit !(b > 0 && (a - b) ^ 2 <= (1e-5 * b) ^ 2) }'
ck "no FAILED cell" test "$(grep -c FAILED "$dir/run.txt")" -eq 0
expect 2 "give one of them" run --suite "$dir/ok.json" "$dir/s.json"
exit $fail
