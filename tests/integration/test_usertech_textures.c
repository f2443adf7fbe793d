/* The harness textures "caustics" and "scene_colour" of user techniques (docs/techniques.md
 * "Harness textures"; issue 29), through the probe technique tests/techniques/scene_probe, against
 * independent oracles:
 *  1. flat water: gr_caustic_irradiance on planes at 10.5 m (between two layers of the stack) and
 *     30 m (below the last, clamped) equals cos(theta_i) F_t, F_t the exact unpolarized Fresnel transmittance computed here
 *     from the Fresnel equations (within 1e-3 relative);
 *  2. the stack a user shader reads (t_caustics, every layer, texel for texel) is byte for byte
 *     the stack the volume techniques build: slicing's settings block at its defaults with the
 *     probe's texture_size and grid, through gr_vol_caustics_params and gr_caustics_build, read
 *     by gr_caustics_read, on the default scene's waves; and its mean over the patch at each
 *     depth is the flat-water flux cos(theta_i) F_t within 3 % (flux conservation);
 *  3. scene colour on flat water, camera looking down at the seabed: the radiance is
 *     albedo / pi E_sun cos(theta_i) F_t exp(-sigma_t d / mu_t) exp(-sigma_t t) per channel
 *     (docs/volume-techniques.md eq. SC3) within 1 %; looking up through Snell's window, where
 *     the surface is seen first (alpha 1), it equals t_sun_light x u_sun_light_radiance; the
 *     alpha is 1 for rising rays and 0 for falling ones;
 *  4. an axis-aligned box on the seabed, its faces' normals from the eye depth: on each face
 *     (away from its edges) the radiance is albedo / pi E_sun C / mu_t (N . l)
 *     exp(-sigma_t d / mu_t) exp(-sigma_t t) with N the face's normal, 0 on faces turned away;
 *     the seabed is 0 inside the box's shadow and the closed form outside (both away from the
 *     shadow's edge; the shadow computed here by a ray-box test). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gl/glctx.h"
#include "realtime/caustics.h"
#include "realtime/frame.h"
#include "realtime/slicing.h"
#include "realtime/technique.h"
#include "realtime/volume.h"

static const double albedo[3] = {0.3, 0.5, 0.7}; /* the probe's scene_colour.albedo */

