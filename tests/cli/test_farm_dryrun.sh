#!/bin/sh
# godrays farm --dry-run writes a farm folder a person can read and submit (no Slurm needed):
# parts.sh, merge.sh, final.sh, submit.sh are bash that parses (bash -n) and names the binary,
# the scene copy and the cache; the array covers 4 frames x 4 tiles; scene.json is a scene
# that validates; --status reads the folder back; bad options exit 2. A suite farm (--suite)
# writes each case's scene copy with the overrides and a run --suite final job.
set -u
BIN=${GODRAYS_BINARY:?}
SRC=${GODRAYS_SOURCE_DIR:?}
T=$(mktemp -d /tmp/godrays-farm-dry.XXXXXX)
fail=0
check() { msg=$1; shift; if "$@"; then :; else echo "FAIL: $msg"; fail=1; fi; }
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --frames 0:30:10 --tiles 4 --dry-run -o "$T/f" \
  > "$T/out.txt" 2>&1
check "dry run exits 0" test $? -eq 0
check "16 tasks (4 frames x 4 tiles)" grep -q "array tasks to run: 0-15" "$T/out.txt"
for s in parts.sh merge.sh final.sh submit.sh; do
  check "$s exists and is executable" test -x "$T/f/$s"
  check "$s parses" bash -n "$T/f/$s"
done
BINABS=$(readlink -f "$BIN")
check "parts.sh names the binary" grep -q "GODRAYS='$BINABS'" "$T/f/parts.sh"
check "parts.sh exports the cache" grep -q "export GODRAYS_CACHE='$T/cache'" "$T/f/parts.sh"
check "parts.sh renders the scene copy" grep -q "CASE_SCENES=('scene.json' 'scene.json'" "$T/f/parts.sh"
check "four frames" test "$(grep -c -- "--frame " "$T/f/parts.sh")" -eq 4
check "submit.sh submits the array" grep -q 'ARRAY="0-15"' "$T/f/submit.sh"
check "merge after the parts" grep -q "afterany" "$T/f/submit.sh"
check "scene copy validates" "$BIN" validate "$T/f/scene.json" > /dev/null
check "nothing submitted" test ! -e "$T/f/jobs.txt"
"$BIN" farm --status "$T/f" > "$T/status.txt" 2>&1
check "status reads it back" grep -q "0 of 4 cases in the cache" "$T/status.txt"
# a task run by hand, outside Slurm, is skipped once its part is there
"$BIN" farm "$SRC/data/scenes/flat.json" --size 32x18 --tiles 2 --then none --dry-run --cache "$T/c2" -o "$T/g" \
  > /dev/null 2>&1
check "flat farm written" test -x "$T/g/parts.sh"
bash "$T/g/parts.sh" 0 > "$T/g0.txt" 2>&1
check "task 0 by hand" grep -q "done in" "$T/g0.txt"
bash "$T/g/parts.sh" 0 > "$T/g0b.txt" 2>&1
check "task 0 again: skipped" grep -q "already in the cache" "$T/g0b.txt"
bash "$T/g/merge.sh" > "$T/m.txt" 2>&1
check "merge with a part missing fails, naming it" grep -q "part 1 missing" "$T/m.txt"
# a suite farm: one scene copy per case (cases/NAME/scene.json, with the suite's and the
# command's overrides), 2 cases x 2 batch groups, the final job is run --suite with them
S=$SRC/data/scenes/default.json
printf '{"name": "tiny", "size": "32x18", "cases": [{"name": "up", "split": "train", "scene": "%s"},
 {"name": "across", "split": "test", "scene": "%s", "camera": {"yaw_deg": 120}}]}\n' "$S" "$S" > "$T/suite.json"
GODRAYS_CACHE=$T/cache "$BIN" farm --suite "$T/suite.json" --set reference.steps=48 --tiles 1 --batch-parts 2 \
  --dry-run -o "$T/s" > "$T/suite.txt" 2>&1
check "suite: dry run exits 0" test $? -eq 0
check "suite: 4 tasks (2 cases x 2 batch groups)" grep -q "array tasks to run: 0-3" "$T/suite.txt"
check "suite: parts.sh lists the cases' copies" \
  grep -q "CASE_SCENES=('cases/up/scene.json' 'cases/across/scene.json')" "$T/s/parts.sh"
