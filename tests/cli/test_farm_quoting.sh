#!/bin/sh
# Issue 31, finding 6 (docs/farm.md, docs/reliability.md): no value given to `godrays farm`
# reaches its scripts as code. A control character in a value is refused (exit 2, no folder
# made); --then-args is quoted word by word; -o and --partition with blanks and '#' stay whole
# on the #SBATCH lines (double-quoted: sbatch splits those lines itself).
# main: `--partition $'p\ntouch X #'` wrote a script that ran `touch X`; --then-args was pasted
# unquoted ($(...) ran); an -o with a space gave unquoted #SBATCH --output paths.
. "$(dirname "$0")/lib.sh"
cd "$dir" || exit 1
small_scene S.json 16 9
nl='
'
expect 2 "--partition 'p touch $dir/pwned #': control character 0x0a" farm S.json --dry-run --cache c -o f1 \
    --partition "p${nl}touch $dir/pwned #"
ck "no folder made for a refused farm" test ! -e f1
expect 2 "--then-args" farm S.json --dry-run --cache c -o f1 --then-args "--max-evals 5${nl}touch $dir/pwned"
expect 2 "--time" farm S.json --dry-run --cache c -o f1 --time "1:00${nl}touch $dir/pwned"
expect 2 "--view '30,10;touch': unexpected character ';'" farm S.json --dry-run --cache c -o f1 --view '30,10;touch'
# a folder with a space and '#', a partition with both, --then-args with shell syntax
"$bin" farm S.json --size 16x9 --tiles 2 --then run --then-args "--techniques shafts \$(touch $dir/pwned) ;x" \
    --partition 'a b#c' --dry-run --cache c -o "f 2#x" >out 2>err || { echo "FAIL: farm --dry-run"; cat err; exit 1; }
for s in parts.sh merge.sh final.sh submit.sh; do ck "$s parses" bash -n "f 2#x/$s"; done
ck "#SBATCH --output quoted whole" grep -qF "#SBATCH --output=\"$dir/f 2#x/logs/final.out\"" "f 2#x/final.sh"
ck "#SBATCH --partition quoted whole" grep -qF '#SBATCH --partition="a b#c"' "f 2#x/final.sh"
ck "--then-args quoted word by word" grep -qF "'--techniques' 'shafts' '\$(touch' '$dir/pwned)' ';x' || fail=1" "f 2#x/final.sh"
# run the final job with a stub godrays that prints its arguments: nothing else runs
cat >stub.sh <<'SH'
#!/bin/sh
for a in "$@"; do printf '[%s]' "$a"; done; echo
SH
chmod +x stub.sh
sed "s|^GODRAYS=.*|GODRAYS='$dir/stub.sh'|" "f 2#x/final.sh" >final_stub.sh
bash final_stub.sh >args.txt 2>&1
ck "the final job ran no injected command" test ! -e pwned
ck "the final job got the arguments as words" grep -qF "[--techniques][shafts][\$(touch][$dir/pwned)][;x]" args.txt
exit $fail
