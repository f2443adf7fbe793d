/* What the harness knows about one frame, in the form real-time shaders use it: camera
 * matrices (GL convention: column-major, right-handed view, clip z in [-1, 1]), the sun and
 * the refracted sun, the refracted sun's screen position, Snell's window, the Gerstner waves
 * (also packed as in seed 000's listing), the medium, the time. Plain data, no GL: every
 * technique (built-in or a user's manifest) gets the same values, and the uniform names of
 * docs/techniques.md map one to one onto these fields. */
#ifndef GR_FRAME_H
#define GR_FRAME_H

#include "scene/scene.h"

#define GR_FRAME_NEAR_M 0.05   /* projection near plane (m) */
#define GR_FRAME_FAR_M 2000.0  /* projection far plane (m) */

typedef struct gr_frame {
    int width, height;              /* frame size (pixels) */
    double time_s;                  /* water time */
    /* camera */
    double eye[3];                  /* camera position (m) */
    double forward[3], right[3], up[3];
    double fov_y_rad, aspect;
    double view[16], proj[16], view_proj[16], inv_view_proj[16]; /* column-major */
    /* sun */
    double to_sun[3];               /* unit, toward the sun, in air */
    double sun_dir[3];              /* unit, direction sunlight travels in air (= -to_sun) */
    double refr_dir[3];             /* unit, direction sunlight travels under a flat surface */
    double to_refr_sun[3];          /* = -refr_dir: where the refracted sun is seen from below */
    double sun_irradiance[3];       /* E_sun (W/m^2 per channel) */
    double transmittance_flat;      /* 1 - Fresnel reflectance at the flat surface */
    double sun_angular_radius_rad;
    /* where the refracted sun is on screen: NDC (x, y in [-1, 1] when visible), uv in [0, 1]
     * (x right, y UP as in GL textures), and w of its clip position: > 0 in front of the
     * camera, <= 0 behind (no mirrored image then: techniques fade it out) */
    double sun_ndc[2], sun_uv[2], sun_clip_w;
    /* (behind the camera, w <= 0, sun_ndc = clip.xy / max(|w|, 1e-9): the side of the screen
     * toward which the sun lies, NOT a projection; uv follows from it. Clip is computed for
     * the point at infinity (to_refr_sun, 0), so w = sun_cos_view.) */
    double sun_cos_view;            /* dot(forward, to_refr_sun) */
    /* Snell's window: cone half-angle asin(1/ior) about +y seen from below */
    double snell_half_angle_rad;
    /* water */
    double rest_height_m;
    int n_waves;
    /* per wave i: waves_a[i] = (dir.x, dir.z, k, omega), waves_b[i] = (amplitude, phase0, 0, 0)
     * (seed eq. 5.5.7: phase = k dir . X0 - omega t + phase0); unused slots are zero */
    float waves_a[GR_MAX_WAVES][4];
    float waves_b[GR_MAX_WAVES][4];
    /* seed 000's packing (CalculateWaterNormal's `float4 waves[NUM_WAVES/4 * 5]`): group j of
     * 4 waves (lanes) is waves_seed[5j .. 5j+4] = kx, kz, A/|k|, A, wt, with the seed's
     * phase = kx x0 + kz z0 - wt, i.e. wt = omega t - phase0 folded into [0, 2 pi) in double
     * (the seed's comment says "wt + phi0": a sign slip, docs/radial-blur.md). Lanes past
     * n_waves are zero (A = 0: no contribution). */
    int n_wave_groups;              /* ceil(n_waves / 4) */
    float waves_seed[GR_MAX_WAVES / 4 * 5][4];
    /* medium */
    double absorption[3], scattering[3], extinction[3];
    double g, ior;
    double seabed_y;                /* y of the seabed plane; -inf-like (-1e30) when none */
} gr_frame;

/* Fills f from the scene at scene->water.time_s. Never fails for a validated scene. */
void gr_frame_init(const gr_scene *scene, gr_frame *f);
/* Same matrices as float (for glUniformMatrix4fv). */
void gr_frame_matf(const double m[16], float out[16]);

/* Column-major 4x4 helpers (m[col * 4 + row], as GL stores them). */
void gr_mat4_mul(const double a[16], const double b[16], double out[16]); /* out = a b; may alias */
int gr_mat4_inverse(const double m[16], double out[16]);                  /* -1 if singular */
/* out = m (x, y, z, w) */
void gr_mat4_apply(const double m[16], const double in[4], double out[4]);
/* The view-projection without the eye translation (world directions / eye-relative
 * positions -> clip): what shaders need for geometry far from the origin in float. */
void gr_frame_view_proj_rot(const gr_frame *f, double out[16]);

#endif
