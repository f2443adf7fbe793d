#!/bin/sh
# The eevee technique (Blender as a child process, docs/engines.md section 5) where Blender or a
# display is missing, fails, hangs or is interrupted; no real Blender runs here (a fake one does):
#   - no blender on PATH: `techniques` lists eevee as unavailable with the reason; `render eevee`
#     and `run --techniques eevee,...` exit 2 with one line naming blender;
#   - no xvfb-run and no $DISPLAY: the same, naming xvfb-run;
#   - a Blender that fails: exit 1, one line with its exit status and its last log lines;
#   - a Blender that hangs: the time limit (--time-limit 1) stops it, exit 1 naming the limit,
#     and its process is gone; Ctrl-C (SIGINT to godrays) stops it as well.
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
small_scene "$dir/s.json" 16 9

# a PATH with the tools but neither blender nor xvfb-run
mkdir -p "$dir/bin" "$dir/bin_x"
for t in sh sleep echo cat; do ln -s "$(command -v $t)" "$dir/bin/$t"; done
ln -s "$(command -v sh)" "$dir/bin_x/sh"
cat >"$dir/bin_x/xvfb-run" <<'SH'
#!/bin/sh
echo "fake xvfb-run: never run"; exit 9
SH
chmod +x "$dir/bin_x/xvfb-run"
real=$bin
wrap() { # wrap NAME ENV...: a godrays that runs with that environment
    w="$dir/$1"; shift
    printf '#!/bin/sh\nexec env %s "%s" "$@"\n' "$*" "$real" >"$w"
    chmod +x "$w"
}

wrap no_blender -u GODRAYS_BLENDER PATH="$dir/bin_x"
bin="$dir/no_blender"
"$bin" techniques >"$dir/list" 2>&1
ck "techniques lists eevee as unavailable, naming blender" \
    grep -q "unavailable here: blender not found on PATH" "$dir/list"
"$bin" techniques --json >"$dir/list.json" 2>&1
ck "techniques --json: available false with the reason" grep -q '"unavailable_reason":.*blender not found' "$dir/list.json"
expect 2 "technique 'eevee' is unavailable here: blender not found on PATH" render eevee "$dir/s.json" -o "$dir/e.exr"
expect 2 "technique 'eevee' is unavailable here: blender not found on PATH" run "$dir/s.json" --techniques eevee,froxel -o "$dir/r"
ck "nothing written" test ! -e "$dir/e.exr"

# a fake Blender, with no display at all
cat >"$dir/fail_blender" <<'SH'
#!/bin/sh
echo "Blender 3.4.1 (fake)"
echo "Read prefs: nothing"
echo "ERROR (gpu.shader): fake failure, the line before the last"
echo "the last line of the fake"
exit 3
SH
chmod +x "$dir/fail_blender"
wrap no_display -u DISPLAY GODRAYS_BLENDER="$dir/fail_blender" PATH="$dir/bin"
bin="$dir/no_display"
expect 2 "xvfb-run not found on PATH and no \$DISPLAY" render eevee "$dir/s.json" -o "$dir/e.exr"

# the failing Blender with a display: its last lines reach the user
wrap failing DISPLAY=:77 GODRAYS_BLENDER="$dir/fail_blender" PATH="$dir/bin"
bin="$dir/failing"
expect 1 "Blender exited with status 3 before the render was done; its last lines: Blender 3.4.1 (fake) | Read prefs: nothing | ERROR (gpu.shader): fake failure, the line before the last | the last line of the fake" \
    render eevee "$dir/s.json" -o "$dir/e.exr"

# a hanging Blender: the time limit stops it and its process
cat >"$dir/hang_blender" <<SH
#!/bin/sh
echo \$\$ >"$dir/hang.pid"
echo "hanging"
exec sleep 60
SH
chmod +x "$dir/hang_blender"
wrap hanging DISPLAY=:77 GODRAYS_BLENDER="$dir/hang_blender" PATH="$dir/bin"
bin="$dir/hanging"
t0=$(date +%s)
expect 1 "Blender's render not done after the time limit of 1 s (--time-limit" render eevee "$dir/s.json" -o "$dir/e.exr" --time-limit 1
t1=$(date +%s)
ck "the time limit acted within 6 s ($((t1 - t0)) s)" test $((t1 - t0)) -le 6
ck "the hanging Blender is gone" sh -c "! kill -0 \$(cat '$dir/hang.pid') 2>/dev/null"

# Ctrl-C during the render stops Blender too
rm -f "$dir/hang.pid"
"$bin" render eevee "$dir/s.json" -o "$dir/e.exr" >"$dir/out" 2>"$dir/err" &
gpid=$!
for i in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20; do [ -s "$dir/hang.pid" ] && break; sleep 0.5; done
kill -INT $gpid
wait $gpid
rc=$?
ck "Ctrl-C: exit 1 (got $rc), interrupted" sh -c "[ $rc -eq 1 ] && grep -q 'interrupted' '$dir/err'"
ck "Ctrl-C: the hanging Blender is gone" sh -c "! kill -0 \$(cat '$dir/hang.pid') 2>/dev/null"
exit $fail
