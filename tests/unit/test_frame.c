/* gr_frame_init (src/realtime/frame.c) against independent values:
 * - a world point on the scene's documented pixel ray (scene.h: forward + ndc_x tan(fov/2)
 *   aspect right + ndc_y tan(fov/2) up) projects through view_proj to that pixel's centre,
 *   with clip w = its distance along forward and NDC z in (-1, 1);
 * - inv_view_proj inverts view_proj; the view matrix is a rigid motion taking the eye to 0;
 * - the refracted sun from Snell's law written with angles (sin t = sin i / n in the sun's
 *   azimuth plane), the flat transmittance at the zenith (1 - ((n-1)/(n+1))^2), Snell's window
 *   asin(1/n);
 * - the refracted sun's uv: the pixel ray through that uv (scene.h formula) is parallel to
 *   to_refr_sun; behind the camera w < 0 and the NDC points to the side the sun lies on;
 * - seed 000's wave packing: the seed's CalculateWaterNormal transcribed from the listing
 *   and fed waves_seed gives the normal of core/gerstner (seed eq. 5.5.8 in double). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "core/gerstner.h"
#include "realtime/frame.h"

#define PI 3.14159265358979323846

static gr_scene *load(const char *json, const char *const *sets, int n)
{
    gr_error err;
    gr_scene *s = malloc(sizeof *s);
    if (!s || gr_scene_load_string(json, "test", sets, n, s, &err) != GR_OK) {
        fprintf(stderr, "scene: %s\n", s ? err.msg : "oom");
        exit(1);
    }
    return s;
}

static const char *json =
    "{\"name\": \"frame\", \"water\": {\"rest_height_m\": 1.5, \"time_s\": 3.7, \"waves\": ["
    "{\"amplitude_m\": 0.3, \"wavelength_m\": 12, \"direction_deg\": 40, \"phase_rad\": 0.4},"
    "{\"amplitude_m\": 0.1, \"wavelength_m\": 5, \"direction_deg\": -70, \"phase_rad\": 2.0},"
    "{\"amplitude_m\": 0.05, \"wavelength_m\": 3, \"direction_deg\": 130, \"phase_rad\": 5.0},"
    "{\"amplitude_m\": 0.04, \"wavelength_m\": 2, \"direction_deg\": 10, \"phase_rad\": 1.0},"
    "{\"amplitude_m\": 0.02, \"wavelength_m\": 1.3, \"direction_deg\": 200, \"phase_rad\": 3.0}]},"
    "\"sun\": {\"elevation_deg\": 55, \"azimuth_deg\": 35},"
    "\"medium\": {\"absorption_per_m\": [0.3, 0.05, 0.02], \"scattering_per_m\": 0.04, \"g\": 0.8, \"ior\": 1.333},"
    "\"camera\": {\"position_m\": [12.5, -6, -40.25], \"yaw_deg\": 20, \"pitch_deg\": 50, \"fov_deg\": 55,"
    "\"width\": 320, \"height\": 200},"
    "\"seabed\": {\"depth_m\": 30}}";

/* The scene's pixel ray (scene.h), not normalized. */
static void pixel_ray(const gr_scene *s, double px, double py, double d[3])
{
    const gr_camera *c = &s->camera;
    double t = tan(0.5 * c->fov_deg * PI / 180.0), a = (double)c->width / c->height;
    double sx = (2.0 * (px + 0.5) / c->width - 1.0) * t * a, sy = (2.0 * (py + 0.5) / c->height - 1.0) * t;
    for (int k = 0; k < 3; k++) d[k] = c->forward[k] + sx * c->right[k] - sy * c->up[k];
}

/* Seed 000's CalculateWaterNormal, transcribed (float, 4 lanes per group, the seed's
 * phase = kx x0 + ky y0 - wt; its y0 is our z0). Returns normalize(cross(t2, t1)). */
