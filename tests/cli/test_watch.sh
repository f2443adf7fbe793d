#!/bin/sh
# `godrays watch` (docs/techniques.md "The edit-to-verdict loop") on a copy of the test
# technique light_blur, a 64x36 scene and a cheap ground truth (well under a second):
#  - the URL is printed; /state.json says render 1 is ok with a verdict; the PNGs decode;
#  - a save (a constant changed in the shader) gives render 2 within 5 s, seen both in the
#    JSON and in the page as headless Chromium (Debian's `chromium`, --dump-dom after a short
#    virtual-time budget) lays it out: the render id, status and verdict filled in by the
#    page's own script (both timed from the save); the new image differs from the old one;
#  - a burst of three writes 20 ms apart is one render (the debounce);
#  - a broken shader: the page shows "compile error" and the compiler's line
#    "blur.frag:LINE:COL: ..." from the user's own file;
#  - a second watch on the same port exits 2 naming the port;
#  - SIGINT: exit 0, "stopped", and the port no longer answers.
# Without Chromium the page checks are skipped (with a message) except in CI (CI=true).
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
browser=""
for b in chromium chromium-browser; do
    if command -v "$b" >/dev/null 2>&1; then browser=$b; break; fi
done
if [ -z "$browser" ] && [ "${CI:-}" = "true" ]; then
    echo "FAIL: chromium is not installed (scripts/setup.sh installs it; CI must run this test)"
    exit 1
fi
command -v curl >/dev/null 2>&1 || { echo "SKIP: curl is not installed"; exit 0; }
cp -r "$src/tests/techniques/light_blur" "$dir/tech"
export GODRAYS_CACHE="$dir/cache"
set -- "$src/data/scenes/default.json" --size 64x36 --set reference.surface_res=64 --set reference.sun_samples=2 \
    --set reference.batches=2 --set reference.steps=16
"$bin" watch "$dir/tech" "$@" >"$dir/watch.out" 2>"$dir/watch.err" &
pid=$!
now() { date +%s.%N; }
elapsed() { echo "$(now) - $1" | bc; } # seconds since $1
state() { curl -s --max-time 2 "http://127.0.0.1:$port/state.json"; }
render_id() { state | sed -n 's/^{"id":\([0-9]*\),.*/\1/p'; }
# wait_id N SECONDS: until /state.json's id is N (1: ok)
wait_id() {
    t=$(now)
    while [ "$(echo "$(elapsed "$t") < $2" | bc)" -eq 1 ]; do
        [ "$(render_id)" = "$1" ] && return 0
        sleep 0.05
    done
    return 1
}
profile=$(mktemp -d)
trap 'kill -9 $pid 2>/dev/null; rm -rf "$dir" "$profile"' EXIT
# page FILE: the page as Chromium lays it out after its script ran (one poll is enough)
page() {
    # shellcheck disable=SC2086
    timeout 60 "$browser" --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking \
        --disable-component-update --disable-sync --user-data-dir="$profile" --virtual-time-budget=2000 \
        --dump-dom "http://127.0.0.1:$port/" >"$1" 2>"$dir/chromium.err"
}
port=""
i=0
while [ -z "$port" ] && [ $i -lt 600 ]; do
    port=$(sed -n 's|^godrays watch: http://127.0.0.1:\([0-9]*\)/ .*|\1|p' "$dir/watch.out")
    [ -n "$port" ] || sleep 0.1
    i=$((i + 1))
done
ck "the URL is printed" [ -n "$port" ]
[ -n "$port" ] || { cat "$dir/watch.out" "$dir/watch.err"; exit 1; }
ck "render 1 is published" wait_id 1 30
state >"$dir/s1.json"
ck "render 1 is ok and scored" grep -q '"ok":true.*"metrics":\[{"key":"rmse".*"verdict":[0-9]' "$dir/s1.json"
for k in test truth diff flip; do
    curl -s "http://127.0.0.1:$port/img/$k.png?id=1" -o "$dir/$k.1.png"
    case $k in
        diff) want="PNG image data, " ;; # with its colorbar below
        *) want="PNG image data, 64 x 36," ;;
    esac
    ck "img/$k.png is a PNG ($want)" sh -c "file '$dir/$k.1.png' | grep -q '$want'"
