#!/bin/sh
# usage: expect_error.sh GODRAYS EXIT_CODE EXPECT_FILE ARGS...
# Runs GODRAYS ARGS..., requires exit code EXIT_CODE, exactly one line on stderr that
# contains the text of EXPECT_FILE (fixed string), and nothing on stdout.
bin=$1; want=$2; expect_file=$3; shift 3
out=$(mktemp); errf=$(mktemp)
"$bin" "$@" >"$out" 2>"$errf"
rc=$?
expect=$(cat "$expect_file")
fail=0
if [ "$rc" -ne "$want" ]; then echo "FAIL: exit code $rc, want $want"; fail=1; fi
lines=$(wc -l <"$errf")
if [ "$lines" -ne 1 ]; then echo "FAIL: stderr has $lines lines, want 1"; fail=1; fi
if ! grep -qF -- "$expect" "$errf"; then echo "FAIL: stderr lacks: $expect"; fail=1; fi
if [ -s "$out" ]; then echo "FAIL: stdout not empty"; fail=1; fi
echo "stderr: $(cat "$errf")"
rm -f "$out" "$errf"
exit $fail
