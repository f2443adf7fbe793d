/* Blender Eevee's volumetrics as a technique (issue 32; docs/engines.md section 5): a real
 * engine measured through the export-capture-compare path. Not a GL technique: each instance
 * runs Blender as a child process (`xvfb-run -a blender -b --factory-startup --python
 * data/blender/eevee_godrays.py -- --serve`, started at the first render and kept for the
 * next ones, so sweeps and tuning pay Blender's start and shader compilation once). A render
 * exports the scene with the project's glTF export, writes a request (the refracted sun and
 * its irradiance under the water, the medium's coefficients and g, Eevee's volumetric
 * settings), waits for Blender's two renders (medium on, medium off: the effect layer is their
 * difference, as docs/engines.md tells users to capture) and reads the EXRs back. Its wall
 * time is Blender's render time. The render respects the time limit and Ctrl-C (Blender's
 * process group is stopped).
 *
 * Availability: Blender, and xvfb-run or a $DISPLAY, and the script must be there; otherwise
 * the class says why (gr_technique_available) and every use exits 2 naming what is missing. */
#ifndef GR_EEVEE_H
#define GR_EEVEE_H

#include <stddef.h>

#include "realtime/technique.h"

typedef struct gr_eevee_settings {
    int tile_size;          /* Eevee's volumetric tile size (px): 2, 4, 8 or 16 */
    int samples;            /* volumetric samples (depth slices), 1..256 */
    double distribution;    /* slice distribution, 0 linear .. 1 exponential */
    double start_m, end_m;  /* volumetric start and end (view depth, m) */
    double light_clamp;     /* 0: off */
    int soft_shadows;
    int volumetric_shadows; /* the sun's attenuation through the medium */
    int shadow_samples;     /* its steps, 1..128 */
    int taa_samples;        /* Eevee's render samples (jittered froxels averaged) */
    int cascade_size;       /* the sun's shadow cascade resolution: 512 .. 4096 */
    double density_scale;   /* multiplies scattering and absorption */
    double anisotropy;      /* HG g given to Eevee; default: the medium's */
    double intensity[3];    /* gain on the result (1: none) */
    int water_grid;         /* cells per side of the exported water mesh */
    int difference;         /* render the medium-off frame and subtract it */
} gr_eevee_settings;

extern const gr_technique_class gr_eevee_class;

/* 1 when Blender, a display (xvfb-run or $DISPLAY) and the script are found; else 0 with the
 * reason (naming the missing program and how to get it) in why. Programs: $GODRAYS_BLENDER or
 * `blender` on PATH, `xvfb-run` on PATH; the script: $GODRAYS_EEVEE_SCRIPT or the source
 * tree's data/blender/eevee_godrays.py. */
int gr_eevee_available(char *why, size_t n);

#endif
