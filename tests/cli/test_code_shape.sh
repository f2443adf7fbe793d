#!/bin/sh
# The code's shape that issue 25 set (docs/architecture.md): every ground truth is rendered in
# reference/ and reached through reference/truth.h (no gr_ref_create / gr_ref_render outside
# reference/ and tests/), no .c file in reference/ over 1000 lines, no function in src/cli over
# 150 lines (a function: from a line at column 0 that opens with its name and '(' to the '}'
# at column 0 that closes the '{' at column 0 after it, the project's layout), and no
# hand-bumped cache format constant.
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
fail=0
n=$(ls "$src"/src/cli/*.c | wc -l)
[ "$n" -ge 10 ] || { echo "FAIL: only $n files in src/cli (pattern broken?)"; fail=1; }
hits=$(grep -rn -E '\bgr_ref_(create|render)\s*\(' "$src/src" --include='*.c' --include='*.h' --include='*.cpp')
[ -z "$hits" ] || { echo "FAIL: a ground truth rendered outside reference/ (use reference/truth.h):"; echo "$hits"; fail=1; }
for f in "$src"/reference/*.c; do
    l=$(wc -l < "$f")
    [ "$l" -le 1000 ] || { echo "FAIL: $f has $l lines (at most 1000)"; fail=1; }
done
long=$(for f in "$src"/src/cli/*.c; do
    awk -v LIM=150 '
        /^[A-Za-z_].*\(/ && !/;[ \t]*$/ { name = $0; start = NR }
        /^\{/ { if (name != "") { fstart = start; fname = name; infn = 1 } }
        /^\}/ { if (infn) { n = NR - fstart + 1; if (n > LIM) printf "%s:%d: %d lines: %s\n", FILENAME, fstart, n, fname; infn = 0; name = "" } }
        END { if (NR > 0 && fstart == 0) print FILENAME ": no function found (pattern broken?)" }' "$f"
done)
[ -z "$long" ] || { echo "FAIL: functions in src/cli over 150 lines:"; echo "$long"; fail=1; }
if grep -rn "GR_CACHE_FORMAT" "$src/src" "$src/reference" >/dev/null 2>&1; then
    echo "FAIL: GR_CACHE_FORMAT is back (the cache key carries the build digest instead)"; fail=1
fi
[ $fail -eq 0 ] && echo "ok: code shape"
exit $fail
