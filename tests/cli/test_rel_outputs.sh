#!/bin/sh
# Output files (issue 15, items 1, 2 and 13; docs/reliability.md "Outputs"):
#  1. an -o path that is a device node (a copy of /dev/null made with mknod) is refused with
#     exit 2 and stays a device node; a FIFO likewise; a symlink is written through: the link
#     stays and its target gets the new file (main renamed a regular file over both);
#  2. a full disk: a tmpfs of 1 MiB filled to the last byte (when this process may mount),
#     and in any case a file-size limit (ulimit -f, SIGXFSZ ignored: writes fail with EFBIG,
#     as on a full disk): exit 1, and no 0-byte, truncated or temporary file is left (main left
#     a 0-byte diff.png and exited 0);
#  13. compare -o DIR from many processes at once: every one succeeds; a folder squatting the
#     fixed temporary name DIR/metrics.json.tmp (what a concurrent process held on main) does
#     not make it fail.
set -u
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
dir=$(mktemp -d)
mnt="$dir/mnt"
cleanup() { umount "$mnt" 2>/dev/null; rm -rf "$dir"; }
trap cleanup EXIT
cd "$dir" || exit 1
scene="$src/data/scenes/default.json"
small="--set camera.width=256 --set camera.height=144"
fail=0
bad() { echo "FAIL: $*"; fail=1; }
ok() { echo "ok: $*"; }

# two small images to compare
"$bin" shafts "$scene" $small -o a.exr -q || { echo "FAIL: cannot render a.exr"; exit 1; }
"$bin" shafts "$scene" $small --set shafts.K=0.5 -o b.exr -q || { echo "FAIL: cannot render b.exr"; exit 1; }

# ---- 1: device nodes, FIFOs, symlinks ---------------------------------------------------
if mknod devnull c 1 3 2>/dev/null; then
    "$bin" shafts "$scene" $small -o devnull -q 2>err.txt
    rc=$?
    if [ "$rc" -eq 2 ] && [ -c devnull ] && grep -q "not a regular file" err.txt; then ok "device node refused: $(cat err.txt)"
    else bad "shafts -o DEVICE: exit $rc (want 2), device node kept: $([ -c devnull ] && echo yes || echo no): $(cat err.txt)"; fi
    mkdir cmpdev && mknod cmpdev/diff.png c 1 3
    "$bin" compare a.exr b.exr -o cmpdev >/dev/null 2>err.txt
    rc=$?
    if [ "$rc" -eq 2 ] && [ -c cmpdev/diff.png ] && [ ! -e cmpdev/metrics.json ]; then ok "compare: device node in -o DIR refused"
    else bad "compare -o DIR with DIR/diff.png a device: exit $rc (want 2), node kept: $([ -c cmpdev/diff.png ] && echo yes || echo no)"; fi
else
    echo "SKIP: mknod not permitted here (not root): device-node cases"
fi
mkfifo fifo.exr
timeout 20 "$bin" shafts "$scene" $small -o fifo.exr -q 2>err.txt
rc=$?
if [ "$rc" -eq 2 ] && [ -p fifo.exr ]; then ok "FIFO output refused"; else bad "shafts -o FIFO: exit $rc (want 2), FIFO kept: $([ -p fifo.exr ] && echo yes || echo no)"; fi

mkdir real && : >real/target.exr && ln -s real/target.exr link.exr
"$bin" shafts "$scene" $small -o link.exr -q --no-preview 2>err.txt
rc=$?
if [ "$rc" -eq 0 ] && [ -L link.exr ] && [ -s real/target.exr ] && [ "$(readlink link.exr)" = real/target.exr ]; then
    ok "symlink output written through to its target"
else
    bad "shafts -o SYMLINK: exit $rc, link kept: $([ -L link.exr ] && echo yes || echo no), target size $(wc -c <real/target.exr): $(cat err.txt)"
