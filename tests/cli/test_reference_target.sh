#!/bin/sh
# `godrays reference --target-error E` refines in rounds of passes and stops at the round cap
# (64 rounds) whether or not E was met. When it was not, one warning line on stderr says so
# with the figures (even with --quiet), the image is still written and the exit code is 0;
# the figures are those of the EXR's metadata (godrays:rel_stderr_mean, godrays:rel_stderr_p95,
# godrays:passes). A target that is met prints nothing under --quiet. A 16x9 image with a
# coarse surface and 8 march steps: 64 rounds of 8 passes take about 3 s on 2 cores. And the
# warning that the surface tessellation's bias is above 1 % of the image mean (case 4).
set -u
. "$(dirname "$0")/lib.sh"
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
cd "$dir" || exit 1
scene="$src/data/scenes/default.json"
tiny="--size 16x9 --surface-res 32 --steps 8 --set reference.near_cells_per_wavelength=0 --quiet"

# 1. unreachable: 1e-6
# shellcheck disable=SC2086
"$bin" reference "$scene" -o far.exr $tiny --target-error 1e-6 >out.txt 2>err.txt
rc=$?
cat err.txt
ck "unreachable target: exit 0" [ "$rc" -eq 0 ]
ck "unreachable target: the image is written" [ -s far.exr ]
ck "unreachable target: one stderr line" [ "$(wc -l <err.txt)" -eq 1 ]
ck "unreachable target: stdout empty" [ ! -s out.txt ]
ck "the warning names the target" grep -qF "godrays reference: warning: target error 1e-06 not reached after " err.txt
ck "the warning names the cap" grep -qF "(the cap: 64 rounds of " err.txt
ck "the warning says what to raise" grep -qF "raise --sun-samples or --spp" err.txt
if command -v iinfo >/dev/null 2>&1; then
    iinfo -v far.exr >meta.txt
    m() { sed -n "s/^ *godrays:$1: *\([-0-9.eE+]*\).*/\1/p" meta.txt | head -n 1; }
    passes=$(m passes); per=$(m passes_per_round); mean=$(m rel_stderr_mean); p95=$(m rel_stderr_p95)
    echo "metadata: passes $passes ($per per round), rel. stderr mean $mean, p95 $p95"
    ck "the cap was reached: 64 rounds" [ "$passes" = "$((64 * per))" ]
    ck "the warning gives the number of passes" grep -qF "after $passes passes (the cap: 64 rounds of $per)" err.txt
    # the warning prints %.3g of the same values
    want_mean=$(awk -v v="$mean" 'BEGIN{printf "%.3g", v}'); want_p95=$(awk -v v="$p95" 'BEGIN{printf "%.3g", v}')
    ck "the warning gives the image mean's error ($want_mean)" grep -qF "image mean $want_mean," err.txt
    ck "the warning gives the p95 pixel's error ($want_p95)" grep -qF "95th-percentile pixel $want_p95;" err.txt
else
    echo "note: iinfo (OpenImageIO tools) not found: metadata not cross-checked"
fi

