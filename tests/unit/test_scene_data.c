/* The shipped scenes have the properties docs/scene-format.md claims, checked against
 * independent evaluations: Snell's law for the refracted sun, a direct pinhole projection
 * for what is in view, eq. 5.5.7 summed here for the translated far_offset surface. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene/scene.h"

static const double PI = 3.14159265358979323846;

static gr_scene *load(const char *rel)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[1024];
    gr_error err;
    snprintf(path, sizeof path, "%s/data/scenes/%s", src ? src : GR_SOURCE_DIR, rel);
    gr_scene *s = calloc(1, sizeof *s);
    gr_status st = gr_scene_load_file(path, NULL, 0, s, &err);
    CHECK_MSG(st == GR_OK, "%s", err.msg);
    return s;
}

/* -T: the direction back up along the refracted sun ray, from Snell's law with angles. */
static void minus_T(const gr_scene *s, double out[3])
{
    double ti = (90.0 - s->sun.elevation_deg) * PI / 180.0;
    double tt = asin(sin(ti) / s->medium.ior);
    double az = s->sun.azimuth_deg * PI / 180.0;
    out[0] = sin(tt) * sin(az);
    out[1] = cos(tt);
    out[2] = sin(tt) * cos(az);
}

static double angle_deg(const double *a, const double *b)
{
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c = d / (la * lb);
    return acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c) * 180.0 / PI;
}

/* Pixel of a world point by intersecting the ray with the image plane at distance 1. */
static int in_view(const gr_scene *s, const double *p)
{
    const gr_camera *c = &s->camera;
    double d[3] = {p[0] - c->position_m[0], p[1] - c->position_m[1], p[2] - c->position_m[2]};
    double z = d[0] * c->forward[0] + d[1] * c->forward[1] + d[2] * c->forward[2];
    if (z <= 0.0) return 0;
    double t = tan(c->fov_deg * PI / 360.0), aspect = (double)c->width / c->height;
    double x = (d[0] * c->right[0] + d[1] * c->right[1] + d[2] * c->right[2]) / z / (t * aspect);
    double y = (d[0] * c->up[0] + d[1] * c->up[1] + d[2] * c->up[2]) / z / t;
    return fabs(x) < 1.0 && fabs(y) < 1.0;
}

static double steepness(const gr_scene *s)
{
    double sum = 0.0;
    for (int i = 0; i < s->water.n_waves; i++) sum += s->water.waves[i].amplitude_m * 2.0 * PI / s->water.waves[i].wavelength_m;
    return sum;
}

static void test_default(void)
{
    gr_scene *s = load("default.json");
    CHECK(s->water.n_waves == 8);
    for (int i = 0; i < s->water.n_waves; i++)
        CHECK(s->water.waves[i].wavelength_m >= 1.0 && s->water.waves[i].wavelength_m <= 12.0);
    double st = steepness(s);
    CHECK_MSG(st >= 0.3 && st <= 0.5, "steepness %g", st);
    CHECK(s->sun.elevation_deg >= 55.0 && s->sun.elevation_deg <= 65.0);
    CHECK_NEAR(s->water.rest_height_m - s->camera.position_m[1], 8.0, 1.0);
    double mt[3];
    minus_T(s, mt);
    double a = angle_deg(s->camera.forward, mt);
    CHECK_MSG(a < 15.0, "camera looks %g deg away from the refracted sun", a);
    /* the refracted sun itself is in the image */
    double sunpt[3] = {s->camera.position_m[0] + 100 * mt[0], s->camera.position_m[1] + 100 * mt[1],
                       s->camera.position_m[2] + 100 * mt[2]};
    CHECK(in_view(s, sunpt));
    CHECK(s->has_seabed && s->seabed_depth_m >= 20.0 && s->seabed_depth_m <= 30.0);
    CHECK(s->camera.width == 640 && s->camera.height == 360);
    int pillar = 0, rock = 0;
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *o = &s->occluders[i];
        if (o->type == GR_OCC_BOX && !strcmp(o->name, "pillar")) {
            pillar = 1;
            double top = o->center_m[1] + 0.5 * o->size_m[1], bottom = o->center_m[1] - 0.5 * o->size_m[1];
            CHECK_NEAR(top, s->water.rest_height_m - 2.0, 0.5);
            CHECK_NEAR(bottom, s->water.rest_height_m - s->seabed_depth_m, 1e-9);
            CHECK(o->size_m[1] > 5.0 * o->size_m[0]);
            double p[3] = {o->center_m[0], top, o->center_m[2]};
            CHECK_MSG(in_view(s, p), "pillar top not in view");
        }
        if (o->type == GR_OCC_SPHERE && !strcmp(o->name, "rock")) {
            rock = 1;
            CHECK_MSG(in_view(s, o->center_m), "rock not in view");
            CHECK(o->center_m[1] + o->radius_m < s->water.rest_height_m - 0.5);
        }
    }
    CHECK(pillar && rock);
    free(s);
}

