#!/bin/sh
# Every command that writes a file or a folder checks, before any rendering, that it can:
# a file's folder must exist and be writable, a folder must be creatable (its nearest existing
# ancestor a writable folder). Otherwise exit 2 with one stderr line naming the flag, the path
# and the reason (strerror), nothing on stdout, nothing written, and at once: the renders these
# commands would start take from seconds (the shafts) to minutes (the ground truths; the scene
# here is the default one at full size, whose ground truth alone takes about a minute).
# Paths through a regular file are used for folders, since a process running as root may
# create folders anywhere, so a missing parent is no error for them.
set -u
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir" || exit 1
export GODRAYS_CACHE="$dir/cache"
scene="$src/data/scenes/default.json"
: >a_file
fail=0
now() { date +%s.%N; }
# expect TEXT ARGS...: exit 2 within 5 s, one stderr line containing TEXT, empty stdout
expect() {
    text=$1; shift
    t0=$(now)
    "$bin" "$@" >out.txt 2>err.txt
    rc=$?
    t=$(awk -v a="$t0" -v b="$(now)" 'BEGIN{printf "%.2f", b - a}')
    lines=$(wc -l <err.txt)
    if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$text" err.txt || [ -s out.txt ] ||
       ! awk -v t="$t" 'BEGIN{exit !(t < 5)}'; then
        echo "FAIL: $*: exit $rc (want 2) after $t s (want < 5), $lines stderr line(s) (want 1 containing '$text'):"
        cat err.txt out.txt
        fail=1
    else
        echo "ok ($t s): $*: $(cat err.txt)"
    fi
}
nf="$dir/no/such/dir"
expect "-o $nf/x.exr: cannot write into $nf: No such file or directory" reference "$scene" -o "$nf/x.exr"
expect "-o a_file/x.exr: cannot write into a_file: Not a directory" reference "$scene" -o a_file/x.exr
expect "-o $dir: cannot write: Is a directory" reference "$scene" -o "$dir"
expect "-o $nf/x.exr: cannot write into $nf: No such file or directory" shafts "$scene" -o "$nf/x.exr"
expect "--save-target $nf/t.exr: cannot write into $nf" shafts "$scene" -o s.exr --save-target "$nf/t.exr"
expect "-o a_file: cannot write into a_file: Not a directory" run "$scene" -o a_file
expect "-o a_file/report: cannot create a folder in a_file: Not a directory" run "$scene" -o a_file/report
expect "-o a_file/sweep: cannot create a folder in a_file: Not a directory" \
    sweep "$scene" --param shafts.K=0.4:1.2:4 -o a_file/sweep
expect "-o a_file/tune: cannot create a folder in a_file: Not a directory" tune "$scene" --params shafts.K -o a_file/tune
expect "-o a_file/pareto: cannot create a folder in a_file: Not a directory" pareto "$scene" --quick -o a_file/pareto
expect "-o a_file/cmp: cannot create a folder in a_file: Not a directory" compare a.exr b.exr -o a_file/cmp
# The default folders (out/SCENE_NAME[/COMMAND]) are checked too: here "out" is a file.
: >out
expect "default output folder out/default: cannot create a folder in out: Not a directory" run "$scene"
expect "default output folder out/default/sweep: cannot create a folder in out: Not a directory" \
    sweep "$scene" --param shafts.K=0.4:1.2:4
expect "default output folder out/default/tune: cannot create a folder in out: Not a directory" \
    tune "$scene" --params shafts.K
expect "default output folder out/default/pareto: cannot create a folder in out: Not a directory" pareto "$scene"
# shafts' default output is shafts.exr in the current folder
mkdir ro && cd ro && : >../ro_marker
chmod 0555 . 2>/dev/null
if [ "$(id -u)" -ne 0 ]; then
    expect "-o shafts.exr: cannot write into .: Permission denied" shafts "$scene"
else
    echo "note: running as root: the unwritable-folder case is not testable (root writes anywhere)"
fi
cd "$dir" && chmod 0755 ro
# nothing was written by the refused commands
left=$(find . -mindepth 1 -not -name a_file -not -name out -not -name ro -not -name ro_marker \
       -not -name out.txt -not -name err.txt | head -n 5)
[ -z "$left" ] || { echo "FAIL: refused commands wrote: $left"; fail=1; }
[ -s a_file ] && { echo "FAIL: a_file was written to"; fail=1; }
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
