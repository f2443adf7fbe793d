/* A user technique's shaders see the documented harness values (docs/techniques.md): the probe
 * technique (tests/techniques/probe) writes them to its layer and each is compared with an
 * independent closed form or CPU implementation:
 *  - gr_view_ray(v_uv) against the camera ray of scene.h (pixel centres, image y down), which
 *    also checks the readback's row order and v_uv;
 *  - gr_water_normal (u_wave_a/u_wave_b) and seed 000's CalculateWaterNormal ported on the
 *    packed u_waves, both against core/gerstner's double-precision normal (seed eq. 5.5.8) at
 *    water.time_s = 1.7;
 *  - number/int/bool/rgb settings as u_set_*, a target read by a later pass, additive blending
 *    and an instanced draw whose instance count is an int setting: exact sums;
 *  - stats: the pass names, samples passed = W H (2 + n) for two full-screen passes and n
 *    full-screen instances. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/gerstner.h"
#include "realtime/technique.h"

#define W 48
#define H 27

static gr_scene *load_scene(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    const char *ov[] = {"camera.width=48", "camera.height=27", "water.time_s=1.7"};
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    if (!s || gr_scene_load_file(path, ov, 3, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

static void set(const gr_technique_class *cls, void *st, const char *key, int ch, double v)
{
    gr_error err;
    CHECK_OK(gr_param_set_number(cls->params, st, key, ch, v, &err), err);
}

static gr_image *render(gr_technique *t, const gr_scene *scene, const void *settings, gr_technique_stats *stats)
{
    gr_error err;
    gr_image *img = gr_image_create(W, H, 3, NULL);
    gr_status st = gr_technique_render(t, scene, settings, img, stats, &err);
    CHECK_OK(st, err);
    return img;
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/techniques/probe", src ? src : GR_SOURCE_DIR);
    gr_error err;
    CHECK_OK(gr_technique_add_dir(dir, &err), err);
    const gr_technique_class *cls = gr_technique_find("probe");
    CHECK(cls != NULL);
    if (!cls) CHECK_DONE();
    gr_scene *scene = load_scene();
    gr_gl *gl = NULL;
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    gr_technique *t = NULL;
    CHECK_OK(gr_technique_create(cls, gl, NULL, &t, &err), err);
    if (!t) CHECK_DONE();
    double settings[GR_TECH_SETTINGS_MAX / sizeof(double)];
    gr_param_defaults(cls->params, settings);
    set(cls, settings, "n", -1, 0);
    gr_technique_stats stats;

    /* mode 0: view rays (scene.h: forward + (2 (px + .5) / W - 1) tan(fov/2) aspect right
     *                               - (2 (py + .5) / H - 1) tan(fov/2) up) */
    set(cls, settings, "mode", -1, 0);
    gr_image *img = render(t, scene, settings, &stats);
    const gr_camera *cam = &scene->camera;
    double tf = tan(0.5 * cam->fov_deg * 3.14159265358979323846 / 180.0), aspect = (double)W / H, worst = 0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double a = (2.0 * (px + 0.5) / W - 1.0) * tf * aspect, b = -(2.0 * (py + 0.5) / H - 1.0) * tf, d[3], len = 0;
            for (int c = 0; c < 3; c++) {
                d[c] = cam->forward[c] + a * cam->right[c] + b * cam->up[c];
                len += d[c] * d[c];
            }
            const float *p = gr_image_pixel(img, px, py);
            for (int c = 0; c < 3; c++) worst = fmax(worst, fabs(p[c] - d[c] / sqrt(len)));
        }
    printf("view rays: max |gl - closed form| = %.3g\n", worst);
    CHECK(worst < 2e-5);
    gr_image_destroy(img);

    /* modes 1 and 2: Gerstner normals at xz = (uv - 0.5) * extent, uv = ((px + .5) / W, 1 - (py + .5) / H) */
    for (int mode = 1; mode <= 2; mode++) {
        set(cls, settings, "mode", -1, mode);
        img = render(t, scene, settings, &stats);
        worst = 0;
        for (int py = 0; py < H; py++)
            for (int px = 0; px < W; px++) {
                double u = (px + 0.5) / W, v = 1.0 - (py + 0.5) / H;
                gr_dvec3 n;
                gr_gerstner_frame(&scene->water, (u - 0.5) * 20.0, (v - 0.5) * 20.0, scene->water.time_s, NULL, NULL, &n);
                const float *p = gr_image_pixel(img, px, py);
                worst = fmax(worst, fmax(fabs(p[0] - n.x), fmax(fabs(p[1] - n.y), fabs(p[2] - n.z))));
            }
        printf("%s: max |gl - gerstner.c| = %.3g\n", mode == 1 ? "gr_water_normal (u_wave_a/b)" : "seed listing (u_waves)",
               worst);
        CHECK(worst < 1e-4);
        gr_image_destroy(img);
    }

    /* mode 3: settings + copy pass + n additive instances */
    set(cls, settings, "mode", -1, 3);
    set(cls, settings, "a", -1, -1.5);
    set(cls, settings, "n", -1, 5);
    set(cls, settings, "flag", -1, 1);
    set(cls, settings, "add", -1, 0.25);
    img = render(t, scene, settings, &stats);
    const float *p = gr_image_pixel(img, 7, 3);
    CHECK_NEAR(p[0], -1.5 + 5 * 0.25, 1e-6);
    CHECK_NEAR(p[1], 5 + 5 * 0.25, 1e-6);
    CHECK_NEAR(p[2], 1 + 5 * 0.25, 1e-6);
    CHECK(stats.n_passes == 3);
    CHECK(!strcmp(stats.pass_names[0], "probe") && !strcmp(stats.pass_names[1], "copy") &&
          !strcmp(stats.pass_names[2], "add"));
    CHECK_MSG(stats.fragments == (long long)W * H * (2 + 5), "fragments %lld", stats.fragments);
    CHECK(stats.wall_ms > 0);
    gr_image_destroy(img);

    /* mode 4: an rgb setting, per channel */
    set(cls, settings, "mode", -1, 4);
    set(cls, settings, "n", -1, 0);
    set(cls, settings, "tint", 0, 0.1);
    set(cls, settings, "tint", 1, 0.2);
    set(cls, settings, "tint", 2, 3.5);
    img = render(t, scene, settings, &stats);
    p = gr_image_pixel(img, W - 1, H - 1);
    CHECK_NEAR(p[0], 0.1, 1e-7);
    CHECK_NEAR(p[1], 0.2, 1e-7);
    CHECK_NEAR(p[2], 3.5, 1e-7);
    gr_image_destroy(img);

    gr_technique_destroy(t);
    gr_gl_destroy(gl);
    free(scene);
    CHECK_DONE();
}
