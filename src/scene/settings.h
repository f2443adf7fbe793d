/* Settings of the two renderers, as stored in the scene's "reference" and "shafts"
 * sections. Their descriptor tables (keys, ranges, defaults, docs) are in settings.c. */
#ifndef GR_SETTINGS_H
#define GR_SETTINGS_H

#include "scene/params.h"

/* Ground-truth integrator (reference/). */
typedef struct gr_reference_settings {
    int spp;                      /* camera samples per pixel (per batch group, see batches) */
    int steps;                    /* stratified, jittered march steps along each camera ray */
    int surface_res;              /* surface tessellation: cells along each axis of the lit patch */
    int sun_samples;              /* passes per round (grid offsets; sun directions if sampled) */
    int batches;                  /* independent batches for the standard-error estimate */
    unsigned long long seed;      /* RNG seed: same seed, same bytes, any thread count */
    int threads;                  /* 0 = all cores */
    double target_error;          /* 0 = off; else refine until rel. std. error < this */
    double transmittance_cutoff;  /* camera rays stop where exp(-tau) falls below this */
    double max_distance_m;        /* camera rays stop here at the latest (clear water) */
    double patch_radius_m;        /* half size of the tessellated surface patch around the
                                     camera; beyond it the waves' mean sunlight is used */
    int sun_disc;                 /* gr_sun_disc_mode: how the sun's disc is averaged */
    int bias_probe;               /* 1: estimate the surface-tessellation bias from a pixel
                                     subsample rendered again at half the surface_res */
} gr_reference_settings;

/* reference.sun_disc: the disc average by the analytic convolution of each beam's footprint
 * (default), or by sampling one direction per pass (brute force, for checks). */
typedef enum gr_sun_disc_mode { GR_SUN_DISC_CONVOLVE = 0, GR_SUN_DISC_SAMPLE = 1 } gr_sun_disc_mode;

typedef enum gr_target_format { GR_TARGET_RGBA8 = 0, GR_TARGET_RGBA16F = 1 } gr_target_format;

/* Real-time shafts (seed 000), every undocumented choice exposed. */
typedef struct gr_shafts_settings {
    int N;                        /* grid vertices along each side (seed eq. 5.5.6) */
    double K;                     /* spacing adjustment factor (eq. 5.5.6), ~0.8 */
    double shaft_length_m;        /* extrusion length of bottom vertices (seed: e.g. 30 m) */
    double shaft_width;           /* shaft width as a fraction of the grid cell */
    int caps;                     /* draw top/bottom faces of each parallelepiped */
    double target_scale;          /* shaft target size / frame size, per axis (0.5 = quarter area) */
    int target_format;            /* gr_target_format */
    double extinction[3];         /* c in eq. 5.5.3 (1/m); default: the medium's sigma_t */
    double g;                     /* HG eccentricity in the final pass; default: the medium's g */
    double bias;                  /* the 0.15 added before the phase (seed, second pass) */
    double intensity[3];          /* user factor in the second pass */
    int shadow_map_size;          /* shadow map resolution (texels per side) */
    double shadow_bias;           /* depth bias of the shadow comparison (m) */
} gr_shafts_settings;

extern const gr_param_table gr_reference_param_table;
extern const gr_param_table gr_shafts_param_table;

#endif