static void seed_normal(const gr_frame *f, float x0, float z0, float n[3])
{
    float t1[3] = {1, 0, 0}, t2[3] = {0, 0, 1};
    for (int i = 0, j = 0; i < f->n_wave_groups; i++, j += 5) {
        for (int l = 0; l < 4; l++) {
            float kx = f->waves_seed[j][l], ky = f->waves_seed[j + 1][l], Ainvk = f->waves_seed[j + 2][l];
            float A = f->waves_seed[j + 3][l], wt = f->waves_seed[j + 4][l];
            float phase = kx * x0 + ky * z0 - wt, sinp = sinf(phase), cosp = cosf(phase);
            t1[0] -= Ainvk * kx * cosp * kx;
            t1[2] -= Ainvk * ky * cosp * kx;
            t1[1] += A * (-sinp) * kx;
            t2[0] -= Ainvk * kx * cosp * ky;
            t2[2] -= Ainvk * ky * cosp * ky;
            t2[1] += A * (-sinp) * ky;
        }
    }
    float c[3] = {t2[1] * t1[2] - t2[2] * t1[1], t2[2] * t1[0] - t2[0] * t1[2], t2[0] * t1[1] - t2[1] * t1[0]};
    float l = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    for (int k = 0; k < 3; k++) n[k] = c[k] / l;
}

