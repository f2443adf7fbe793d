/* Seed 002's god rays as seed 000 describes them: N planes across the view volume (slabs of
 * view depth), each textured with the caustic pattern (caustics.h) carried along the refracted
 * sun to its depth, attenuated along the sun's and the view path, weighted by the HG phase,
 * shadowed by the occluders' shadow map, blended additively. Output in the ground truth's
 * radiance units. Derivations: docs/volume-techniques.md. */
#ifndef GR_SLICING_H
#define GR_SLICING_H

#include "realtime/technique.h"

typedef enum gr_vol_distribution { GR_VOL_LINEAR = 0, GR_VOL_EXPONENTIAL = 1 } gr_vol_distribution;

typedef struct gr_slicing_settings {
    int slices;             /* planes (32) */
    int distribution;       /* gr_vol_distribution */
    double near_m;          /* exponential: first slab boundary (m of view depth) */
    int texture_size;       /* caustic texture side */
    int grid;               /* water grid cells per patch side */
    double patch_m;         /* caustic patch side (m) */
    int caustic_depths;     /* planes in the caustic stack */
    double caustic_first_m, caustic_last_m; /* stack depths, geometric between these */
    double extinction[3];   /* sigma_t on both paths; default: the medium's */
    double g;               /* HG asymmetry; default: the medium's */
    int sun_disc;           /* blur the caustic planes by the sun's disc */
    double intensity[3];    /* gain on the physical result (1) */
    int shadow_map_size;
    double shadow_extent_m; /* half side of the shadow map's square around the eye */
} gr_slicing_settings;

extern const gr_technique_class gr_slicing_class;

#endif