static void test_others(void)
{
    gr_scene *s = load("flat.json");
    CHECK(s->water.n_waves == 0 && s->n_occluders == 0);
    free(s);
    s = load("low_sun.json");
    CHECK(s->sun.elevation_deg >= 10.0 && s->sun.elevation_deg <= 20.0);
    free(s);
    s = load("murky_coastal.json");
    CHECK(s->medium.scattering[1] > 0.2 && s->medium.absorption[1] > 0.1);
    free(s);
}

static void test_hard(void)
{
    const char *names[] = {"sun_1deg", "sun_90deg", "look_at_sun", "g_099", "sigma_tiny", "sigma_huge",
                           "waves_near_loop", "camera_1mm", "far_offset"};
    char rel[128];
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        snprintf(rel, sizeof rel, "hard/%s.json", names[i]);
        gr_scene *s = load(rel);
        CHECK_MSG(s->camera.width <= 320 && s->camera.height <= 180, "%s is not small", names[i]);
        free(s);
    }
    gr_scene *s = load("hard/sun_1deg.json");
    CHECK(s->sun.elevation_deg == 1.0);
    free(s);
    s = load("hard/sun_90deg.json");
    CHECK(s->sun.elevation_deg == 90.0);
    free(s);
    s = load("hard/look_at_sun.json");
    double mt[3];
    minus_T(s, mt);
    CHECK_MSG(angle_deg(s->camera.forward, mt) < 1e-6, "look_at_sun is %g deg off -T", angle_deg(s->camera.forward, mt));
    free(s);
    s = load("hard/g_099.json");
    CHECK(s->medium.g == 0.99);
    free(s);
    s = load("hard/sigma_tiny.json");
    for (int k = 0; k < 3; k++) CHECK_REL(s->medium.extinction[k], 1e-4, 1e-12);
    free(s);
    s = load("hard/sigma_huge.json");
    for (int k = 0; k < 3; k++) CHECK_REL(s->medium.extinction[k], 20.0, 1e-12);
    free(s);
    s = load("hard/waves_near_loop.json");
    CHECK_MSG(fabs(steepness(s) - 0.97) < 0.01, "steepness %g", steepness(s));
    free(s);
    s = load("hard/camera_1mm.json");
    CHECK(s->water.n_waves == 0);
    CHECK_NEAR(s->water.rest_height_m - s->camera.position_m[1], 1e-3, 1e-12);
    free(s);
}

/* far_offset is the default scene translated by o = (1e5, 0, 1e5): same camera view and
 * occluders relative to the camera, and the same surface (eq. 5.5.7 evaluated here). */
static void test_far_offset(void)
{
    gr_scene *d = load("default.json"), *f = load("hard/far_offset.json");
    const double o[3] = {1e5, 0.0, 1e5};
    for (int k = 0; k < 3; k++) {
        CHECK(f->camera.position_m[k] == d->camera.position_m[k] + o[k]);
        CHECK_NEAR(f->camera.forward[k], d->camera.forward[k], 1e-15);
    }
    CHECK(f->n_occluders == d->n_occluders && f->water.n_waves == d->water.n_waves);
    for (int i = 0; i < d->n_occluders && i < f->n_occluders; i++)
        for (int k = 0; k < 3; k++) CHECK(f->occluders[i].center_m[k] == d->occluders[i].center_m[k] + o[k]);
    double worst = 0.0;
    for (int gx = -10; gx <= 10; gx++)
        for (int gz = -10; gz <= 10; gz++) {
            double x0 = 0.73 * gx, z0 = 0.91 * gz, t = 1.7 * (gx + gz);
            double pd[3] = {x0, 0, z0}, pf[3] = {x0 + o[0], 0, z0 + o[2]};
            for (int i = 0; i < d->water.n_waves; i++) {
                const gr_wave *wd = &d->water.waves[i], *wf = &f->water.waves[i];
                double kd = 2 * PI / wd->wavelength_m, a = wd->direction_deg * PI / 180.0;
                double phd = kd * (sin(a) * x0 + cos(a) * z0) - wd->omega_rad_s * t + wd->phase_rad;
                double phf = kd * (sin(a) * (x0 + o[0]) + cos(a) * (z0 + o[2])) - wf->omega_rad_s * t + wf->phase_rad;
                pd[0] -= wd->amplitude_m * sin(a) * sin(phd);
                pd[2] -= wd->amplitude_m * cos(a) * sin(phd);
                pd[1] += wd->amplitude_m * cos(phd);
                pf[0] -= wf->amplitude_m * sin(a) * sin(phf);
                pf[2] -= wf->amplitude_m * cos(a) * sin(phf);
                pf[1] += wf->amplitude_m * cos(phf);
            }
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(pf[k] - o[k] - pd[k]));
        }
    CHECK_MSG(worst < 1e-8, "far_offset surface differs from the shifted default by %g m", worst);
    free(d);
    free(f);
}

int main(void)
{
    test_default();
    test_others();
    test_hard();
    test_far_offset();
    CHECK_DONE();
}
