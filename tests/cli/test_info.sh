#!/bin/sh
# `godrays info` makes a real headless context: exit 0, an OpenGL renderer line, and every
# library version in dotted form; `--json` gives the same facts as one parseable object.
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
out=$(mktemp); errf=$(mktemp)
trap 'rm -f "$out" "$errf"' EXIT
fail=0
"$bin" info >"$out" 2>"$errf"
rc=$?
cat "$out"
if [ "$rc" -ne 0 ]; then echo "FAIL: godrays info exit $rc: $(cat "$errf")"; fail=1; fi
# a non-empty renderer after the label
if ! grep -Eq '^OpenGL renderer +[^ ]' "$out"; then echo "FAIL: no 'OpenGL renderer' line"; fail=1; fi
for lib in godrays Embree OpenEXR OpenImageIO cJSON; do
  if ! grep -Eq "^$lib +[0-9]+\.[0-9]+\.[0-9]+" "$out"; then echo "FAIL: no version for $lib"; fail=1; fi
done
# PLplot: a version when linked, else says so
if ! grep -Eq '^PLplot +([0-9]+\.[0-9]+|not linked)' "$out"; then echo "FAIL: no PLplot line"; fail=1; fi
if ! grep -Eq '^EGL platform +(surfaceless|device)$' "$out"; then echo "FAIL: no EGL platform line"; fail=1; fi
if ! grep -Eq '^max texture size +[1-9][0-9]+$' "$out"; then echo "FAIL: no max texture size"; fail=1; fi
# The versions the binary reports must be the installed packages' (an independent source).
if command -v dpkg-query >/dev/null 2>&1; then
  emb=$(dpkg-query -W -f '${Version}' libembree3-3 2>/dev/null | sed 's/[+~-].*//')
  if [ -n "$emb" ] && ! grep -Eq "^Embree +$emb " "$out"; then echo "FAIL: Embree is not $emb"; fail=1; fi
  cj=$(dpkg-query -W -f '${Version}' libcjson1 2>/dev/null | sed 's/[+~-].*//')
  if [ -n "$cj" ] && ! grep -Eq "^cJSON +$cj\$" "$out"; then echo "FAIL: cJSON is not $cj"; fail=1; fi
fi
# --json: one object with the same renderer
"$bin" info --json >"$out" 2>"$errf"
rc=$?
if [ "$rc" -ne 0 ]; then echo "FAIL: godrays info --json exit $rc"; fail=1; fi
if command -v python3 >/dev/null 2>&1; then
  if ! python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["gl"]["renderer"] and d["embree"]["version"] and d["openexr"], d' "$out"; then
    echo "FAIL: --json output is not the expected JSON"; fail=1
  fi
elif ! grep -q '"renderer"' "$out"; then echo "FAIL: --json lacks renderer"; fail=1; fi
# help and a bad flag
"$bin" info --help >"$out" 2>&1 || { echo "FAIL: info --help exit non-zero"; fail=1; }
grep -q 'usage: godrays info' "$out" || { echo "FAIL: info --help has no usage line"; fail=1; }
"$bin" info --nosuchflag >"$out" 2>"$errf"
rc=$?
if [ "$rc" -ne 2 ] || [ "$(wc -l <"$errf")" -ne 1 ]; then echo "FAIL: bad flag: exit $rc, stderr: $(cat "$errf")"; fail=1; fi
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
