#!/bin/sh
# `godrays run` refuses bad usage and bad input with exit 2 and one stderr line naming the
# problem, before any rendering (so before any output folder exists); an unreadable scene
# file is an I/O failure (exit 1) naming it; an output folder that cannot be made (a path
# through a file) is refused with exit 2 before any rendering (tests/cli/test_output_checks.sh
# covers the other commands).
set -u
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/run_errors
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
export GODRAYS_CACHE="$out/cache"
fail=0
scene="$src/data/scenes/default.json"
# expect CODE PATTERN ARGS...: exit code CODE, exactly one stderr line containing PATTERN
expect() {
    code=$1; pat=$2; shift 2
    "$bin" run "$@" >stdout.txt 2>stderr.txt
    rc=$?
    lines=$(wc -l <stderr.txt)
    if [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] && grep -q -- "$pat" stderr.txt; then
        echo "ok: run $* -> $rc: $(cat stderr.txt)"
    else
        echo "FAIL: run $*: exit $rc (expected $code), $lines stderr line(s), expected '$pat':"
        cat stderr.txt
        fail=1
    fi
}
expect 2 "no scene file given" -o x
expect 2 "unknown option --bogus" "$scene" --bogus
expect 2 "more than one scene" "$scene" "$scene"
expect 2 "-o needs a value" "$scene" -o
expect 2 "--set oops: expected KEY=VALUE" "$scene" --set oops
expect 2 "--size 12: expected WxH" "$scene" --size 12
# a scene file that cannot be read is an I/O failure (the scene loader's GR_E_IO, as in validate)
expect 1 "nope.json: cannot open" "$out/nope.json" -o x
expect 2 "shafts.K" "$scene" --set shafts.K=-1 -o x
expect 2 "medium.g" "$scene" --set medium.g=2 -o x
[ -e x ] && { echo "FAIL: a refused run created its output folder"; fail=1; }
[ -e cache ] && { echo "FAIL: a refused run touched the cache"; fail=1; }
: >a_file
expect 2 "-o a_file: cannot write into a_file: Not a directory" "$scene" --size 32x18 --set reference.surface_res=16 --set reference.sun_samples=1 \
    --set reference.batches=2 --set reference.steps=4 -q -o a_file
"$bin" run --help >help.txt 2>&1
[ $? -eq 0 ] && grep -q "usage: godrays run SCENE" help.txt || { echo "FAIL: run --help"; fail=1; }
"$bin" --help | grep -q "^  run " || { echo "FAIL: run is not listed in godrays --help"; fail=1; }
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
