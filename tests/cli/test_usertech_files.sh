#!/bin/sh
# Issue 31, findings 4, 5 and 10 (docs/reliability.md, "Issue 31: user techniques and time
# limit"): every file of a user technique is read by one reader (gr_ut_read_file) that
#   - refuses a FIFO as manifest.json or as a shader without blocking (the old reader opened it
#     before checking its type and hung: `timeout` turns a hang into a failure here),
#   - caps a manifest and a shader at 1 MiB (a 100 MB manifest took 4.1 GB),
#   - reads nothing outside the technique folder: an absolute shader path, "../", a shader or
#     a manifest that is a symbolic link out of the folder (the manifest's first line was
#     echoed in the JSON error), while links that stay inside the folder still work.
. "$(dirname "$0")/lib.sh"

# a valid technique in $1 (fragment shader f.frag)
make_tech() {
    mkdir -p "$1"
    cat >"$1/manifest.json" <<'JSON'
{"version": 1, "name": "files_probe", "description": "reads files",
 "targets": {"out": {"format": "rgba32f"}},
 "passes": [{"name": "only", "fragment": "f.frag", "target": "out"}]}
JSON
    printf 'out vec4 o_color;\nvoid main() { o_color = vec4(1.0); }\n' >"$1/f.frag"
}

# tex CODE TEXT DIR: `techniques --technique-dir DIR` (at most 20 s) exits CODE with one line
tex() {
    want=$1; text=$2; d=$3
    timeout 20 "$bin" techniques --technique-dir "$d" >"$dir/out" 2>"$dir/err"
    rc=$?
    lines=$(wc -l <"$dir/err")
    if [ "$want" -eq 0 ]; then
        if [ "$rc" -eq 0 ] && grep -qF files_probe "$dir/out"; then echo "ok: $text"; else
            echo "FAIL: $text: exit $rc"; cat "$dir/err"; fail=1; fi
        return
    fi
    if [ "$rc" -ne "$want" ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$text" "$dir/err"; then
        echo "FAIL: $d: exit $rc (want $want; 124 = hung), $lines stderr line(s) (want 1 containing '$text'):"
        cat "$dir/err"; fail=1
    else
        echo "ok: $(cat "$dir/err")"
    fi
}

make_tech "$dir/good"
tex 0 "a valid technique" "$dir/good"

# finding 4: FIFOs
make_tech "$dir/fifo_manifest"
rm "$dir/fifo_manifest/manifest.json"
mkfifo "$dir/fifo_manifest/manifest.json"
tex 2 "fifo_manifest/manifest.json: cannot read the manifest: not a regular file" "$dir/fifo_manifest"
make_tech "$dir/fifo_shader"
rm "$dir/fifo_shader/f.frag"
mkfifo "$dir/fifo_shader/f.frag"
tex 2 "passes[0].fragment: cannot read shader $dir/fifo_shader/f.frag: not a regular file" "$dir/fifo_shader"

# finding 5: size caps (1 MiB = 1048576 bytes); a manifest of 2 MiB of spaces is valid JSON
make_tech "$dir/big_manifest"
head -c 2097152 /dev/zero | tr '\0' ' ' >>"$dir/big_manifest/manifest.json"
tex 2 "cannot read the manifest: $(wc -c <"$dir/big_manifest/manifest.json") bytes, over the cap of 1048576 bytes (1 MiB)" "$dir/big_manifest"
make_tech "$dir/big_shader"
head -c 1048577 /dev/zero | tr '\0' '\n' >>"$dir/big_shader/f.frag"
tex 2 "f.frag: $(wc -c <"$dir/big_shader/f.frag") bytes, over the cap of 1048576 bytes" "$dir/big_shader"

# finding 10: nothing outside the folder
printf 'SECRET-FIRST-LINE {\n' >"$dir/outside.txt"
printf 'out vec4 o_color;\nvoid main() { o_color = vec4(1.0); }\n' >"$dir/outside.frag"
make_tech "$dir/link_manifest"
rm "$dir/link_manifest/manifest.json"
ln -s ../outside.txt "$dir/link_manifest/manifest.json"
tex 2 "link_manifest/manifest.json: cannot read the manifest: outside the technique folder" "$dir/link_manifest"
ck "no message quotes a file outside the folder" sh -c "! grep -q SECRET '$dir/err'"
make_tech "$dir/link_shader"
rm "$dir/link_shader/f.frag"
ln -s ../outside.frag "$dir/link_shader/f.frag"
tex 2 "link_shader/f.frag: outside the technique folder" "$dir/link_shader"
make_tech "$dir/dotdot"
sed -i 's|"f.frag"|"../outside.frag"|' "$dir/dotdot/manifest.json"
tex 2 "dotdot/../outside.frag: outside the technique folder" "$dir/dotdot"
make_tech "$dir/absolute"
sed -i "s|\"f.frag\"|\"$dir/absolute/f.frag\"|" "$dir/absolute/manifest.json"
tex 2 "passes[0].fragment: '$dir/absolute/f.frag': an absolute path" "$dir/absolute"

# links that stay inside the folder, and a folder given through a link, are fine
make_tech "$dir/inner_link"
mkdir "$dir/inner_link/sub"
mv "$dir/inner_link/f.frag" "$dir/inner_link/sub/real.frag"
ln -s sub/real.frag "$dir/inner_link/f.frag"
tex 0 "a shader linked inside the folder" "$dir/inner_link"
ln -s good "$dir/good_link"
tex 0 "a folder given through a link" "$dir/good_link"
exit $fail
