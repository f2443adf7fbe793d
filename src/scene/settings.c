/* Descriptor table of the ground truth's settings (settings.h). One row per field:
 * key, type, range, default, unit, doc. docs/scene-format.md lists the same rows
 * (tests/unit/test_scene_doc.c checks that every key is documented there).
 * Ranges are sanity bounds that keep a run finite and well-defined, not tuning advice. */
#include "scene/settings.h"

#include <math.h>
#include <stddef.h>

#define NONE 0u
#define LO_X GR_PF_MIN_EXCL
#define HI_X GR_PF_MAX_EXCL
#define FROM GR_PF_FROM_SCENE

static const char *const sun_disc_names[] = {"convolve", "sample", NULL};

#define REF(field) offsetof(gr_reference_settings, field)
static const gr_param reference_params[] = {
    {.name = "spp", .type = GR_PT_INT, .offset = REF(spp), .min = 1, .max = 1 << 20, .def = 1,
     .unit = "", .doc = "camera samples per pixel in each batch"},
    {.name = "camera_rays", .type = GR_PT_INT, .offset = REF(camera_rays), .min = 1, .max = 16, .def = 4,
     .unit = "", .doc = "camera rays sharing each camera sample's march steps, one in each sub-cell of its pixel cell (round robin over the steps): the pixel's footprint sampled more finely at the same steps"},
    {.name = "antithetic", .type = GR_PT_BOOL, .offset = REF(antithetic), .min = 0, .max = 1, .def = 0,
     .unit = "", .doc = "a batch's passes in pairs whose surface grids are offset by half a cell in both directions, whose rays are mirrored in their sub-cells and whose steps lie half a stratum apart, so that their tessellation, footprint and step noise largely cancel (the step pilot counts a pair as one sample of twice the strata); needs 2 or more passes per batch (sun_samples >= 2 batches, e.g. batches 4: about 0.8 of the default's CPU time, every 8x8 block under 0.35 %, 3 degrees of freedom; docs/reference.md 2.5)"},
    {.name = "steps", .type = GR_PT_INT, .offset = REF(steps), .min = 1, .max = 1 << 16, .def = 64,
     .unit = "", .doc = "stratified, jittered march steps along each camera ray (with adaptive_steps: the most a pixel takes)"},
    {.name = "surface_res", .type = GR_PT_INT, .offset = REF(surface_res), .min = 2, .max = 16384,
     .def = 256, .unit = "", .doc = "surface tessellation: cells along each axis of the lit patch"},
    {.name = "sun_samples", .type = GR_PT_INT, .offset = REF(sun_samples), .min = 1, .max = 4096,
     .def = 8, .unit = "", .doc = "passes per round: surface-grid offsets (and sun directions with sun_disc = sample)"},
    {.name = "batches", .type = GR_PT_INT, .offset = REF(batches), .min = 2, .max = 1024, .def = 8,
     .unit = "", .doc = "independent batches for the standard-error estimate"},
    {.name = "seed", .type = GR_PT_U64, .offset = REF(seed), .min = 0, .max = 9007199254740991.0,
     .def = 1, .unit = "", .doc = "RNG seed: same seed, same bytes, any thread count"},
    {.name = "threads", .type = GR_PT_INT, .offset = REF(threads), .min = 0, .max = 1024, .def = 0,
     .unit = "", .doc = "worker threads, 0 = all cores"},
    {.name = "target_error", .type = GR_PT_DOUBLE, .offset = REF(target_error), .min = 0, .max = 1,
     .flags = HI_X, .def = 0, .unit = "",
     .doc = "0 = off; else refine until the relative standard error is below this"},
    {.name = "transmittance_cutoff", .type = GR_PT_DOUBLE, .offset = REF(transmittance_cutoff),
     .min = 0, .max = 1, .flags = LO_X | HI_X, .def = 1e-4, .unit = "",
     .doc = "camera rays stop where the light they can still gather falls below this fraction (camera and sun paths' attenuation)"},
    {.name = "max_distance_m", .type = GR_PT_DOUBLE, .offset = REF(max_distance_m), .min = 0,
     .max = 1e6, .flags = LO_X, .def = 1000, .unit = "m",
     .doc = "camera rays stop here at the latest (clear water)"},
    {.name = "patch_radius_m", .type = GR_PT_DOUBLE, .offset = REF(patch_radius_m), .min = 0,
     .max = 1e5, .flags = LO_X, .def = 60, .unit = "m",
     .doc = "half size of the tessellated surface patch around the camera; beyond it the waves' mean sunlight"},
    {.name = "sun_disc", .type = GR_PT_ENUM, .offset = REF(sun_disc), .min = 0, .max = 1,
     .def = GR_SUN_DISC_CONVOLVE, .enum_names = sun_disc_names, .unit = "",
     .doc = "sun-disc average: analytic convolution of each beam's footprint, or one sampled direction per pass"},
    {.name = "bias_probe", .type = GR_PT_BOOL, .offset = REF(bias_probe), .min = 0, .max = 1, .def = 1,
     .unit = "", .doc = "estimate the surface-tessellation bias: every 5th pixel re-rendered at surface_res and surface_res/2 (Richardson), about 5 % more time"},
    {.name = "adaptive_steps", .type = GR_PT_BOOL, .offset = REF(adaptive_steps), .min = 0, .max = 1, .def = 1,
     .unit = "", .doc = "march steps per pixel from a pilot ray (between min_steps and steps) to meet step_error; false: steps everywhere"},
    {.name = "step_error", .type = GR_PT_DOUBLE, .offset = REF(step_error), .min = 0, .max = 1, .flags = LO_X | HI_X,
     .def = 0.012, .unit = "",
     .doc = "adaptive steps: target standard error of the step noise, relative to max(pixel, image mean)"},
    {.name = "min_steps", .type = GR_PT_INT, .offset = REF(min_steps), .min = 1, .max = 1 << 16, .def = 16,
     .unit = "", .doc = "adaptive steps: the fewest march steps a pixel takes (16: two strata in each of the eight segments along the ray, so that the batch means are near enough to normal for honest error bars)"},
    {.name = "pilot_steps", .type = GR_PT_INT, .offset = REF(pilot_steps), .min = 2, .max = 1 << 16, .def = 64,
     .unit = "", .doc = "adaptive steps: march steps of the pilot ray per pixel that sets the steps"},
    {.name = "steps_along_ray", .type = GR_PT_BOOL, .offset = REF(steps_along_ray), .min = 0, .max = 1, .def = 1,
     .unit = "", .doc = "adaptive steps: allot a pixel's steps along its ray where the pilot saw the step noise (8 segments, each at least one step and a quarter of its even share); false: evenly"},
    {.name = "refine_factor", .type = GR_PT_INT, .offset = REF(refine_factor), .min = 1, .max = 16, .def = 3,
     .unit = "", .doc = "local refinement: the camera rays that run along the refracted sun's beams look up a tessellation with the surface cells they meet split into F x F (1 = off)"},
    {.name = "refine_angle_deg", .type = GR_PT_DOUBLE, .offset = REF(refine_angle_deg), .min = 0, .max = 30, .def = 12,
     .unit = "deg", .doc = "local refinement: the camera rays within this angle of the refracted sun direction (either way) look up the refined tessellation; the others the plain grid"},
    {.name = "near_cells_per_wavelength", .type = GR_PT_DOUBLE, .offset = REF(near_cells_per_wavelength), .min = 0, .max = 64,
     .def = 6.4, .unit = "",
     .doc = "refinement near the camera: where the plain grid has fewer cells than this across the shortest wave (a wide lit region: a level or deep view; 6.4: where the default scene's 0.6 % bias at 8.2 would pass 1 %), the cells near the camera are split by the smallest odd factor that brings them to it (0 = off)"},
    {.name = "near_radius_cells", .type = GR_PT_DOUBLE, .offset = REF(near_radius_cells), .min = 0, .max = 4096, .flags = LO_X,
     .def = 24, .unit = "cells", .doc = "refinement near the camera: the cells within this many plain cells of the camera's position sheared along the refracted sun"},
    {.name = "near_max_factor", .type = GR_PT_INT, .offset = REF(near_max_factor), .min = 1, .max = 15, .def = 3,
     .unit = "", .doc = "refinement near the camera: the largest split factor (odd: an even value counts as the odd one below it; the cost grows with its square)"},
};
#undef REF

const gr_param_table gr_reference_param_table = {
    "reference", reference_params, sizeof reference_params / sizeof reference_params[0]};