done
ck "an unknown URL is 404" [ "$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$port/nothing")" = 404 ]

# a save: the blur's sum doubled
sed -i 's/vec3 c = texture(t_sun_light, uv).rgb;/vec3 c = 2.0 * texture(t_sun_light, uv).rgb;/' "$dir/tech/blur.frag"
t_save=$(now)
ck "the edit is in the file" grep -q '2.0 \* texture' "$dir/tech/blur.frag"
ck "render 2 is published within 5 s of the save" wait_id 2 5
echo "JSON: render 2 after $(elapsed "$t_save") s"
state >"$dir/s2.json"
ck "render 2 names the file saved" grep -q '"changed":"blur.frag"' "$dir/s2.json"
curl -s "http://127.0.0.1:$port/img/test.png?id=2" -o "$dir/test.2.png"
ck "the new render's image differs" sh -c "! cmp -s '$dir/test.1.png' '$dir/test.2.png'"
if [ -n "$browser" ]; then
    page "$dir/dom2.html"
    t_page=$(elapsed "$t_save")
    echo "page: render 2 laid out by Chromium $t_page s after the save"
    ck "the page shows render 2 (filled by its script)" grep -q 'id="render-id">2<' "$dir/dom2.html"
    ck "the page shows the verdict" grep -Eq 'id="verdict">[0-9]' "$dir/dom2.html"
    ck "the page shows the status ok" grep -q 'id="status" class="ok">ok<' "$dir/dom2.html"
    ck "the page showed it within 5 s of the save" [ "$(echo "$t_page < 5" | bc)" -eq 1 ]
    ck "the page's image URL is render 2's" grep -q 'src="img/test.png?id=2"' "$dir/dom2.html"
fi

# a burst of writes is one render
for k in 1 2 3; do printf '// %s\n' "$k" >>"$dir/tech/blur.frag"; sleep 0.02; done
ck "a burst of three writes gives render 3" wait_id 3 5
sleep 0.5
ck "... and no render 4" [ "$(render_id)" = 3 ]

# a broken shader: the compiler's log in the page
sed -i 's/o_color = vec4/o_colour = vec4/' "$dir/tech/blur.frag"
ck "render 4 (the broken shader) is published" wait_id 4 5
state >"$dir/s4.json"
ck "render 4 is a compile error" grep -q '"ok":false,"stage":"compile"' "$dir/s4.json"
line=$(grep -n 'o_colour' "$dir/tech/blur.frag" | cut -d: -f1)
ck "the message names blur.frag:$line" grep -q "blur.frag:$line:" "$dir/s4.json"
if [ -n "$browser" ]; then
    page "$dir/dom4.html"
    ck "the page shows the compile error" grep -q 'id="status" class="bad">compile error<' "$dir/dom4.html"
    ck "the page shows the compiler's line blur.frag:$line:" sh -c \
        "sed -n '/<pre id=\"log\"/,/<\/pre>/p' '$dir/dom4.html' | grep -q 'blur.frag:$line:[0-9]*: '"
fi
grep -q "render 4 (blur.frag): compile error: " "$dir/watch.out"
ck "stdout has one line per render, render 4 the compile error" [ $? -eq 0 ]

# the port is taken: a second watch exits 2 naming it
"$bin" watch "$dir/tech" "$@" --port "$port" -q >"$dir/w2.out" 2>"$dir/w2.err"
ck "a second watch on port $port exits 2" [ $? -eq 2 ]
ck "... naming the port" grep -q "^godrays watch: --port $port: cannot listen on 127.0.0.1:$port: " "$dir/w2.err"

# Ctrl-C
kill -INT $pid
wait $pid
rc=$?
ck "SIGINT: exit 0" [ "$rc" -eq 0 ]
ck "SIGINT: 'stopped' on stderr" grep -q '^godrays watch: stopped$' "$dir/watch.err"
ck "the port is closed" sh -c "! curl -s --max-time 2 -o /dev/null 'http://127.0.0.1:$port/state.json'"
[ "$fail" -eq 0 ] || { cat "$dir/watch.out" "$dir/watch.err"; }
exit $fail
