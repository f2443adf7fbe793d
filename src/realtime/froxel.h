/* Froxel volumetric fog (Wronski 2014; Hillaire 2015), as in Frostbite, Unreal and Unity HDRP,
 * lit by the refracted sun with seed 002's caustic texture as its cookie: a view-frustum grid
 * (default 160 x 90 x 64, exponential depth slices); a compute pass writes each froxel's
 * in-scattering (sigma_s x HG phase x irradiance x caustic cookie x shadow x extinction along
 * the sun's path); a second integrates front to back with Hillaire's energy-conserving step;
 * each pixel reads the result at its ray's end. Derivations: docs/volume-techniques.md. */
#ifndef GR_FROXEL_H
#define GR_FROXEL_H

#include "realtime/volume.h"
#include "realtime/technique.h"

typedef struct gr_froxel_settings {
    int grid_x, grid_y, grid_z;  /* froxels across, up, in depth */
    int distribution;            /* gr_vol_distribution (slicing.h): 0 linear, 1 exponential */
    double near_m;               /* exponential: the first depth slice's far face (m) */
    int jitter;                  /* sample each froxel at a per-froxel noise depth, not its middle */
    int phase_per_pixel;         /* HG phase per pixel (exact for one directional light), not per froxel */
    gr_vol_settings vol;         /* caustic stack, extinction, g, sun disc, intensity, shadow map */
} gr_froxel_settings;

extern const gr_technique_class gr_froxel_class;

#endif