fi
# the target is a readable EXR: compare it with itself
"$bin" compare link.exr real/target.exr >/dev/null 2>&1 || bad "the symlink's target does not read as an image"
mkdir cmplink && ln -s ../elsewhere.png cmplink/diff.png
"$bin" compare a.exr b.exr -o cmplink >/dev/null 2>err.txt
rc=$?
if [ "$rc" -eq 0 ] && [ -L cmplink/diff.png ] && [ -s elsewhere.png ]; then ok "compare: symlinked diff.png written through"
else bad "compare -o DIR with DIR/diff.png a symlink: exit $rc, link kept: $([ -L cmplink/diff.png ] && echo yes || echo no)"; fi

# ---- 2: full disk -----------------------------------------------------------------------
# no_leftovers DIR: nothing 0-byte or temporary in DIR
no_leftovers() {
    left=$(find "$1" -type f \( -size 0 -o -name '*.tmp*' \) 2>/dev/null)
    [ -z "$left" ] || { echo "  left behind: $left"; return 1; }
}
mkdir -p "$mnt"
if mount -t tmpfs -o size=1m tmpfs "$mnt" 2>/dev/null; then
    dd if=/dev/zero of="$mnt/fill" bs=1k 2>/dev/null # fills it: dd stops at ENOSPC
    "$bin" compare a.exr b.exr -o "$mnt/cmp" >/dev/null 2>err.txt
    rc=$?
    if [ "$rc" -eq 1 ] && no_leftovers "$mnt" && [ "$(wc -l <err.txt)" -eq 1 ]; then ok "full tmpfs: compare -o: $(cat err.txt)"
    else bad "full tmpfs: compare -o: exit $rc (want 1): $(cat err.txt)"; ls -la "$mnt" "$mnt/cmp" 2>/dev/null; fi
    # room for the EXR and part of the PNG: the preview write fails half-way
    rm -f "$mnt/fill" "$mnt/cmp/"*
    size=$(wc -c <a.exr)
    dd if=/dev/zero of="$mnt/fill" bs=1 count=$((1048576 - size - 8192)) 2>/dev/null
    "$bin" shafts "$scene" $small -o "$mnt/x.exr" -q 2>err.txt
    rc=$?
    if [ "$rc" -eq 1 ] && no_leftovers "$mnt" && [ -s "$mnt/x.exr" ] && [ ! -e "$mnt/x.png" ]; then ok "full tmpfs: shafts: exit $rc: $(cat err.txt)"
    else bad "full tmpfs: shafts -o: exit $rc (want 1): $(cat err.txt)"; ls -la "$mnt"; fi
    umount "$mnt"
else
    echo "SKIP: cannot mount a tmpfs here: the file-size-limit case below stands for the full disk"
fi
# a file-size limit of 8 KiB: every write past it fails with EFBIG (SIGXFSZ ignored)
mkdir lim
(trap '' XFSZ; ulimit -f 8 && exec "$bin" compare a.exr b.exr -o lim/cmp) >/dev/null 2>err.txt
rc=$?
if [ "$rc" -eq 1 ] && no_leftovers lim && [ "$(wc -l <err.txt)" -eq 1 ] && [ ! -e lim/cmp/diff.png ]; then ok "file-size limit: compare -o: $(cat err.txt)"
else bad "file-size limit: compare -o: exit $rc (want 1): $(cat err.txt)"; ls -la lim/cmp; fi

# ---- 13: concurrent writers of one folder -------------------------------------------------
mkdir -p squat/metrics.json.tmp
"$bin" compare a.exr b.exr -o squat >/dev/null 2>err.txt || bad "compare -o with DIR/metrics.json.tmp taken: $(cat err.txt)"
rounds=${GODRAYS_TEST_REDUCED:+3}
rounds=${rounds:-8}
r=0
: >rcs.txt
while [ "$r" -lt "$rounds" ]; do
    for k in 1 2 3 4 5 6; do
        ("$bin" compare a.exr b.exr -o conc >/dev/null 2>>errs.txt; echo $? >>rcs.txt) &
    done
    wait
    r=$((r + 1))
done
nbad=$(grep -vc '^0$' rcs.txt)
if [ "$nbad" -eq 0 ] && [ -s conc/metrics.json ] && no_leftovers conc; then ok "$((rounds * 6)) concurrent compare -o: all exit 0"
else bad "concurrent compare -o: $nbad of $((rounds * 6)) failed: $(head -3 errs.txt 2>/dev/null)"; fi
exit $fail