int main(void)
{
    gr_scene *s = load(json, NULL, 0);
    gr_frame f;
    gr_frame_init(s, &f);
    const double n = 1.333;

    /* Pixel rays project back to their pixel centres. */
    const double pix[5][2] = {{0, 0}, {319, 199}, {160, 100}, {17.25, 150.5}, {300, 3}};
    for (int i = 0; i < 5; i++) {
        double d[3], p[4], clip[4];
        pixel_ray(s, pix[i][0], pix[i][1], d);
        const double dist = 7.3; /* along forward: the ray is forward + lateral terms */
        for (int k = 0; k < 3; k++) p[k] = s->camera.position_m[k] + dist * d[k];
        p[3] = 1.0;
        gr_mat4_apply(f.view_proj, p, clip);
        double ndc_x = 2.0 * (pix[i][0] + 0.5) / 320 - 1.0, ndc_y = 1.0 - 2.0 * (pix[i][1] + 0.5) / 200;
        CHECK_NEAR(clip[0] / clip[3], ndc_x, 1e-9);
        CHECK_NEAR(clip[1] / clip[3], ndc_y, 1e-9);
        CHECK_NEAR(clip[3], dist, 1e-9);
        CHECK(fabs(clip[2] / clip[3]) < 1.0);
        /* and back through the inverse */
        double back[4];
        gr_mat4_apply(f.inv_view_proj, clip, back);
        for (int k = 0; k < 3; k++) CHECK_NEAR(back[k] / back[3], p[k], 1e-6);
    }
    /* View is rigid: the eye maps to the origin, forward to -z. */
    double e[4] = {s->camera.position_m[0], s->camera.position_m[1], s->camera.position_m[2], 1}, v[4];
    gr_mat4_apply(f.view, e, v);
    for (int k = 0; k < 3; k++) CHECK_NEAR(v[k], 0.0, 1e-12);
    double fw[4] = {s->camera.forward[0], s->camera.forward[1], s->camera.forward[2], 0};
    gr_mat4_apply(f.view, fw, v);
    CHECK_NEAR(v[0], 0, 1e-12);
    CHECK_NEAR(v[1], 0, 1e-12);
    CHECK_NEAR(v[2], -1, 1e-12);
    /* view_proj_rot = view_proj minus the translation: same result on directions */
    double vpr[16], a4[4], b4[4];
    gr_frame_view_proj_rot(&f, vpr);
    gr_mat4_apply(vpr, fw, a4);
    gr_mat4_apply(f.view_proj, fw, b4);
    for (int k = 0; k < 4; k++) CHECK_NEAR(a4[k], b4[k], 1e-12);

    /* Refracted sun by Snell's law with angles. */
    double zi = (90.0 - 55.0) * PI / 180.0, zt = asin(sin(zi) / n), az = 35.0 * PI / 180.0;
    double want[3] = {sin(zt) * sin(az), cos(zt), sin(zt) * cos(az)};
    for (int k = 0; k < 3; k++) {
        CHECK_NEAR(f.to_refr_sun[k], want[k], 1e-12);
        CHECK_NEAR(f.refr_dir[k], -want[k], 1e-12);
    }
    CHECK_NEAR(f.snell_half_angle_rad, asin(1.0 / n), 1e-15);
    CHECK_NEAR(f.snell_half_angle_rad * 180.0 / PI, 48.6, 0.05);

    /* The refracted sun's uv: the pixel ray through it is parallel to to_refr_sun. */
    CHECK(f.sun_clip_w > 0);
    {
        double px = f.sun_uv[0] * 320 - 0.5, py = (1.0 - f.sun_uv[1]) * 200 - 0.5, d[3];
        pixel_ray(s, px, py, d);
        double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        double dot = (d[0] * want[0] + d[1] * want[1] + d[2] * want[2]) / l;
        CHECK_NEAR(dot, 1.0, 1e-12);
        CHECK_NEAR(f.sun_cos_view, s->camera.forward[0] * want[0] + s->camera.forward[1] * want[1] +
                                       s->camera.forward[2] * want[2], 1e-12);
        CHECK(f.sun_uv[0] > 0 && f.sun_uv[0] < 1 && f.sun_uv[1] > 0 && f.sun_uv[1] < 1);
    }
    /* Seed packing vs core/gerstner's normal at several rest points. */
    CHECK(f.n_waves == 5 && f.n_wave_groups == 2);
    for (int i = 0; i < 6; i++) {
        double x0 = -13.0 + 7.7 * i, z0 = 4.0 - 3.1 * i;
        gr_dvec3 nn;
        gr_gerstner_frame(&s->water, x0, z0, s->water.time_s, NULL, NULL, &nn);
        float sn[3];
        seed_normal(&f, (float)x0, (float)z0, sn);
        CHECK_NEAR(sn[0], nn.x, 2e-4);
        CHECK_NEAR(sn[1], nn.y, 2e-4);
        CHECK_NEAR(sn[2], nn.z, 2e-4);
        /* the per-wave form too: phase = k dir . X0 - omega t + phase0 */
        double hy = 0.0;
        for (int w = 0; w < f.n_waves; w++)
            hy += f.waves_b[w][0] * cos(f.waves_a[w][2] * (f.waves_a[w][0] * x0 + f.waves_a[w][1] * z0) -
                                        f.waves_a[w][3] * s->water.time_s + f.waves_b[w][1]);
        gr_dvec3 P = gr_gerstner_position(&s->water, x0, z0, s->water.time_s);
        CHECK_NEAR(1.5 + hy, P.y, 1e-4);
    }
    CHECK_NEAR(f.rest_height_m, 1.5, 0);
    CHECK_NEAR(f.seabed_y, 1.5 - 30.0, 1e-12);
    CHECK_NEAR(f.extinction[0], 0.34, 1e-12);
    free(s);

    /* Sun at the zenith: T = 1 - R0. Camera looking down: the refracted sun is behind it. */
    const char *sets[] = {"sun.elevation_deg=90", "camera.pitch_deg=-60", "camera.yaw_deg=200"};
    s = load(json, sets, 3);
    gr_frame_init(s, &f);
    double r0 = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
    CHECK_NEAR(f.transmittance_flat, 1.0 - r0, 1e-12);
    CHECK_NEAR(f.to_refr_sun[1], 1.0, 1e-12);
    CHECK(f.sun_clip_w < 0);
    CHECK_NEAR(f.sun_clip_w, f.sun_cos_view, 1e-12);
    /* not mirrored: NDC y has the sign of the sun's component along the camera's up */
    CHECK(f.sun_ndc[1] * s->camera.up[1] > 0);
    free(s);
    /* Tilted camera with the sun to its right and behind: NDC x points right. */
    const char *sets2[] = {"camera.yaw_deg=-60", "camera.pitch_deg=-10"};
    s = load(json, sets2, 2);
    gr_frame_init(s, &f);
    double side = f.to_refr_sun[0] * s->camera.right[0] + f.to_refr_sun[1] * s->camera.right[1] +
                  f.to_refr_sun[2] * s->camera.right[2];
    printf("behind: w %.3f ndc %.3f %.3f side %.3f\n", f.sun_clip_w, f.sun_ndc[0], f.sun_ndc[1], side);
    CHECK(f.sun_ndc[0] * side > 0);
    free(s);
    CHECK_DONE();
}