# 2. reachable: 0.5 (one round meets it): nothing on stderr under --quiet
# shellcheck disable=SC2086
"$bin" reference "$scene" -o near.exr $tiny --target-error 0.5 >out.txt 2>err.txt
rc=$?
ck "reachable target: exit 0" [ "$rc" -eq 0 ]
ck "reachable target: no warning" [ ! -s err.txt ]
[ -s err.txt ] && cat err.txt
# 3. the step cap (docs/reference.md 2.5, "When the cap holds the steps back"): a cap of 17
# march steps (min_steps is 16) is below what the pilot asks for in most pixels: one warning
# line (even with --quiet) with the share of the pixels held back and what they asked for,
# the figures of the EXR's godrays:steps_capped_frac and steps_wanted_mean_capped
"$bin" reference "$scene" -o cap.exr --size 16x9 --surface-res 32 --steps 17 --quiet >out.txt 2>err.txt
rc=$?
cat err.txt
ck "step cap: exit 0" [ "$rc" -eq 0 ]
ck "step cap: one stderr line" [ "$(wc -l <err.txt)" -eq 1 ]
ck "step cap: the warning names the cap" grep -qF "needs more than the cap of 17 march steps (reference.steps)" err.txt
ck "step cap: the warning says what to raise" grep -qF "raise --steps" err.txt
if command -v iinfo >/dev/null 2>&1; then
    iinfo -v cap.exr >meta.txt
    m() { sed -n "s/^ *godrays:$1: *\([-0-9.eE+]*\).*/\1/p" meta.txt | head -n 1; }
    frac=$(m steps_capped_frac); want=$(m steps_wanted_mean_capped)
    echo "metadata: steps_capped_frac $frac, steps_wanted_mean_capped $want"
    pct=$(awk -v v="$frac" 'BEGIN{printf "%.1f", 100 * v}'); w0=$(awk -v v="$want" 'BEGIN{printf "%.0f", v}')
    ck "step cap: the warning gives the share held back ($pct%)" grep -qF "in $pct% of the pixels" err.txt
    ck "step cap: the warning gives what they asked for ($w0)" grep -qF "asked for $w0 on average" err.txt
    ck "step cap: they asked for more than the cap" awk -v v="$want" 'BEGIN{exit !(v > 17)}'
fi

# 4. the surface tessellation's bias above 1 % of the image mean (docs/reference.md 4, "Views
# with a wide lit region"): without --quiet one warning gives godrays:bias_surface_rel_est and
# the remedy, twice the surface_res; under --quiet (cases 2 and 3, the same 32 cells) nothing
"$bin" reference "$scene" -o bias.exr --size 16x9 --surface-res 32 --steps 17 --no-preview >out.txt 2>err.txt
rc=$?
grep "tessellation" err.txt
ck "bias: exit 0" [ "$rc" -eq 0 ]
ck "bias: one warning naming the remedy" [ "$(grep -c "warning: the surface tessellation's bias is about .*--surface-res 64 should" err.txt)" -eq 1 ]
# the default scene at 32 cells has 1 cell per wave: the cells near the camera are refined
# (docs/reference.md 2.2, "Near the camera"), and the warning says the estimate leans high there
ck "bias: the warning names the refinement near the camera" grep -qF "the cells near the camera are refined already (godrays:surface_refine_near), but short of their target" err.txt
# where the near cells reach their target (here a target of 2 cells per wave, which factor 3
# reaches on a level view at 64 cells), the probe measures their own error with them 2x finer
# (docs/reference.md 4, "The probe and the cells near the camera") and the warning says the
# figure includes it
"$bin" reference "$scene" -o bias_held.exr --size 16x9 --surface-res 64 --steps 17 --set camera.pitch_deg=5 \
    --set reference.near_cells_per_wavelength=2 --set reference.near_radius_cells=6 --no-preview >out.txt 2>err_held.txt
rc=$?
ck "bias, near cells held: exit 0" [ "$rc" -eq 0 ]
ck "bias, near cells held: the warning says the figure includes them" grep -qF "it includes the error of the cells near the camera, refined (godrays:surface_refine_near) and measured with them 2x finer (godrays:bias_probe_near_held)" err_held.txt
if command -v iinfo >/dev/null 2>&1; then
    iinfo -v bias.exr >meta.txt
    est=$(sed -n "s/^ *godrays:bias_surface_rel_est: *\([-0-9.eE+]*\).*/\1/p" meta.txt | head -n 1)
    pct=$(awk -v v="$est" 'BEGIN{printf "%.2g", 100 * v}')
    ck "bias: the warning gives godrays:bias_surface_rel_est ($pct%)" grep -qF "bias is about $pct% of the image mean" err.txt
    ck "bias: above the 1 % line" awk -v v="$est" 'BEGIN{exit !(v > 0.01)}'
fi

[ "$fail" -eq 0 ] && echo "all checks passed"
exit $fail
