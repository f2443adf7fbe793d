/* Seed 001's light rays after Hu et al. 2010 ("Interactive volume caustics in single-scattering
 * media"): the water surface rendered from the sun into position and normal textures; a
 * geometry shader turns each texel into one line along its refracted sun ray, from the surface
 * to the first occluder (shadow map), the seabed or a maximum length, drawn into the eye's view
 * with additive blending; each fragment adds the single-scattered radiance of the line's flux
 * (attenuation along both paths, HG phase): by default the exact integral of the pixel's ray
 * through the line's beam prism (the texel's footprint around the line), or, as a ribbon of a
 * few pixels, the flux over the ribbon's width and obliquity; either way the sum of the lines
 * converges to the radiance of the ground truth.
 * Derivation: docs/volume-techniques.md, "Light rays". */
#ifndef GR_LIGHT_RAYS_H
#define GR_LIGHT_RAYS_H

#include "realtime/volume.h"
#include "realtime/technique.h"

typedef enum gr_light_rays_footprint {
    GR_LIGHT_RAYS_PRISM = 0,  /* the pixel's ray through the line's beam prism, integrated exactly */
    GR_LIGHT_RAYS_RIBBON = 1  /* a camera-facing ribbon, the radiance of a sheet crossing */
} gr_light_rays_footprint;

typedef struct gr_light_rays_settings {
    int rays;               /* texels per side of the light's view: rays^2 lines (512) */
    int footprint;          /* gr_light_rays_footprint: how a line reaches the pixels (prism) */
    int kernel;             /* the footprint's side in texels (1) */
    double line_width;      /* the ribbon's least width (not used by the prism) */
    double max_length_m;    /* longest line (m) */
    double margin_m;        /* extra border of the light's window around the lit volume (m) */
    gr_vol_settings vol;    /* extinction, g, intensity, shadow map (caustic fields unused) */
} gr_light_rays_settings;

extern const gr_technique_class gr_light_rays_class;

#endif
