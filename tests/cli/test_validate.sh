#!/bin/sh
# `godrays validate`: exit codes, normalized output, --set, and every shipped scene.
# Env (set by ctest): GODRAYS_BINARY, GODRAYS_SOURCE_DIR, GODRAYS_TEST_OUT.
bin=${GODRAYS_BINARY:?}
src=${GODRAYS_SOURCE_DIR:?}
tmp=$(mktemp -d "${GODRAYS_TEST_OUT:-/tmp}/validate.XXXXXX")
fail=0
die() { echo "FAIL: $*"; fail=1; }

# 1. the default scene validates; stdout is the normalized scene, stderr is empty
"$bin" validate "$src/data/scenes/default.json" >"$tmp/a.json" 2>"$tmp/err"
rc=$?
[ "$rc" -eq 0 ] || die "default.json: exit $rc: $(cat "$tmp/err")"
[ -s "$tmp/err" ] && die "default.json: stderr not empty: $(cat "$tmp/err")"
grep -q '"name": "default"' "$tmp/a.json" || die "default.json: output lacks the name"
grep -q '"transmittance_cutoff": ' "$tmp/a.json" || die "default.json: output lacks filled-in defaults"

# 2. the normalized output is itself a valid scene and a fixed point
"$bin" validate "$tmp/a.json" >"$tmp/b.json" 2>"$tmp/err" || die "normalized output does not validate: $(cat "$tmp/err")"
cmp -s "$tmp/a.json" "$tmp/b.json" || die "validate(validate(x)) != validate(x)"

# 3. --set changes the output, and only the overridden key
"$bin" validate --set camera.fov_deg=50 "$src/data/scenes/default.json" >"$tmp/c.json" 2>"$tmp/err" \
    || die "--set camera.fov_deg=50: $(cat "$tmp/err")"
grep -q '"fov_deg": 50,' "$tmp/c.json" || die "--set did not change fov_deg"
ndiff=$(diff "$tmp/a.json" "$tmp/c.json" | grep -c '^[<>]')
[ "$ndiff" -eq 2 ] || die "--set camera.fov_deg changed $ndiff lines, want 2 (one out, one in)"
"$bin" validate --set=medium.g=0.5 --set 'water.waves[0].amplitude_m=0.2' "$src/data/scenes/default.json" \
    >"$tmp/d.json" 2>"$tmp/err" || die "two overrides: $(cat "$tmp/err")"
grep -q '"g": 0.5' "$tmp/d.json" || die "--set=medium.g=0.5 not applied"
grep -q '{"amplitude_m": 0.2,' "$tmp/d.json" || die "array-index override not applied"

# 4. a bad --set key exits 2 with one line naming the override
"$bin" validate --set shafts.Kx=1 "$src/data/scenes/default.json" >"$tmp/out" 2>"$tmp/err"
rc=$?
[ "$rc" -eq 2 ] || die "bad --set key: exit $rc, want 2"
grep -qF 'godrays validate: --set shafts.Kx=1: shafts.Kx: unknown key' "$tmp/err" || die "bad --set key: got: $(cat "$tmp/err")"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || die "bad --set key: stderr is not one line"
[ -s "$tmp/out" ] && die "bad --set key: stdout not empty"

# 5. a missing file is an I/O error: exit 1, one line naming the file
"$bin" validate "$tmp/no-such-scene.json" >"$tmp/out" 2>"$tmp/err"
rc=$?
[ "$rc" -eq 1 ] || die "missing file: exit $rc, want 1"
grep -qF "$tmp/no-such-scene.json: cannot open" "$tmp/err" || die "missing file: got: $(cat "$tmp/err")"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || die "missing file: stderr is not one line"

# 6. usage errors exit 2; --help exits 0 and prints to stdout
"$bin" validate >/dev/null 2>"$tmp/err"; rc=$?
[ "$rc" -eq 2 ] || die "no scene: exit $rc, want 2"
grep -q 'see godrays validate --help' "$tmp/err" || die "no scene: got: $(cat "$tmp/err")"
"$bin" validate --bogus "$src/data/scenes/default.json" >/dev/null 2>&1; rc=$?
[ "$rc" -eq 2 ] || die "unknown option: exit $rc, want 2"
"$bin" validate "$src/data/scenes/default.json" "$src/data/scenes/flat.json" >/dev/null 2>&1; rc=$?
[ "$rc" -eq 2 ] || die "two scenes: exit $rc, want 2"
"$bin" validate --set >/dev/null 2>&1; rc=$?
[ "$rc" -eq 2 ] || die "--set without value: exit $rc, want 2"
"$bin" validate --help >"$tmp/out" 2>/dev/null; rc=$?
[ "$rc" -eq 0 ] || die "--help: exit $rc"
grep -q 'usage: godrays validate' "$tmp/out" || die "--help prints no usage"

# 7. every shipped scene validates, and its normalized form reloads to the same text
n=0
for f in "$src"/data/scenes/*.json "$src"/data/scenes/*/*.json; do
    [ -e "$f" ] || continue
    n=$((n + 1))
    if ! "$bin" validate "$f" >"$tmp/s1.json" 2>"$tmp/err"; then die "$f: $(cat "$tmp/err")"; continue; fi
    "$bin" validate "$tmp/s1.json" >"$tmp/s2.json" 2>"$tmp/err" || die "$f normalized: $(cat "$tmp/err")"
    cmp -s "$tmp/s1.json" "$tmp/s2.json" || die "$f: normalized form is not a fixed point"
done
[ "$n" -ge 13 ] || die "only $n shipped scenes found"
echo "checked $n shipped scenes"

rm -rf "$tmp"
[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
