/* The settings block the volume techniques share (slicing, froxel, light rays) and its
 * descriptors, without GL: the block `gr_vol_settings`, its descriptor lists GR_VOL_PARAMS_*, the
 * check across its fields and the caustic fields' descriptors, which a user technique's
 * manifest (realtime/usertech_manifest.c, no GL) takes for its "caustics" object. What the
 * volume techniques' renders share is realtime/volume.h. */
#ifndef GR_VOLSETTINGS_H
#define GR_VOLSETTINGS_H

#include <math.h>
#include <stddef.h>

#include "common/status.h"
#include "realtime/caustics.h"
#include "scene/params.h"

/* Settings the volume techniques share: a block (member `vol`) of each one's settings struct,
 * described by the GR_VOL_PARAMS_* descriptor lists below (same keys, ranges and docs in every
 * technique's scene section). The caustic fields are unused by a technique without the
 * caustic texture (light rays), which lists only GR_VOL_PARAMS_MEDIUM and _LIGHT. */
typedef struct gr_vol_settings {
    int texture_size, grid;      /* caustic texture side, water grid cells per patch side */
    double patch_m;              /* caustic patch side (m) */
    int caustic_depths;          /* planes in the caustic stack */
    double caustic_first_m, caustic_last_m; /* stack depths, geometric between these */
    double extinction[3];        /* sigma_t on both paths; default: the medium's */
    double g;                    /* HG asymmetry; default: the medium's */
    int sun_disc;                /* blur the caustic planes by the sun's disc */
    double intensity[3];         /* gain on the physical result (1) */
    int shadow_map_size;
    double shadow_extent_m;      /* half side of the shadow map's square around the eye */
} gr_vol_settings;

/* Descriptors of the shared block inside settings struct T (its member `vol`). */
#define GR_VOL_PARAMS_CAUSTICS(T)                                                                                    \
    {.name = "texture_size", .type = GR_PT_INT, .offset = offsetof(T, vol.texture_size), .min = 8, .max = 4096,      \
     .def = 512, .unit = "texels", .doc = "caustic texture side (rendered at twice this, 2x2 box filtered)"},         \
    {.name = "grid", .type = GR_PT_INT, .offset = offsetof(T, vol.grid), .min = 2, .max = 2048, .def = 256,          \
     .unit = "cells", .doc = "water grid cells per patch side (beam-traced triangles: 2 grid^2 per depth)"},          \
    {.name = "patch_m", .type = GR_PT_DOUBLE, .offset = offsetof(T, vol.patch_m), .min = 0, .max = 1e4,              \
     .flags = GR_PF_MIN_EXCL, .def = 24, .unit = "m", .doc = "caustic patch side: the texture repeats with this period"}, \
    {.name = "caustic_depths", .type = GR_PT_INT, .offset = offsetof(T, vol.caustic_depths), .min = 1,               \
     .max = GR_CAUSTICS_MAX_DEPTHS, .def = 8, .unit = "", .doc = "planes of the caustic stack"},                      \
    {.name = "caustic_first_m", .type = GR_PT_DOUBLE, .offset = offsetof(T, vol.caustic_first_m), .min = 0,          \
     .max = 1e4, .flags = GR_PF_MIN_EXCL, .def = 1, .unit = "m", .doc = "shallowest caustic plane below the rest height"}, \
    {.name = "caustic_last_m", .type = GR_PT_DOUBLE, .offset = offsetof(T, vol.caustic_last_m), .min = 0,            \
     .max = 1e4, .flags = GR_PF_MIN_EXCL, .def = 25, .unit = "m",                                                    \
     .doc = "deepest caustic plane (geometric spacing between)"}
#define GR_VOL_PARAMS_MEDIUM(T)                                                                                      \
    {.name = "extinction", .type = GR_PT_RGB, .offset = offsetof(T, vol.extinction), .min = 0, .max = 1e4,           \
     .flags = GR_PF_FROM_SCENE, .def = NAN, .unit = "1/m", .scene_source = "medium.extinction",                      \
     .doc = "sigma_t along the sun's and the view path; default: the medium's", .tune_lo = 0.5, .tune_hi = 2.0},     \
    {.name = "g", .type = GR_PT_DOUBLE, .offset = offsetof(T, vol.g), .min = -1, .max = 1,                           \
     .flags = GR_PF_MIN_EXCL | GR_PF_MAX_EXCL | GR_PF_FROM_SCENE, .def = NAN, .unit = "", .scene_source = "medium.g", \
     .doc = "HG asymmetry; default: the medium's", .tune_lo = 0.5, .tune_hi = 0.98}
#define GR_VOL_PARAMS_SUN_DISC(T)                                                                                    \
    {.name = "sun_disc", .type = GR_PT_BOOL, .offset = offsetof(T, vol.sun_disc), .min = 0, .max = 1, .def = 1,      \
     .unit = "", .doc = "blur each caustic plane by the sun's disc (the mip level of its blur diameter)"}
#define GR_VOL_PARAMS_LIGHT(T)                                                                                       \
    {.name = "intensity", .type = GR_PT_RGB, .offset = offsetof(T, vol.intensity), .min = 0, .max = 1e9, .def = 1,   \
     .unit = "", .doc = "gain on the physical radiance (1: no fit)", .tune_lo = 0.2, .tune_hi = 5.0},                \
    {.name = "shadow_map_size", .type = GR_PT_INT, .offset = offsetof(T, vol.shadow_map_size), .min = 16,            \
     .max = 8192, .def = 1024, .unit = "texels", .doc = "occluders' shadow map side"},                              \
    {.name = "shadow_extent_m", .type = GR_PT_DOUBLE, .offset = offsetof(T, vol.shadow_extent_m), .min = 0,          \
     .max = 1e5, .flags = GR_PF_MIN_EXCL, .def = 40, .unit = "m",                                                    \
     .doc = "half side of the shadow map's square around the eye"}

/* The descriptors of the block's caustic fields (GR_VOL_PARAMS_CAUSTICS, then
 * GR_VOL_PARAMS_SUN_DISC) with offsets into a gr_vol_settings: the same names, ranges and
 * defaults as every volume technique's section. *n receives their count. */
const gr_param *gr_vol_caustic_descriptors(size_t *n);

/* Checks of the shared block across its settings (`name` is the technique's section):
 * caustic_last_m >= caustic_first_m. The table's ranges are checked by technique.c. */
gr_status gr_vol_check(const char *name, const gr_vol_settings *s, gr_error *err);

#endif
