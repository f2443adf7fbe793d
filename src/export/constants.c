/* Shader constants for engines (see constants.h; derivations in docs/engines.md). */
#include "export/constants.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/outfile.h"
#include "core/optics.h"
#include "core/shaftgeom.h"
#include "realtime/frame.h"
#include "realtime/shafts.h"

static double wrap_2pi(double x)
{
    double c = fmod(x, 2.0 * GR_PI);
    return c < 0.0 ? c + 2.0 * GR_PI : c;
}

static void set3(double *d, const double *s) { d[0] = s[0], d[1] = s[1], d[2] = s[2]; }

gr_status gr_constants_compute(const gr_scene *s, gr_shader_constants *c, gr_error *err)
{
    memset(c, 0, sizeof *c);
    const gr_camera *cam = &s->camera;
    const gr_water *w = &s->water;
    c->time_s = w->time_s;
    set3(c->eye, cam->position_m);
    c->depth_m = w->rest_height_m - cam->position_m[1];
    if (!(c->depth_m > 0.0))
        return gr_fail(err, GR_E_INPUT, "camera.position_m: y = %g is not below the water's rest height %g; P and S "
                       "(seed eqs. 5.5.5-5.5.6) need an underwater viewer", cam->position_m[1], w->rest_height_m);

    /* The scene's "shafts" section, its scene-derived defaults (extinction, g) resolved. */
    const gr_shafts_settings *sec = gr_shafts_scene_settings(s);
    if (!sec) return gr_fail(err, GR_E_INPUT, "shafts: the scene has no shafts settings");
    gr_shafts_settings sh;
    gr_shafts_resolve(s, sec, &sh);

    /* Seed eqs. 5.5.5a/b and 5.5.6 (src/core/shaftgeom). */
    gr_dvec3 T;
    gr_dvec3 P = gr_shafts_center(gr_d3(c->eye[0], c->eye[1], c->eye[2]),
                                  gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]), w->rest_height_m,
                                  s->medium.ior, &T);
    c->P[0] = P.x, c->P[1] = P.y, c->P[2] = P.z;
    c->refr_dir[0] = T.x, c->refr_dir[1] = T.y, c->refr_dir[2] = T.z;
    for (int k = 0; k < 3; k++) c->to_refr_sun[k] = -c->refr_dir[k];
    c->S = gr_shafts_spacing(sh.K, c->depth_m, cam->fov_deg * GR_PI / 180.0, sh.N);
    if (!(isfinite(P.x) && isfinite(P.z) && T.y < 0.0 && c->S > 0.0 && isfinite(c->S)))
        return gr_fail(err, GR_E_INPUT, "sun.elevation_deg: no finite shaft centre P for this sun and camera");

    /* The frame's shader inputs as every technique gets them (src/realtime/frame.h): GL
     * matrices, sun, seed 000's packed waves in world coordinates (wt = w t - phi0 mod 2 pi). */
    gr_frame *fr = malloc(sizeof *fr);
    if (!fr) return gr_fail(err, GR_E_NOMEM, "out of memory");
    gr_frame_init(s, fr);
    memcpy(c->view, fr->view, sizeof c->view);
    memcpy(c->proj, fr->proj, sizeof c->proj);
    memcpy(c->view_proj, fr->view_proj, sizeof c->view_proj);
    memcpy(c->inv_view_proj, fr->inv_view_proj, sizeof c->inv_view_proj);
    set3(c->sun_dir, fr->sun_dir);
    set3(c->to_sun, fr->to_sun);
    set3(c->sun_irradiance, fr->sun_irradiance);
    c->sun_angular_radius_rad = fr->sun_angular_radius_rad;
    c->transmittance_flat = fr->transmittance_flat;
    c->n_waves = fr->n_waves;
    c->n_groups = fr->n_wave_groups;
    memcpy(c->waves_world, fr->waves_seed, sizeof c->waves_world);
    memcpy(c->waves_rel_p, fr->waves_seed, sizeof c->waves_rel_p);
    free(fr);
    /* Relative to P (as src/realtime uses them): K.X0 = K.(X0 - P) + K.P, so wt_P = wt - K.P. */
    for (int i = 0; i < w->n_waves; i++) {
        const gr_wave *wv = &w->waves[i];
        double kx = wv->k * wv->dir[0], kz = wv->k * wv->dir[1];
        double wt = wv->omega_rad_s * w->time_s - wv->phase_rad;
        c->waves_rel_p[(i / 4) * 5 + 4][i % 4] = (float)wrap_2pi(wt - (kx * P.x + kz * P.z));
    }
    if (gr_mat4_inverse(c->view_proj, c->inv_view_proj) != 0)
        return gr_fail(err, GR_E_INPUT, "camera: singular view-projection matrix");

    /* Medium and the shafts' own settings (their defaults are the medium's) */
    set3(c->extinction, s->medium.extinction);
    c->g = s->medium.g;
    c->ior = s->medium.ior;
    set3(c->shaft_extinction, sh.extinction);
    c->shaft_g = sh.g;
    c->shaft_bias = sh.bias;
    set3(c->shaft_intensity, sh.intensity);
    c->hgg[0] = 1.0 - c->shaft_g * c->shaft_g;
    c->hgg[1] = 1.0 + c->shaft_g * c->shaft_g;
    c->hgg[2] = 2.0 * c->shaft_g;
    c->shaft_N = sh.N;
    c->shaft_K = sh.K;
    c->shaft_length_m = sh.shaft_length_m;
    c->shaft_width = sh.shaft_width;
    c->seabed_y = s->has_seabed ? w->rest_height_m - s->seabed_depth_m : -1e30;
    return GR_OK;
}