static gr_scene *load_file(const char *rel, const char *const *ov, int n_ov)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", src ? src : GR_SOURCE_DIR, rel);
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    if (!s || gr_scene_load_file(path, ov, n_ov, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

/* Exact unpolarized Fresnel transmittance from air (1) into water (n) at incidence cos_i. */
static double fresnel_t(double cos_i, double n)
{
    double sin_t = sqrt(1.0 - cos_i * cos_i) / n, cos_t = sqrt(1.0 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (cos_t - n * cos_i) / (cos_t + n * cos_i);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

static void set(const gr_technique_class *cls, void *st, const char *key, double v)
{
    gr_error err;
    CHECK_OK(gr_param_set_number(cls->params, st, key, -1, v, &err), err);
}

static gr_image *render(gr_technique *t, const gr_scene *scene, const void *settings)
{
    gr_error err;
    gr_image *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    CHECK_OK(gr_technique_render(t, scene, settings, img, NULL, &err), err);
    return img;
}

/* The camera ray through pixel (px, py) of scene.h (image y down). */
static void view_ray(const gr_scene *s, int px, int py, double d[3])
{
    const gr_camera *cam = &s->camera;
    double tf = tan(0.5 * cam->fov_deg * 3.14159265358979323846 / 180.0), aspect = (double)cam->width / cam->height;
    double a = (2.0 * (px + 0.5) / cam->width - 1.0) * tf * aspect, b = -(2.0 * (py + 0.5) / cam->height - 1.0) * tf;
    double len = 0;
    for (int c = 0; c < 3; c++) {
        d[c] = cam->forward[c] + a * cam->right[c] + b * cam->up[c];
        len += d[c] * d[c];
    }
    for (int c = 0; c < 3; c++) d[c] /= sqrt(len);
}

/* Slab test of the ray o + s d against the box [lo, hi]: the entry distance (-1 if missed) and
 * the entry face's axis and sign. */
static double box_hit(const double o[3], const double d[3], const double lo[3], const double hi[3], int *axis, int *sign)
{
    double t0 = -1e30, t1 = 1e30;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-12) {
            if (o[k] < lo[k] || o[k] > hi[k]) return -1;
            continue;
        }
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        int sg = -1;
        if (a > b) {
            double x = a;
            a = b;
            b = x;
            sg = 1;
        }
        if (a > t0) {
            t0 = a;
            if (axis) *axis = k;
            if (sign) *sign = sg;
        }
        if (b < t1) t1 = b;
    }
    return (t0 <= t1 && t0 > 0) ? t0 : -1;
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/techniques/scene_probe", src ? src : GR_SOURCE_DIR);
    gr_error err;
    CHECK_OK(gr_technique_add_dir(dir, &err), err);
    const gr_technique_class *cls = gr_technique_find("scene_probe");
    CHECK(cls != NULL);
    if (!cls) CHECK_DONE();
    gr_gl *gl = NULL;
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    gr_technique *t = NULL;
    CHECK_OK(gr_technique_create(cls, gl, NULL, &t, &err), err);
    if (!t) CHECK_DONE();
    double settings[GR_TECH_SETTINGS_MAX / sizeof(double)];
    gr_param_defaults(cls->params, settings);

    /* ---- 1. flat water: the helper against cos(theta_i) F_t ---- */
    const char *ov1[] = {"camera.width=64", "camera.height=36", "camera.pitch_deg=-50", "seabed.depth_m=12"};
    gr_scene *flat = load_file("data/scenes/flat.json", ov1, 4);
    gr_frame f;
    gr_frame_init(flat, &f);
    const double cos_i = f.to_sun[1], n = flat->medium.ior;
    const double c_flat = cos_i * fresnel_t(cos_i, n);
    printf("flat water: cos(theta_i) = %.6f, F_t = %.6f (here), %.6f (harness)\n", cos_i, fresnel_t(cos_i, n),
           f.transmittance_flat);
    const double planes[2] = {10.5, 30.0}; /* between layers 9.97 and 15.8 m; below the last */
    for (int k = 0; k < 2; k++) {
        set(cls, settings, "mode", 0);
        set(cls, settings, "plane_depth_m", planes[k]);
        gr_image *img = render(t, flat, settings);
        double worst = 0;
        int hits = 0;
        for (int i = 0; i < img->width * img->height; i++) {
            const float *p = img->pixels + (size_t)i * 3;
            if (p[2] != 1.0f) continue; /* the ray does not reach the plane */
            hits++;
            worst = fmax(worst, fabs(p[0] - c_flat) / c_flat);
        }
        printf("flat water, plane at %g m: %d pixels, max relative error %.3g\n", planes[k], hits, worst);
        CHECK(hits > img->width * img->height / 2);
        CHECK(worst < 1e-3);
        gr_image_destroy(img);
    }

    /* ---- 2. the user's stack is the volume techniques' stack ---- */
    const char *ov2[] = {"camera.width=64", "camera.height=64"};
    gr_scene *wavy = load_file("data/scenes/default.json", ov2, 2);
    gr_frame fw;
    gr_frame_init(wavy, &fw);
    gr_slicing_settings ss;
    gr_param_defaults(gr_slicing_class.params, &ss);
    ss.vol.texture_size = 64; /* the probe's "caustics": {"texture_size": 64, "grid": 64} */
    ss.vol.grid = 64;
    gr_caustics_params cp;
    gr_vol_caustics_params(&ss.vol, &cp);
    gr_caustics *caus = NULL;
    CHECK_OK(gr_gl_make_current(gl, &err), err);
    CHECK_OK(gr_caustics_create(NULL, &caus, &err), err);
    CHECK_OK(gr_caustics_build(caus, wavy, &fw, &cp, &err), err);
    const double c_wavy = fw.to_sun[1] * fresnel_t(fw.to_sun[1], wavy->medium.ior);
    set(cls, settings, "mode", 1);
    for (int layer = 0; layer < cp.n_depths; layer++) {
        gr_image *ref = NULL;
        CHECK_OK(gr_gl_make_current(gl, &err), err);
        CHECK_OK(gr_caustics_read(caus, layer, &ref, &err), err);
        set(cls, settings, "layer", layer);
        gr_image *img = render(t, wavy, settings);
        if (!ref) break;
        int differ = 0;
        double sum = 0;
        for (int y = 0; y < 64; y++)
            for (int x = 0; x < 64; x++) {
                float a = gr_image_pixel(img, x, 63 - y)[0], b = ref->pixels[y * 64 + x]; /* image rows top first */
                differ += memcmp(&a, &b, sizeof a) != 0;
                sum += b;
            }
        double mean = sum / (64.0 * 64.0);
        printf("layer %d (%.3g m): %d of 4096 texels differ from the volume techniques' stack; mean %.5f, flat %.5f (%+.2f %%)\n",
               layer, cp.depths_m[layer], differ, mean, c_wavy, 100.0 * (mean / c_wavy - 1.0));
        CHECK(differ == 0);
        CHECK(fabs(mean / c_wavy - 1.0) < 0.03);
        gr_image_destroy(img);
        gr_image_destroy(ref);
    }
    CHECK_OK(gr_gl_make_current(gl, &err), err);
    gr_caustics_destroy(caus);

    /* ---- 3. scene colour on flat water: the seabed, Snell's window ---- */
    const double mu_t = -f.refr_dir[1], d_bed = flat->seabed_depth_m;
    set(cls, settings, "mode", 2);
    gr_image *sc = render(t, flat, settings);
    double worst = 0;
    int seen = 0;
    for (int py = 0; py < sc->height; py++)
        for (int px = 0; px < sc->width; px++) {
            double d[3];
            view_ray(flat, px, py, d);
            if (!(d[1] < -1e-3)) continue;
            double te = (f.seabed_y - f.eye[1]) / d[1];
            const float *p = gr_image_pixel(sc, px, py);
            for (int c = 0; c < 3; c++) {
                const double s_t = flat->medium.extinction[c];
                /* eq. SC3: albedo / pi E_sun C exp(-sigma_t d / mu_t) exp(-sigma_t t) */
                double L = albedo[c] / 3.14159265358979323846 * f.sun_irradiance[c] * c_flat *
                           exp(-s_t * d_bed / mu_t) * exp(-s_t * te);
                worst = fmax(worst, fabs(p[c] - L) / L);
            }
            seen++;
        }
    printf("scene colour, seabed on flat water: %d pixels, max relative error %.3g\n", seen, worst);
    CHECK(seen == sc->width * sc->height);
    CHECK(worst < 0.01);
    gr_image_destroy(sc);

    /* two views: across the horizon (rising and falling rays), toward the refracted sun */
    int rising = 0, falling = 0, bad_alpha = 0, differ = 0, lit = 0;
    for (int v = 0; v < 2; v++) {
        const char *ov3[] = {"camera.width=64", "camera.height=36", v ? "camera.pitch_deg=60" : "camera.pitch_deg=10",
                             "seabed.depth_m=12"};
        gr_scene *up = load_file("data/scenes/flat.json", ov3, 4);
        set(cls, settings, "mode", 2);
        sc = render(t, up, settings);
        set(cls, settings, "mode", 3);
        gr_image *sl = render(t, up, settings);
        set(cls, settings, "mode", 4);
        gr_image *al = render(t, up, settings);
        for (int py = 0; py < sc->height; py++)
            for (int px = 0; px < sc->width; px++) {
                double d[3];
                view_ray(up, px, py, d);
                const float *a = gr_image_pixel(al, px, py), *p = gr_image_pixel(sc, px, py), *q = gr_image_pixel(sl, px, py);
                if (d[1] > 1e-3) {
                    rising++;
                    bad_alpha += a[0] != 1.0f || a[1] != 1.0f;
                    differ += memcmp(p, q, 3 * sizeof *p) != 0;
                    lit += q[2] > 0;
                } else if (d[1] < -1e-3) {
                    falling++;
                    bad_alpha += a[0] != 0.0f || a[1] != 0.0f;
                    differ += q[0] != 0 || q[1] != 0 || q[2] != 0; /* the light pass: seabed black */
                }
            }
        gr_image_destroy(sc);
        gr_image_destroy(sl);
        gr_image_destroy(al);
        free(up);
    }
    printf("looking up: %d rising rays (%d see the sun's kernel), %d falling; %d wrong alphas, %d pixels where scene "
           "colour != sun light x radiance\n",
           rising, lit, falling, bad_alpha, differ);
    CHECK(rising > 100 && falling > 100 && lit > 0);
    CHECK(bad_alpha == 0);
    CHECK(differ == 0);

    /* ---- 4. a box on the seabed: normals from the eye depth, its shadow ---- */
    const double lo[3] = {-1.0, -12.0, 4.0}, hi[3] = {1.0, -9.0, 6.0};
    char json[2048];
    snprintf(json, sizeof json,
             "{\"version\": 1, \"name\": \"box\", \"water\": {\"rest_height_m\": 0, \"time_s\": 0, \"waves\": []},"
             " \"sun\": {\"elevation_deg\": 40, \"azimuth_deg\": 225, \"irradiance\": [1, 1, 1], \"angular_diameter_deg\": 0.53},"
             " \"medium\": {\"absorption_per_m\": [0.342, 0.0585, 0.0212], \"scattering_per_m\": [0.041, 0.049, 0.062],"
             " \"g\": 0.9, \"ior\": 1.333},"
             " \"camera\": {\"position_m\": [3, -5, 0], \"yaw_deg\": 0, \"pitch_deg\": -35, \"fov_deg\": 60, \"width\": 96, \"height\": 54},"
             " \"occluders\": [{\"type\": \"box\", \"name\": \"b\", \"center_m\": [%g, %g, %g], \"size_m\": [%g, %g, %g]}],"
             " \"seabed\": {\"depth_m\": 12}}",
             0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]), hi[0] - lo[0], hi[1] - lo[1],
             hi[2] - lo[2]);
    gr_scene *bs = malloc(sizeof *bs);
    if (!bs || gr_scene_load_string(json, "box scene", NULL, 0, bs, &err) != GR_OK) {
        fprintf(stderr, "box scene: %s\n", bs ? err.msg : "out of memory");
        return 1;
    }
    gr_frame fb;
    gr_frame_init(bs, &fb);
    const double mub = -fb.refr_dir[1], cb = fb.to_sun[1] * fresnel_t(fb.to_sun[1], bs->medium.ior);
    set(cls, settings, "mode", 2);
    sc = render(t, bs, settings);
    double worst_face = 0, worst_bed = 0, worst_dark = 0;
    int n_face[3][2] = {{0}}, n_bed = 0, n_shadow = 0;
    const int W = bs->camera.width, H = bs->camera.height;
    for (int py = 1; py < H - 1; py++)
        for (int px = 1; px < W - 1; px++) {
            double d[3];
            int axis = -1, sign = 0, same = 1;
            view_ray(bs, px, py, d);
            double tb = box_hit(fb.eye, d, lo, hi, &axis, &sign);
            /* the 4 neighbours on the same face, or all on the seabed */
            for (int k = 0; k < 4; k++) {
                double dn[3];
                int ax = -1, sg = 0;
                view_ray(bs, px + (k == 0) - (k == 1), py + (k == 2) - (k == 3), dn);
                double tn = box_hit(fb.eye, dn, lo, hi, &ax, &sg);
                same &= (tb > 0) == (tn > 0) && (tb < 0 || (ax == axis && sg == sign));
            }
            if (!same || !(d[1] < -1e-3)) continue;
            const float *p = gr_image_pixel(sc, px, py);
            double te = tb > 0 ? tb : (fb.seabed_y - fb.eye[1]) / d[1];
            double x[3] = {fb.eye[0] + d[0] * te, fb.eye[1] + d[1] * te, fb.eye[2] + d[2] * te};
            double nrm[3] = {0, 0, 0}, depth = fb.rest_height_m - x[1];
            if (tb > 0) nrm[axis] = sign;
            else nrm[1] = 1;
            double cosl = fmax(0.0, nrm[0] * fb.to_refr_sun[0] + nrm[1] * fb.to_refr_sun[1] + nrm[2] * fb.to_refr_sun[2]);
            double vis = 1.0;
            if (tb < 0) { /* the seabed's shadow: the sun ray from x and from 4 points 0.25 m away */
                int hit = 0;
                for (int k = 0; k < 5; k++) {
                    double o[3] = {x[0] + 0.25 * ((k == 1) - (k == 2)), x[1] + 1e-6, x[2] + 0.25 * ((k == 3) - (k == 4))};
                    hit += box_hit(o, fb.to_refr_sun, lo, hi, NULL, NULL) > 0;
                }
                if (hit != 0 && hit != 5) continue; /* near the shadow's edge */
                vis = hit ? 0.0 : 1.0;
            }
            for (int c = 0; c < 3; c++) {
                const double s_t = bs->medium.extinction[c];
                double L = albedo[c] / 3.14159265358979323846 * fb.sun_irradiance[c] * cb / mub * cosl *
                           exp(-s_t * depth / mub) * vis * exp(-s_t * te);
                if (tb > 0 && cosl > 0) worst_face = fmax(worst_face, fabs(p[c] - L) / L);
                else if (tb > 0 || vis == 0) worst_dark = fmax(worst_dark, fabs(p[c]));
                else worst_bed = fmax(worst_bed, fabs(p[c] - L) / L);
            }
            if (tb > 0) n_face[axis][sign > 0]++;
            else if (vis == 0) n_shadow++;
            else n_bed++;
        }
    printf("box: face pixels -x %d +x %d, -y %d +y %d, -z %d +z %d; lit faces max relative error %.3g, faces turned "
           "away and the shadow max %.3g\n",
           n_face[0][0], n_face[0][1], n_face[1][0], n_face[1][1], n_face[2][0], n_face[2][1], worst_face, worst_dark);
    printf("box: seabed %d lit pixels (max relative error %.3g), %d in the shadow\n", n_bed, worst_bed, n_shadow);
    CHECK(n_face[1][1] > 20 && n_face[2][0] > 20 && n_face[0][1] > 20 && n_shadow > 20 && n_bed > 100);
    CHECK(worst_face < 0.02);
    CHECK(worst_bed < 0.01);
    CHECK(worst_dark == 0);
    gr_image_destroy(sc);

    gr_technique_destroy(t);
    gr_gl_destroy(gl);
    free(flat);
    free(wavy);
    free(bs);
    CHECK_DONE();
}
