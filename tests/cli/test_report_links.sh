#!/bin/sh
# The report of `godrays run` and the pages of `godrays sweep`, `tune` and `pareto` link each
# other (docs/report.md, docs/tuning.md):
#  - a run's index.html gives, for each of DIR/sweep, DIR/tune, DIR/pareto that does not exist
#    yet, the exact command that makes it: the run's scene and --set/--size options, shell-quoted
#    (the folder name here has a space), and -o DIR/COMMAND;
#  - those commands, copied out of the page and run as they are, work (sweep and tune here; the
#    pareto command is checked as text: its high-quality ground truth alone takes half a minute,
#    and cli.tune_pareto checks the pareto page's link back);
#  - their pages link back to ../index.html; a page outside a run's folder does not;
#  - a run written after them links DIR/sweep/index.html and DIR/tune/index.html (files that
#    exist) and still gives the pareto command.
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
out=${GODRAYS_TEST_OUT:-/tmp}/report_links
rm -rf "$out"
mkdir -p "$out"
cd "$out" || exit 1
export GODRAYS_CACHE="$out/cache"
scene="$src/data/scenes/default.json"
rep="rep x"
small="--size 32x18 --set reference.surface_res=16 --set reference.sun_samples=1 --set reference.batches=2 --set reference.steps=4"
# shellcheck disable=SC2086
"$bin" run "$scene" -o "$rep" $small -q >run1.txt 2>&1
rc=$?
# 0, or 3 when a technique failed: at 32 x 18 both radial blurs render black (failed rows);
# the report is complete either way (docs/report.md)
ck "first run exits 0 or 3 ($rc)" [ $rc -eq 0 -o $rc -eq 3 ]
ck "first run wrote index.html" [ -s "$rep/index.html" ]

# the command in the page for COMMAND, HTML entities decoded
command_in_page() {
    grep -o "not made yet: <code>godrays $1 [^<]*</code>" "$rep/index.html" |
        sed "s/^not made yet: <code>//; s|</code>\$||; s/&#39;/'/g; s/&quot;/\"/g; s/&lt;/</g; s/&gt;/>/g; s/&amp;/\\&/g"
}
words="$scene $small"
case "$scene" in *[!A-Za-z0-9_./=:,+%@-]*) words="'$scene' $small" ;; esac
for c in sweep tune pareto; do
    case $c in
        # the example: the first technique's first two number settings with a tuning box
        sweep) extra=" --param shafts.K=0.2:2:16 --param shafts.shaft_length_m=5:100:16" ;;
        tune) extra=" --params shafts.K,shafts.shaft_length_m" ;;
        pareto) extra="" ;;
    esac
    want="godrays $c $words$extra -o 'rep x/$c'"
    got=$(command_in_page $c)
    ck "first index gives the $c command" [ "$got" = "$want" ]
    [ "$got" = "$want" ] || printf 'got:  %s\nwant: %s\n' "$got" "$want"
done
ck "first index links no tuning page" sh -c "! grep -Eq 'href=\"(sweep|tune|pareto)/' '$rep/index.html'"

# run the sweep and tune commands as the page gives them (`godrays` is the built binary)
godrays() { "$bin" "$@"; }
for c in sweep tune; do
    cmd=$(command_in_page $c)
    eval "$cmd -q" >"$c.txt" 2>&1
    ck "the page's $c command exits 0" [ $? -eq 0 ]
    ck "$c wrote $rep/$c/index.html" [ -s "$rep/$c/index.html" ]
    ck "$c page links back to the run's report" grep -qF '<a href="../index.html">' "$rep/$c/index.html"
    ck "$c reused the run's cached ground truth" [ "$(ls cache | grep -c '^reference-.*\.exr$')" -eq 1 ]
done
# a sweep page with no run report beside it has no link back
# shellcheck disable=SC2086
"$bin" sweep "$scene" $small --param shafts.K=0.4:1.2:3 -o lone/sweep -q >lone.txt 2>&1
ck "lone sweep exits 0" [ $? -eq 0 ]
ck "lone sweep page has no link back" sh -c "! grep -q 'href=\"../index.html\"' lone/sweep/index.html"

# the run again: it now links the two pages that exist
# shellcheck disable=SC2086
"$bin" run "$scene" -o "$rep" $small -q >run2.txt 2>&1
rc=$?
ck "second run exits 0 or 3 ($rc)" [ $rc -eq 0 -o $rc -eq 3 ]
for c in sweep tune; do
    ck "second index links $c/index.html" grep -qF "<a href=\"$c/index.html\">" "$rep/index.html"
    ck "second index gives no $c command" [ -z "$(command_in_page $c)" ]
done
ck "second index still gives the pareto command" [ -n "$(command_in_page pareto)" ]
grep -o 'href="[^"]*"' "$rep/index.html" | sed 's/^href="//; s/"$//' >hrefs.txt
while read -r f; do
    case $f in
        '#'*) ck "anchor $f exists" grep -qF "id=\"${f#\#}\"" "$rep/index.html" ;; # the leaderboard's links
        *) ck "linked file $f exists" [ -s "$rep/$f" ] ;;
    esac
done <hrefs.txt

[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