/* ---- output --------------------------------------------------------------------------- */

static gr_status write_text(const char *path, const char *text, gr_error *err)
{
    return gr_outfile_write(path, text, -1, err); /* atomic: common/outfile */
}

static cJSON *arr(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]));
    return a;
}

static cJSON *waves_json(const float (*rows)[4], int groups)
{
    cJSON *a = cJSON_CreateArray();
    for (int r = 0; a && r < groups * 5; r++) {
        double v[4] = {rows[r][0], rows[r][1], rows[r][2], rows[r][3]};
        cJSON_AddItemToArray(a, arr(v, 4));
    }
    return a;
}

gr_status gr_constants_write_json(const gr_scene *s, const gr_shader_constants *c, const char *path, gr_error *err)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "format", "godrays-constants-1");
    cJSON_AddStringToObject(root, "scene_name", s->name);
    cJSON_AddStringToObject(root, "scene_hash", s->hash);
    cJSON_AddStringToObject(root, "conventions", "metres, seconds, radians; +y up, right-handed; matrices are "
                            "column-major (element row r, column c at index 4 c + r) in GL convention: view looks "
                            "down -z, clip z in [-1, 1]; vectors are unit; directions of travel unless named to_");
    cJSON_AddNumberToObject(root, "time_s", c->time_s);
    cJSON_AddNumberToObject(root, "width", s->camera.width);
    cJSON_AddNumberToObject(root, "height", s->camera.height);
    cJSON *wv = cJSON_AddObjectToObject(root, "waves");
    cJSON_AddNumberToObject(wv, "count", c->n_waves);
    cJSON_AddNumberToObject(wv, "groups", c->n_groups);
    cJSON_AddNumberToObject(wv, "rest_height_m", s->water.rest_height_m);
    cJSON_AddStringToObject(wv, "layout", "seed 000: per group of 4 waves, 5 vec4 rows kx, kz, A/|k|, A, wt; "
                            "phase = kx x0 + kz z0 - wt; unused lanes have A = 0");
    cJSON_AddItemToObject(wv, "packed_world", waves_json((const float (*)[4])c->waves_world, c->n_groups));
    cJSON_AddItemToObject(wv, "packed_relative_to_P", waves_json((const float (*)[4])c->waves_rel_p, c->n_groups));
    cJSON *sh = cJSON_AddObjectToObject(root, "shafts");
    cJSON_AddItemToObject(sh, "P", arr(c->P, 3));
    cJSON_AddNumberToObject(sh, "S", c->S);
    cJSON_AddNumberToObject(sh, "N", c->shaft_N);
    cJSON_AddNumberToObject(sh, "K", c->shaft_K);
    cJSON_AddNumberToObject(sh, "viewer_depth_m", c->depth_m);
    cJSON_AddNumberToObject(sh, "shaft_length_m", c->shaft_length_m);
    cJSON_AddNumberToObject(sh, "shaft_width", c->shaft_width);
    cJSON_AddItemToObject(sh, "extinction_per_m", arr(c->shaft_extinction, 3));
    cJSON_AddNumberToObject(sh, "g", c->shaft_g);
    cJSON_AddItemToObject(sh, "HGg", arr(c->hgg, 3));
    cJSON_AddNumberToObject(sh, "bias", c->shaft_bias);
    cJSON_AddItemToObject(sh, "intensity", arr(c->shaft_intensity, 3));
    cJSON *su = cJSON_AddObjectToObject(root, "sun");
    cJSON_AddItemToObject(su, "dir", arr(c->sun_dir, 3));
    cJSON_AddItemToObject(su, "to_sun", arr(c->to_sun, 3));
    cJSON_AddItemToObject(su, "refracted_dir", arr(c->refr_dir, 3));
    cJSON_AddItemToObject(su, "to_refracted_sun", arr(c->to_refr_sun, 3));
    cJSON_AddItemToObject(su, "irradiance_W_m2", arr(c->sun_irradiance, 3));
    cJSON_AddNumberToObject(su, "angular_radius_rad", c->sun_angular_radius_rad);
    cJSON_AddNumberToObject(su, "transmittance_flat", c->transmittance_flat);
    cJSON *ca = cJSON_AddObjectToObject(root, "camera");
    cJSON_AddItemToObject(ca, "eye", arr(c->eye, 3));
    cJSON_AddItemToObject(ca, "view", arr(c->view, 16));
    cJSON_AddItemToObject(ca, "proj", arr(c->proj, 16));
    cJSON_AddItemToObject(ca, "view_proj", arr(c->view_proj, 16));
    cJSON_AddItemToObject(ca, "inv_view_proj", arr(c->inv_view_proj, 16));
    cJSON_AddNumberToObject(ca, "fov_y_rad", s->camera.fov_deg * GR_PI / 180.0);
    cJSON_AddNumberToObject(ca, "znear_m", GR_CONST_ZNEAR_M);
    cJSON_AddNumberToObject(ca, "zfar_m", GR_CONST_ZFAR_M);
    cJSON *me = cJSON_AddObjectToObject(root, "medium");
    cJSON_AddItemToObject(me, "absorption_per_m", arr(s->medium.absorption, 3));
    cJSON_AddItemToObject(me, "scattering_per_m", arr(s->medium.scattering, 3));
    cJSON_AddItemToObject(me, "extinction_per_m", arr(c->extinction, 3));
    cJSON_AddNumberToObject(me, "g", c->g);
    cJSON_AddNumberToObject(me, "ior", c->ior);
    if (s->has_seabed) cJSON_AddNumberToObject(me, "seabed_y_m", c->seabed_y);
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    gr_status st = write_text(path, text, err);
    free(text);
    return st;
}

