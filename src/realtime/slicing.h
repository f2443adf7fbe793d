/* Seed 002's god rays as seed 000 describes them: N planes across the view volume (slabs of
 * view depth), each textured with the caustic pattern (caustics.h) carried along the refracted
 * sun to its depth, attenuated along the sun's and the view path, weighted by the HG phase,
 * shadowed by the occluders' shadow map, blended additively. Output in the ground truth's
 * radiance units. Derivations: docs/volume-techniques.md. */
#ifndef GR_SLICING_H
#define GR_SLICING_H

#include "realtime/volume.h"
#include "realtime/technique.h"

typedef enum gr_vol_distribution { GR_VOL_LINEAR = 0, GR_VOL_EXPONENTIAL = 1 } gr_vol_distribution;

typedef struct gr_slicing_settings {
    int slices;             /* planes (32) */
    int distribution;       /* gr_vol_distribution */
    double near_m;          /* exponential: first slab boundary (m of view depth) */
    double target_scale;    /* slices' target size / frame size per axis (1; < 1: upsampled) */
    gr_vol_settings vol;    /* caustic stack, extinction, g, sun disc, intensity, shadow map */
} gr_slicing_settings;

extern const gr_technique_class gr_slicing_class;

#endif