check "suite: the copies are 32x18 with 48 steps, across's at yaw 120" python3 -c "import json, sys
u, a = (json.load(open(sys.argv[1] + '/cases/' + c + '/scene.json')) for c in ('up', 'across'))
sys.exit(not all(s['camera']['width'] == 32 and s['camera']['height'] == 18 and s['reference']['steps'] == 48
                 for s in (u, a)) or a['camera']['yaw_deg'] != 120 or u['camera']['yaw_deg'] == 120)" "$T/s"
check "suite: final.sh is run --suite with the overrides" \
  grep -qF "run --suite '$T/suite.json' --set 'reference.steps=48' -o" "$T/s/final.sh"
"$BIN" farm --status "$T/s" > "$T/sst.txt" 2>&1
check "suite: status names the cases" grep -q "case 1 across: parts 0/2" "$T/sst.txt"
GODRAYS_CACHE=$T/cache "$BIN" farm --suite "$T/suite.json" --frames 0:10:10 --dry-run -o "$T/x" > /dev/null 2>&1
check "--suite with --frames: exit 2" test $? -eq 2
GODRAYS_CACHE=$T/cache "$BIN" farm --suite "$T/suite.json" --batch-parts 9 --dry-run -o "$T/x" > "$T/bp.txt" 2>&1
check "--suite --batch-parts 9: exit 2 naming the case" grep -q "case up: --tiles" "$T/bp.txt"
# memory requests (docs/farm.md "Memory"): none unless asked; a size on every job; auto on the
# parts and the merge, the part's the largest of the cases' estimates, which `reference` states
# when it refuses a render over GODRAYS_MAX_MEMORY (0.01 GiB steps there)
check "no --mem: no request" sh -c "! grep -q '^#SBATCH --mem' '$T/f/parts.sh' '$T/f/merge.sh' '$T/f/final.sh'"
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --mem 4G --dry-run -o "$T/m4" > /dev/null 2>&1
for s in parts.sh merge.sh final.sh; do check "--mem 4G: $s" grep -qx "#SBATCH --mem=4G" "$T/m4/$s"; done
GODRAYS_CACHE=$T/cache "$BIN" farm --suite "$T/suite.json" --mem auto --dry-run -o "$T/ma" > /dev/null 2>&1
check "--mem auto: exit 0" test $? -eq 0
pm=$(sed -n 's/^#SBATCH --mem=\([0-9]*\)M$/\1/p' "$T/ma/parts.sh")
mm=$(sed -n 's/^#SBATCH --mem=\([0-9]*\)M$/\1/p' "$T/ma/merge.sh")
check "--mem auto: parts.sh and merge.sh request MiB ($pm, $mm)" test -n "$pm" -a -n "$mm"
check "--mem auto: final.sh keeps the site's default" sh -c "! grep -q '^#SBATCH --mem' '$T/ma/final.sh'"
for c in up across; do
  GODRAYS_MAX_MEMORY=1M "$BIN" reference "$T/ma/cases/$c/scene.json" -o "$T/x.exr" > "$T/ref_$c.txt" 2>&1
done
check "--mem auto: the parts' request is the larger case's estimate" python3 -c "import re, sys
g = [float(re.search(r'needs about ([0-9.]+) GiB', open(sys.argv[1] + '/ref_' + c + '.txt').read()).group(1))
     for c in ('up', 'across')]
print('  cases', g, 'GiB; parts', sys.argv[2], 'MiB')
sys.exit(abs(max(g) * 1024 - int(sys.argv[2])) > 12)" "$T" "${pm:-0}"
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --mem 12X --dry-run -o "$T/mx" > "$T/mx.txt" 2>&1
check "--mem 12X: exit 2 naming --mem" sh -c "[ $? -eq 2 ] && grep -q -- '--mem 12X' '$T/mx.txt' && [ ! -e '$T/mx' ]"
# bad options
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --tiles 0 --dry-run -o "$T/x" > /dev/null 2>&1
check "--tiles 0: exit 2" test $? -eq 2
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --set reference.target_error=0.01 --dry-run \
  -o "$T/x" > "$T/te.txt" 2>&1
check "target_error: exit 2" test $? -eq 2
check "target_error: says why" grep -q "target_error" "$T/te.txt"
GODRAYS_CACHE=$T/cache "$BIN" farm "$SRC/data/scenes/default.json" --then pareto --dry-run -o "$T/x" > /dev/null 2>&1
check "--then pareto: exit 2" test $? -eq 2
if [ $fail -eq 0 ]; then rm -rf "$T"; echo "all checks passed"; else echo "kept $T"; cat "$T"/*.txt; fi
exit $fail