/* ---- GLSL ----------------------------------------------------------------------------- */

typedef struct sbuf {
    char *p;
    size_t n, cap;
    int bad;
} sbuf;

__attribute__((format(printf, 2, 3))) static void sb_printf(sbuf *b, const char *fmt, ...)
{
    if (b->bad) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int m = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (m < 0) {
            b->bad = 1;
            return;
        }
        if (b->p && b->n + (size_t)m < b->cap) {
            b->n += (size_t)m;
            return;
        }
        size_t cap = b->cap ? b->cap * 2 : 4096;
        while (cap < b->n + (size_t)m + 1) cap *= 2;
        char *q = realloc(b->p, cap);
        if (!q) {
            b->bad = 1;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
}

/* float literals: %.9g round-trips a float; GLSL needs a '.' or exponent in a float literal */
static void sb_float(sbuf *b, double v)
{
    char t[40];
    snprintf(t, sizeof t, "%.9g", (double)(float)v);
    if (!strpbrk(t, ".eEn")) strcat(t, ".0");
    sb_printf(b, "%s", t);
}

static void sb_vec(sbuf *b, const char *type, const double *v, int n)
{
    sb_printf(b, "%s(", type);
    for (int i = 0; i < n; i++) {
        if (i) sb_printf(b, ", ");
        sb_float(b, v[i]);
    }
    sb_printf(b, ")");
}

static void sb_const3(sbuf *b, const char *name, const double *v, const char *doc)
{
    sb_printf(b, "const vec3 %s = ", name);
    sb_vec(b, "vec3", v, 3);
    sb_printf(b, "; // %s\n", doc);
}

static void sb_mat(sbuf *b, const char *name, const double *m, const char *doc)
{
    sb_printf(b, "// %s\nconst mat4 %s = ", doc, name);
    sb_vec(b, "mat4", m, 16); /* GLSL's mat4(16 scalars) takes them column by column */
    sb_printf(b, ";\n");
}

static void sb_waves(sbuf *b, const char *name, const float (*rows)[4], int groups)
{
    int n = groups * 5;
    sb_printf(b, "const vec4 %s[%d] = vec4[%d](\n", name, n, n);
    for (int r = 0; r < n; r++) {
        double v[4] = {rows[r][0], rows[r][1], rows[r][2], rows[r][3]};
        sb_printf(b, "    ");
        sb_vec(b, "vec4", v, 4);
        sb_printf(b, "%s // group %d: %s\n", r + 1 < n ? "," : "", r / 5,
                  (const char *[]){"kx", "kz", "A/|k|", "A", "wt"}[r % 5]);
    }
    sb_printf(b, ");\n");
}

gr_status gr_constants_write_glsl(const gr_scene *s, const gr_shader_constants *c, const char *path, gr_error *err)
{
    sbuf b = {0};
    sb_printf(&b, "// godrays export --glsl: scene \"%s\" (hash %s) at water time %.9g s, %dx%d.\n", s->name, s->hash,
              c->time_s, s->camera.width, s->camera.height);
    sb_printf(&b, "// Metres, seconds, radians; +y up, right-handed. Matrices in GL convention (view looks down\n"
                  "// -z, clip z in [-1, 1]). Paste into a GLSL 3.30+ / ES 3.00 shader (docs/engines.md).\n");
    sb_printf(&b, "#define GR_NUM_WAVES %d\n#define GR_NUM_WAVE_GROUPS %d\n", c->n_waves, c->n_groups > 0 ? c->n_groups : 1);
    sb_printf(&b, "// Seed 000's packed waves: per group of 4, rows kx, kz, A/|k|, A, wt; phase = kx x0 + kz z0 - wt\n"
                  "// (eq. 5.5.7). GR_WAVES: x0, z0 world coordinates. GR_WAVES_REL_P: x0, z0 relative to GR_P.\n");
    if (c->n_groups > 0) {
        sb_waves(&b, "GR_WAVES", (const float (*)[4])c->waves_world, c->n_groups);
        sb_waves(&b, "GR_WAVES_REL_P", (const float (*)[4])c->waves_rel_p, c->n_groups);
    } else {
        sb_printf(&b, "const vec4 GR_WAVES[5] = vec4[5](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));\n"
                      "const vec4 GR_WAVES_REL_P[5] = GR_WAVES;\n");
    }
    sb_printf(&b, "const float GR_WATER_REST_HEIGHT = ");
    sb_float(&b, s->water.rest_height_m);
    sb_printf(&b, ";\n");
    sb_const3(&b, "GR_P", c->P, "shaft grid centre, seed eq. 5.5.5a");
    sb_printf(&b, "const float GR_S = ");
    sb_float(&b, c->S);
    sb_printf(&b, "; // shaft spacing (m), seed eq. 5.5.6\nconst int GR_N = %d; // shaft grid vertices per side\n",
              c->shaft_N);
    sb_const3(&b, "GR_REFRACTED_SUN_DIR", c->refr_dir, "T, seed eq. 5.5.5b: sunlight's direction under flat water");
    sb_const3(&b, "GR_TO_REFRACTED_SUN", c->to_refr_sun, "-T");
    sb_const3(&b, "GR_SUN_DIR", c->sun_dir, "sunlight's direction in air");
    sb_const3(&b, "GR_SUN_IRRADIANCE", c->sun_irradiance, "W/m^2 per channel");
    sb_printf(&b, "const float GR_SUN_ANGULAR_RADIUS = ");
    sb_float(&b, c->sun_angular_radius_rad);
    sb_printf(&b, ";\nconst float GR_TRANSMITTANCE_FLAT = ");
    sb_float(&b, c->transmittance_flat);
    sb_printf(&b, ";\n");
    sb_const3(&b, "GR_EXTINCTION", c->extinction, "medium sigma_t (1/m)");
    sb_printf(&b, "const float GR_G = ");
    sb_float(&b, c->g);
    sb_printf(&b, "; // medium HG asymmetry\nconst float GR_IOR = ");
    sb_float(&b, c->ior);
    sb_printf(&b, ";\n");
    sb_const3(&b, "GR_SHAFT_EXTINCTION", c->shaft_extinction, "shafts.extinction (1/m), seed eq. 5.5.3");
    sb_const3(&b, "GR_HGG", c->hgg, "seed's packed HG: (1 - g^2, 1 + g^2, 2 g), shafts.g");
    sb_printf(&b, "const float GR_SHAFT_BIAS = ");
    sb_float(&b, c->shaft_bias);
    sb_printf(&b, ";\n");
    sb_const3(&b, "GR_SHAFT_INTENSITY", c->shaft_intensity, "shafts.intensity");
    sb_const3(&b, "GR_EYE", c->eye, "camera position (m)");
    sb_mat(&b, "GR_VIEW", c->view, "view matrix");
    sb_mat(&b, "GR_PROJ", c->proj, "projection matrix (near 0.05 m, far 2000 m)");
    sb_mat(&b, "GR_VIEW_PROJ", c->view_proj, "GR_PROJ * GR_VIEW");
    sb_mat(&b, "GR_INV_VIEW_PROJ", c->inv_view_proj, "inverse(GR_VIEW_PROJ)");
    gr_status st;
    if (b.bad) st = gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    else st = write_text(path, b.p, err);
    free(b.p);
    return st;
}
