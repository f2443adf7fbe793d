/* Settings of the ground-truth renderer, as stored in the scene's "reference" section. Its
 * descriptor table (keys, ranges, defaults, docs) is in settings.c. The real-time
 * techniques' settings are declared by each technique (src/realtime/, e.g. shafts.h) and
 * reach the scene as its sections (scene/sections.h). */
#ifndef GR_SETTINGS_H
#define GR_SETTINGS_H

#include "scene/params.h"

/* Ground-truth integrator (reference/). */
typedef struct gr_reference_settings {
    int spp;                      /* camera samples per pixel (per batch group, see batches) */
    int camera_rays;              /* rays per camera sample, sharing its march steps */
    int antithetic;               /* 1: a batch's passes in pairs whose surface grids are offset by
                                     half a cell (docs/reference.md 2.5, "Antithetic pairs") */
    int steps;                    /* stratified, jittered march steps along each camera ray;
                                     with adaptive_steps the most any pixel takes */
    int surface_res;              /* surface tessellation: cells along each axis of the lit patch */
    int sun_samples;              /* passes per round (grid offsets; sun directions if sampled) */
    int batches;                  /* independent batches for the standard-error estimate */
    unsigned long long seed;      /* RNG seed: same seed, same bytes, any thread count */
    int threads;                  /* 0 = all cores */
    double target_error;          /* 0 = off; else refine until rel. std. error < this */
    double transmittance_cutoff;  /* camera rays stop where the light left to gather falls below this (docs/reference.md 1) */
    double max_distance_m;        /* camera rays stop here at the latest (clear water) */
    double patch_radius_m;        /* half size of the tessellated surface patch around the
                                     camera; beyond it the waves' mean sunlight is used */
    int sun_disc;                 /* gr_sun_disc_mode: how the sun's disc is averaged */
    int bias_probe;               /* 1: estimate the surface-tessellation bias from a pixel
                                     subsample rendered again at half the surface_res */
    int adaptive_steps;           /* 1: steps per pixel from a pilot (docs/reference.md 2.5) */
    double step_error;            /* adaptive steps: the step noise's target, relative to
                                     max(pixel, image mean), after the whole render */
    int min_steps;                /* adaptive steps: the fewest a pixel takes */
    int pilot_steps;              /* adaptive steps: march steps of the pilot rays */
    int steps_along_ray;          /* adaptive steps: allotted along each ray by the pilot's noise
                                     per segment (0: evenly; docs/reference.md 2.5) */
    int refine_factor;            /* surface cells split F x F where camera rays run along the
                                     beams (1 = off; docs/reference.md 2.2) */
    double refine_angle_deg;      /* ...those camera rays: within this angle of the refracted sun */
    double near_cells_per_wavelength; /* refinement near the camera: where the plain grid has fewer
                                     cells across the shortest wave, those near the camera are
                                     split by the smallest odd factor that brings them to it
                                     (0 = off; docs/reference.md 2.2) */
    double near_radius_cells;     /* ...within this many plain cells of the camera (sheared) */
    int near_max_factor;          /* ...by at most this factor (its odd part) */
} gr_reference_settings;

/* reference.sun_disc: the disc average by the analytic convolution of each beam's footprint
 * (default), or by sampling one direction per pass (brute force, for checks). */
typedef enum gr_sun_disc_mode { GR_SUN_DISC_CONVOLVE = 0, GR_SUN_DISC_SAMPLE = 1 } gr_sun_disc_mode;

extern const gr_param_table gr_reference_param_table;

#endif
