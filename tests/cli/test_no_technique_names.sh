#!/bin/sh
# The commands, tuning and the report work with any technique through src/realtime/technique.h
# and never name one (docs/architecture.md): no file under src/tune, src/report or src/cli may
# hold a registered technique's name as a word (its scene section, its "NAME.KEY" settings, a
# string literal, its header realtime/NAME.h) or its symbols gr_NAME_*. The one exception is
# the alias table of src/cli/main.c (`godrays shafts` = `godrays render shafts`).
# The names come from the binary itself (`godrays techniques --json`), so a new built-in
# technique is checked without editing this test.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
fail=0
names=$("$bin" techniques --json | python3 -c 'import json,sys; print(" ".join(t["name"] for t in json.load(sys.stdin)["techniques"]))')
[ -n "$names" ] || { echo "FAIL: godrays techniques --json lists no technique"; exit 1; }
for n in $names; do
    # the patterns find what they look for: the technique's own code defines its class
    grep -rq "gr_${n}_class" "$src/src/realtime" || { echo "FAIL: no gr_${n}_class under src/realtime (pattern broken?)"; fail=1; }
    hits=$(grep -rnwE -- "$n|gr_${n}_[A-Za-z0-9_]*" "$src/src/tune" "$src/src/report" "$src/src/cli" |
           grep -vE "^$src/src/cli/main.c:[0-9]+: +\{\"[a-z0-9_]+\", \"[^\"]*\", \"[a-z]+\", \"$n\"\},$")
    if [ -n "$hits" ]; then
        echo "FAIL: technique '$n' named outside src/realtime:"
        echo "$hits"
        fail=1
    else
        echo "ok: '$n' is not named in src/tune, src/report, src/cli (besides main.c's alias table)"
    fi
done
[ "$fail" -eq 0 ] && echo "all checks passed ($names)"
exit $fail
