#!/bin/sh
# Command dispatch: help exits 0 with a usage text, an unknown command exits 2 with one line
# on stderr naming it, and every subcommand's --help exits 0.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
out=$(mktemp); errf=$(mktemp)
trap 'rm -f "$out" "$errf"' EXIT
fail=0

"$bin" --help >"$out" 2>"$errf"; rc=$?
[ "$rc" -eq 0 ] || { echo "FAIL: --help exit $rc"; fail=1; }
grep -q '^usage: godrays COMMAND' "$out" || { echo "FAIL: --help prints no usage"; fail=1; }
for cmd in validate info; do
  grep -Eq "^  $cmd " "$out" || { echo "FAIL: --help does not list $cmd"; fail=1; }
done

"$bin" nosuchcmd >"$out" 2>"$errf"; rc=$?
[ "$rc" -eq 2 ] || { echo "FAIL: unknown command exit $rc, want 2"; fail=1; }
[ "$(wc -l <"$errf")" -eq 1 ] || { echo "FAIL: unknown command: stderr not one line:"; cat "$errf"; fail=1; }
grep -q 'nosuchcmd' "$errf" || { echo "FAIL: error does not name the command"; fail=1; }
[ -s "$out" ] && { echo "FAIL: unknown command wrote to stdout"; fail=1; }

"$bin" >"$out" 2>"$errf"; rc=$?
[ "$rc" -eq 2 ] || { echo "FAIL: no command: exit $rc, want 2"; fail=1; }

# every command listed by --help has a --help of its own
"$bin" --help | sed -n 's/^  \([a-z][a-z]*\) .*/\1/p' >"$out"
n=0
for cmd in $(cat "$out"); do
  n=$((n + 1))
  "$bin" "$cmd" --help >"$errf" 2>&1; rc=$?
  [ "$rc" -eq 0 ] || { echo "FAIL: $cmd --help exit $rc"; fail=1; }
  # an alias ("same as `render shafts`") shows the help of the command it stands for
  want=$("$bin" --help | sed -n "s/^  $cmd  *same as \`\([a-z]*\) .*/\1/p")
  [ -n "$want" ] || want=$cmd
  grep -q "usage: godrays $want" "$errf" || { echo "FAIL: $cmd --help has no 'usage: godrays $want'"; fail=1; }
done
[ "$n" -ge 2 ] || { echo "FAIL: --help lists only $n commands"; fail=1; }

[ "$fail" -eq 0 ] && echo "all checks passed ($n commands)"
exit $fail
