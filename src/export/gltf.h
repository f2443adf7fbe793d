/* glTF 2.0 export of a scene for the engines users build in (docs/engines.md): the displaced
 * Gerstner water surface at the scene's time as a mesh with normals (optionally the animation
 * as morph targets), the camera, the sun as a KHR_lights_punctual directional light, the
 * occluders and the seabed as meshes, and under `extras` everything a shader needs that glTF
 * has no field for (wave constants, medium, g, ior, the sun's angular diameter, units, axes).
 * JSON through cJSON, the binary buffer written here; `.gltf` (+ `.bin`) or `.glb`. */
#ifndef GR_EXPORT_GLTF_H
#define GR_EXPORT_GLTF_H

#include <stddef.h>

#include "scene/scene.h"

#define GR_GLTF_MAX_FRAMES 1000
#define GR_GLTF_LM_PER_W 683.0 /* luminous efficacy for W/m^2 -> lux in the KHR light (docs/engines.md) */

typedef struct gr_gltf_options {
    int grid_cells;        /* water mesh cells per side (0: 512) */
    double half_size_m;    /* half side of the square water patch at rest (0: 32 m) */
    int n_frames;          /* 0: no animation; else morph targets at frame_t0 + i frame_dt */
    double frame_t0, frame_dt; /* water times of the frames (s) */
} gr_gltf_options;

/* Parses "A:B:S" (water times in seconds: first, last, step; A <= B, S > 0) into t0, dt and the
 * frame count floor((B - A) / S) + 1 (at most GR_GLTF_MAX_FRAMES). GR_E_USAGE naming `flag`
 * and the reason otherwise. */
gr_status gr_gltf_parse_frames(const char *text, const char *flag, gr_gltf_options *o, gr_error *err);

/* 1 if path ends in .gltf, 2 if in .glb (any case), 0 otherwise. */
int gr_gltf_kind(const char *path);

/* The buffer a .gltf at path names, written beside it: PATH-without-extension.bin into buf.
 * 1 when path is a .gltf (and buf large enough), 0 otherwise (a .glb holds its buffer). */
int gr_gltf_bin_path(const char *path, char *buf, size_t n);

/* Writes the scene to path (.gltf: also PATH-without-extension.bin beside it; .glb: one file).
 * Files are written under temporary names and renamed: nothing half-written stays behind;
 * the .bin and the .gltf are renamed only once both are complete, the .gltf last (an
 * interrupted export leaves the old pair or the new one).
 * GR_E_USAGE for an unknown extension or bad options, GR_E_IO when a file cannot be written,
 * GR_E_NOMEM. */
gr_status gr_gltf_write(const gr_scene *s, const gr_gltf_options *o, const char *path, gr_error *err);

#endif
