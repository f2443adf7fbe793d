#!/bin/sh
# godrays farm --dry-run writes a farm folder a person can read and submit (no Slurm needed):
# parts.sh, merge.sh, final.sh, submit.sh are bash that parses (bash -n) and names the binary,
# the scene copy and the cache; the array covers 4 frames x 4 tiles; scene.json is a scene
# that validates; --status reads the folder back; bad options exit 2.
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
check "parts.sh renders the scene copy" grep -q 'SCENE="$FARM/scene.json"' "$T/f/parts.sh"
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
