#!/bin/sh
# Issue 31, finding 8 (docs/reliability.md, "Outputs"): tune's trace.csv goes through the atomic
# writer. A complete trace.csv from an earlier run stays as it was until the new one is
# complete: SIGINT once the tune has started writing its trace leaves the old file byte for
# byte, no temporary file, exit 130; an uninterrupted run replaces it with whole lines only.
# main: trace.csv was opened "w" at the start (the old trace wiped) and an interrupt left it
# cut mid-line.
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
small_scene S.json 48 27
mkdir -p t
printf 'eval,shafts.K,rmse_fit\n1,0.5,0.25\n' >t/trace.csv
cp t/trace.csv old.csv
# the ground truth first, so that the interrupted run is in its evaluations at once
"$bin" tune S.json --params shafts.K --max-evals 8 -q -o warm >/dev/null 2>&1 || { echo "FAIL: warm-up tune"; exit 1; }
"$bin" tune S.json --params shafts.K --max-evals 400 --starts 4 -q -o t >out 2>err &
pid=$!
n=0
until ls t/trace.csv.tmp-* >/dev/null 2>&1 || ! cmp -s t/trace.csv old.csv; do
    n=$((n + 1))
    if [ "$n" -gt 600 ] || ! kill -0 "$pid" 2>/dev/null; then break; fi
    sleep 0.05
done
sleep 0.5 # some evaluations written
kill -INT "$pid" 2>/dev/null
wait "$pid"
rc=$?
if [ "$rc" -eq 130 ] && cmp -s t/trace.csv old.csv && [ -z "$(ls t/*.tmp-* 2>/dev/null)" ]; then
    echo "ok: SIGINT during tune: the previous trace.csv kept, no temporary file, exit 130"
else
    echo "FAIL: SIGINT during tune: exit $rc (want 130); trace.csv $(cmp -s t/trace.csv old.csv && echo kept || echo CHANGED), $(wc -c <t/trace.csv) bytes, last line '$(tail -c 40 t/trace.csv)'; temporaries: $(ls t)"
    fail=1
fi
# an uninterrupted run replaces it, whole lines only
"$bin" tune S.json --params shafts.K --max-evals 8 -q -o t >/dev/null 2>err || { echo "FAIL: tune"; cat err; fail=1; }
if python3 - t/trace.csv <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
assert rows[0] == ["eval", "shafts.K", "rmse_fit"] or rows[0][0] == "eval", rows[0]
assert len(rows) > 2 and all(len(r) == len(rows[0]) for r in rows), "ragged rows"
assert [int(r[0]) for r in rows[1:]] == list(range(1, len(rows))), "evaluations not 1..n"
PY
then echo "ok: a complete run replaced trace.csv ($(wc -l <t/trace.csv) lines)"; else echo "FAIL: new trace.csv"; fail=1; fi
exit $fail
