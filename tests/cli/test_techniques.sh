#!/bin/sh
# `godrays techniques` and `godrays render TECHNIQUE`:
#  - the text and JSON lists agree, every technique has a description and every setting its
#    key, type, range, default, unit and doc; every setting is documented in its section of
#    docs/scene-format.md (an independent list, written by hand);
#  - bad usage exits 2 with one line: an unknown technique (naming the known ones), a missing
#    technique, a --technique-dir that cannot be loaded, an unknown option;
#  - `render NAME` writes the EXR (its metadata names the technique and every setting) and its
#    PNG preview, and `godrays shafts` is `render shafts`: the same pixels.
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}

"$bin" techniques >"$dir/list.txt" 2>"$dir/list.err"
ck "techniques exits 0" [ $? -eq 0 ]
"$bin" techniques --json >"$dir/list.json" 2>"$dir/json.err"
ck "techniques --json exits 0" [ $? -eq 0 ]
python3 - "$dir/list.json" "$dir/list.txt" "$src/docs/scene-format.md" <<'PY' || fail=1
import json, sys
d = json.load(open(sys.argv[1]))
text = open(sys.argv[2]).read()
doc = open(sys.argv[3]).read()
bad = 0
names = [t["name"] for t in d["techniques"]]
if not names:
    print("FAIL: no technique listed"); bad = 1
for t in d["techniques"]:
    n = t["name"]
    if not t.get("description"):
        print(f"FAIL: {n} has no description"); bad = 1
    if (n + "  (") not in text:
        print(f"FAIL: {n} missing from the text list"); bad = 1
    sec = doc.find("### `%s`" % n)
    if sec < 0:
        print(f"FAIL: docs/scene-format.md has no section for {n}"); bad = 1
    nxt = doc.find("\n### ", sec + 1)
    body = doc[sec:nxt if nxt > 0 else len(doc)]
    if not t["settings"]:
        print(f"FAIL: {n} has no settings"); bad = 1
    for p in t["settings"]:
        for k in ("key", "type", "range", "unit", "doc"):
            if k not in p:
                print(f"FAIL: {n}.{p.get('key')} lacks {k}"); bad = 1
        if "default" not in p:
            print(f"FAIL: {n}.{p['key']} lacks a default"); bad = 1
        if p["default"] is None and not p.get("default_from"):
            print(f"FAIL: {n}.{p['key']}: null default without default_from"); bad = 1
        if ("%s.%s " % (n, p["key"])) not in text:
            print(f"FAIL: {n}.{p['key']} missing from the text list"); bad = 1
        if ("| `%s` |" % p["key"]) not in body:
            print(f"FAIL: {n}.{p['key']} not documented in its docs/scene-format.md section"); bad = 1
print("techniques:", ", ".join(names), "- lists agree" if not bad else "")
sys.exit(bad)
PY

scene="$src/data/scenes/default.json"
expect 2 "unknown technique 'no_such_technique'" render no_such_technique "$scene" -o "$dir/x.exr"
first=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["techniques"][0]["name"])' "$dir/list.json")
expect 2 "$first" render no_such_technique "$scene" -o "$dir/x.exr" # the message lists the known ones
expect 2 "no technique given" render
expect 2 "expected TECHNIQUE SCENE" render "$scene"
expect 2 "$dir/no_such_dir" techniques --technique-dir "$dir/no_such_dir"
expect 2 "$dir/no_such_dir" render "$first" "$scene" --technique-dir "$dir/no_such_dir" -o "$dir/x.exr"
expect 2 "unknown argument --bogus" techniques --bogus
expect 2 "$first.no_such_key" render "$first" "$scene" --set "$first.no_such_key=1" -o "$dir/x.exr"
ck "no output left by the failures" sh -c "! ls '$dir'/x* 2>/dev/null"

# every technique renders, its EXR names it
for t in $(python3 -c 'import json,sys; print(" ".join(t["name"] for t in json.load(open(sys.argv[1]))["techniques"]))' "$dir/list.json"); do
  "$bin" render "$t" "$scene" --size 64x36 -o "$dir/$t.exr" >"$dir/r.out" 2>"$dir/r.err"
  ck "render $t exits 0" [ $? -eq 0 ]
  ck "render $t wrote the EXR and its preview" [ -s "$dir/$t.exr" ] && [ -s "$dir/$t.png" ]
  ck "render $t prints its GPU and wall times" grep -q "^$dir/$t.exr: $t, t = .* GPU ms:.*; wall " "$dir/r.out"
  if command -v iinfo >/dev/null 2>&1; then
    iinfo -v "$dir/$t.exr" >"$dir/info" 2>&1
    ck "$t.exr metadata names the technique" grep -q "godrays:technique: \"$t\"" "$dir/info"
    ck "$t.exr metadata has the GPU and wall times" grep -q "godrays:wall_ms" "$dir/info"
  fi
done
# the alias: same pixels as render shafts (and the same default output name)
if grep -q "^  shafts  " "$dir/list.txt" || python3 -c 'import json,sys; sys.exit(0 if any(t["name"]=="shafts" for t in json.load(open(sys.argv[1]))["techniques"]) else 1)' "$dir/list.json"; then
  (cd "$dir" && "$bin" shafts "$scene" --size 64x36 -q) || { echo "FAIL: godrays shafts"; fail=1; }
  ck "godrays shafts writes shafts.exr by default" [ -s "$dir/shafts.exr" ]
  "$bin" render shafts "$scene" --size 64x36 -q -o "$dir/r2.exr"
  if command -v idiff >/dev/null 2>&1; then
    ck "godrays shafts = godrays render shafts (pixels)" idiff -q "$dir/shafts.exr" "$dir/r2.exr"
  fi
fi
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
