# Shared preamble of the shell-level CLI tests: source it first (`. "$(dirname "$0")/lib.sh"`).
# It sets
#   bin   the godrays binary (GODRAYS_BINARY, set by ctest)
#   src   the source tree (GODRAYS_SOURCE_DIR; empty when not set)
#   dir   a fresh temporary folder, removed when the script exits
#   fail  0; the helpers below set it to 1 on a failure, and the script ends with `exit $fail`
# and defines
#   ck DESCRIPTION COMMAND...   records a failure if COMMAND fails
#   expect CODE TEXT ARGS...    godrays ARGS... must exit CODE with exactly one stderr line that
#                               contains TEXT (fixed string) and print nothing on stdout
#   small_scene PATH W H [JSON] writes a small wavy scene of W x H pixels; JSON (optional) is
#                               more top-level members, e.g. '"radial_blur": {"samples": 40}'
bin=${GODRAYS_BINARY:?GODRAYS_BINARY is not set (run through ctest)}
src=${GODRAYS_SOURCE_DIR:-}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0

ck() {
    d=$1; shift
    if "$@"; then echo "ok: $d"; else echo "FAIL: $d"; fail=1; fi
}

expect() {
    want=$1; text=$2; shift 2
    "$bin" "$@" >"$dir/out" 2>"$dir/err"
    rc=$?
    lines=$(wc -l <"$dir/err")
    if [ "$rc" -ne "$want" ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$text" "$dir/err" || [ -s "$dir/out" ]; then
        echo "FAIL: $*: exit $rc (want $want), $lines stderr line(s) (want 1 containing '$text'):"
        cat "$dir/err"; fail=1
    else
        echo "ok: $*: $(cat "$dir/err")"
    fi
}

small_scene() {
    extra=${4:+,
 $4}
    cat >"$1" <<JSON
{"name": "small", "water": {"waves": [{"amplitude_m": 0.1, "wavelength_m": 8, "direction_deg": 30}]},
 "sun": {"elevation_deg": 60, "azimuth_deg": 30},
 "medium": {"absorption_per_m": [0.3, 0.06, 0.03], "scattering_per_m": 0.03, "g": 0.8},
 "camera": {"position_m": [0, -8, 0], "yaw_deg": 30, "pitch_deg": 60, "fov_deg": 60, "width": $2, "height": $3}$extra}
JSON
}
