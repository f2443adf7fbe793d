/* Descriptor tables of the two renderers' settings (settings.h). One row per field:
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
    {.name = "steps", .type = GR_PT_INT, .offset = REF(steps), .min = 1, .max = 1 << 16, .def = 64,
     .unit = "", .doc = "stratified, jittered march steps along each camera ray"},
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
     .min = 0, .max = 1, .flags = LO_X | HI_X, .def = 1e-3, .unit = "",
     .doc = "camera rays stop where the transmittance exp(-tau) falls below this"},
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
};
#undef REF

static const char *const target_format_names[] = {"rgba8", "rgba16f", NULL};

#define SH(field) offsetof(gr_shafts_settings, field)
static const gr_param shafts_params[] = {
    {.name = "N", .type = GR_PT_INT, .offset = SH(N), .min = 2, .max = 1024, .def = 11, .unit = "",
     .doc = "grid vertices along each side of the shaft grid (seed eq. 5.5.6); (N-1)^2 shafts"},
    {.name = "K", .type = GR_PT_DOUBLE, .offset = SH(K), .min = 0, .max = 10, .flags = LO_X,
     .def = 0.8, .unit = "", .doc = "spacing adjustment factor K of seed eq. 5.5.6"},
    {.name = "shaft_length_m", .type = GR_PT_DOUBLE, .offset = SH(shaft_length_m), .min = 0,
     .max = 10000, .flags = LO_X, .def = 30, .unit = "m",
     .doc = "extrusion length of the bottom vertices along the refracted sun ray"},
    {.name = "shaft_width", .type = GR_PT_DOUBLE, .offset = SH(shaft_width), .min = 0, .max = 1,
     .flags = LO_X, .def = 1.0, .unit = "", .doc = "shaft width as a fraction of the grid cell"},
    {.name = "caps", .type = GR_PT_BOOL, .offset = SH(caps), .min = 0, .max = 1, .def = 1, .unit = "",
     .doc = "draw the top and bottom faces of each parallelepiped"},
    {.name = "target_scale", .type = GR_PT_DOUBLE, .offset = SH(target_scale), .min = 0, .max = 1,
     .flags = LO_X, .def = 0.5, .unit = "",
     .doc = "shaft render target size / frame size, per axis (0.5 = a quarter of the area)"},
    {.name = "target_format", .type = GR_PT_ENUM, .offset = SH(target_format), .min = 0, .max = 1,
     .def = GR_TARGET_RGBA8, .enum_names = target_format_names, .unit = "",
     .doc = "shaft render target format (the seed uses 8 bits per channel)"},
    {.name = "extinction", .type = GR_PT_RGB, .offset = SH(extinction), .min = 0, .max = 10000,
     .flags = FROM, .def = NAN, .unit = "1/m", .scene_source = "medium.extinction",
     .doc = "extinction c of seed eq. 5.5.3; default: the medium's sigma_t"},
    {.name = "g", .type = GR_PT_DOUBLE, .offset = SH(g), .min = -1, .max = 1,
     .flags = LO_X | HI_X | FROM, .def = NAN, .unit = "", .scene_source = "medium.g",
     .doc = "HG eccentricity of the final pass (seed eq. 5.5.4); default: the medium's g"},
    {.name = "bias", .type = GR_PT_DOUBLE, .offset = SH(bias), .min = 0, .max = 10, .def = 0.15,
     .unit = "", .doc = "constant added to the shaft intensity before the phase (seed, second pass)"},
    {.name = "intensity", .type = GR_PT_RGB, .offset = SH(intensity), .min = 0, .max = 1e6, .def = 1,
     .unit = "", .doc = "user factor on the shaft intensity in the second pass"},
    {.name = "shadow_map_size", .type = GR_PT_INT, .offset = SH(shadow_map_size), .min = 16,
     .max = 16384, .def = 1024, .unit = "texels", .doc = "shadow map resolution per side"},
    {.name = "shadow_bias", .type = GR_PT_DOUBLE, .offset = SH(shadow_bias), .min = 0, .max = 100,
     .def = 0.05, .unit = "m", .doc = "depth bias of the shadow comparison"},
};
#undef SH

const gr_param_table gr_reference_param_table = {
    "reference", reference_params, sizeof reference_params / sizeof reference_params[0]};
const gr_param_table gr_shafts_param_table = {
    "shafts", shafts_params, sizeof shafts_params / sizeof shafts_params[0]};
