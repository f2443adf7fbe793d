#!/bin/sh
# `godrays tune --rgb-per-channel` (docs/tuning.md): a short run at 96 x 54 of a technique with
# an RGB gain whose blue is cut to a quarter (radial_blur.intensity = [1, 1, 0.25]): the objective
# is scored after the per-channel fit and the snippet's intensity carries the fitted factors, so
# its blue / red ratio must move back up, towards the truth's balance: above 2 x the start's
# 0.25 (the technique's own colour at intensity 1 is near the truth's: the factor is about 4).
# The same with red cut: red / blue goes up. Exit 2 for a technique whose gain is one number
# (the user technique shadow_march), and for --rgb-per-channel with another --fit.
set -u
. "$(dirname "$0")/lib.sh"
export GODRAYS_CACHE="$dir/cache"
command -v python3 >/dev/null || { echo "FAIL: python3 not found"; exit 1; }
small_scene "$dir/s.json" 96 54
common="--technique radial_blur --params radial_blur.light_radius_deg --max-evals 4 --starts 1 --coarse 0 -q"

# ratio DIR A B: the tuned snippet's intensity[A] / intensity[B] (tune.json)
ratio() {
    python3 -c "import json, sys; i = json.load(open(sys.argv[1]))['snippet']['radial_blur']['intensity']; print(i[int(sys.argv[2])] / i[int(sys.argv[3])])" "$@"
}
"$bin" tune "$dir/s.json" $common --rgb-per-channel --set 'radial_blur.intensity=[1,1,0.25]' -o "$dir/blue" \
    >"$dir/blue.txt" 2>&1
ck "blue cut: exit 0" [ $? -eq 0 ]
cat "$dir/blue.txt"
ck "blue cut: tune.json says rgb" python3 -c "
import json, sys; d = json.load(open('$dir/blue/tune.json')); sys.exit(0 if d['fit'] == 'rgb' and d['rgb_per_channel'] else 1)"
ck "blue cut: trace column after the per-channel fit" sh -c "head -1 '$dir/blue/trace.csv' | grep -q ',objective_fit_rgb$'"
br=$(ratio "$dir/blue/tune.json" 2 0)
echo "tuned intensity B / R = $br (start 0.25)"
ck "blue cut: B / R of the tuned intensity above 0.5" python3 -c "import sys; sys.exit(0 if $br > 0.5 else 1)"

"$bin" tune "$dir/s.json" $common --rgb-per-channel --set 'radial_blur.intensity=[0.25,1,1]' -o "$dir/red" \
    >"$dir/red.txt" 2>&1
ck "red cut: exit 0" [ $? -eq 0 ]
rb=$(ratio "$dir/red/tune.json" 0 2)
echo "tuned intensity R / B = $rb (start 0.25)"
ck "red cut: R / B of the tuned intensity above 0.5" python3 -c "import sys; sys.exit(0 if $rb > 0.5 else 1)"

expect 2 "--rgb-per-channel: technique shadow_march has no per-channel colour setting (its gain intensity is one number)" \
    tune "$dir/s.json" --technique-dir "$src/data/techniques/shadow_march" --technique shadow_march \
    --params shadow_march.caustics --rgb-per-channel -o "$dir/no"
expect 2 "it needs --fit rgb, not --fit scale" tune "$dir/s.json" $common --rgb-per-channel --fit scale -o "$dir/no"
expect 2 "--fit 'tint': use scale" tune "$dir/s.json" $common --fit=tint -o "$dir/no"
expect 2 "--fit 'tint': use scale" run "$dir/s.json" --fit=tint -o "$dir/no"
ck "nothing written for the refusals" [ ! -e "$dir/no" ]
exit $fail
