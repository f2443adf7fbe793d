/* The per-frame values a real-time god-ray shader uses, computed from a scene for an engine
 * programmer to paste in (docs/engines.md): seed 000's packed wave array, the shaft grid's
 * centre P and spacing S, the refracted sun direction, GL view and projection matrices, the
 * medium. Written as JSON (`godrays export --constants`) or as GLSL constants (`--glsl`). */
#ifndef GR_EXPORT_CONSTANTS_H
#define GR_EXPORT_CONSTANTS_H

#include "scene/scene.h"

#include "realtime/frame.h"

#define GR_CONST_ZNEAR_M GR_FRAME_NEAR_M  /* projection planes: src/realtime/frame.h's */
#define GR_CONST_ZFAR_M GR_FRAME_FAR_M

typedef struct gr_shader_constants {
    double time_s;
    int n_waves, n_groups;          /* groups of 4 waves; unused lanes have A = 0 */
    /* seed 000's listing (section 5.5.4): per group 5 vec4 rows kx, kz, A/|k|, A, wt with
     * phase = kx x0 + kz z0 - wt. world: x0, z0 world coordinates, wt = w t - phi0 mod 2 pi;
     * rel_p: x0, z0 relative to P (as src/realtime uses them), wt = w t - phi0 - K.P mod 2 pi */
    float waves_world[GR_MAX_WAVES / 4 * 5][4];
    float waves_rel_p[GR_MAX_WAVES / 4 * 5][4];
    double P[3];                    /* seed eq. 5.5.5a */
    double S;                       /* seed eq. 5.5.6 (shafts.K, shafts.N) */
    double depth_m;                 /* d = rest height - eye y */
    double refr_dir[3];             /* T of seed eq. 5.5.5b: sunlight's direction under flat water */
    double to_refr_sun[3];          /* -T */
    double sun_dir[3], to_sun[3], sun_irradiance[3], sun_angular_radius_rad;
    double transmittance_flat;      /* 1 - exact Fresnel reflectance at the flat surface */
    double eye[3];
    double view[16], proj[16], view_proj[16], inv_view_proj[16]; /* column-major, GL */
    double extinction[3], g, ior;   /* the medium's */
    double shaft_extinction[3], shaft_g, shaft_bias, shaft_intensity[3]; /* shafts settings */
    double hgg[3];                  /* seed's packed HG: (1 - g^2, 1 + g^2, 2 g), shafts.g */
    int shaft_N;
    double shaft_K, shaft_length_m, shaft_width;
    double seabed_y;                /* -1e30 without a seabed */
} gr_shader_constants;

/* Fills c at the scene's time. GR_E_INPUT (naming camera.position_m) when the eye is not
 * under the rest plane: P and S (seed eqs. 5.5.5-5.5.6) need an underwater viewer. */
gr_status gr_constants_compute(const gr_scene *s, gr_shader_constants *c, gr_error *err);

/* Writes the constants as JSON / as GLSL constants to path (temporary file renamed into
 * place). GR_E_IO when it cannot be written. */
gr_status gr_constants_write_json(const gr_scene *s, const gr_shader_constants *c, const char *path, gr_error *err);
gr_status gr_constants_write_glsl(const gr_scene *s, const gr_shader_constants *c, const char *path, gr_error *err);

#endif
