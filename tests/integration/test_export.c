/* godrays export's library side, read back independently:
 *  - the glTF written by gr_gltf_write, parsed here with cJSON and a few lines of buffer reading
 *    (no glTF library): sampled water vertices lie on the project's Gerstner surface (their height
 *    from gr_gerstner_height_at at their own (x, z), which inverts eq. 5.5.7 independently of the
 *    rest grid) within 1e-5 m, and their normals match gr_gerstner_frame at the recovered rest point;
 *    the .glb's header and chunks follow the spec and its BIN chunk is the .gltf's .bin;
 *  - the shader constants against closed forms: the view matrix maps the eye to the origin and
 *    forward to -z; un-projecting pixel centres gives the scene's pixel rays (scene.h); P is on the
 *    rest plane on the refracted sun ray through the eye (eq. 5.5.5a); T obeys Snell's law; S is
 *    eq. 5.5.6; the packed waves give back gr_gerstner_position through the seed's formula;
 *  - the GLSL file compiles in a real GL context and, evaluated there, gives the same surface
 *    and the same clip position of P as the double computation. */
#include "check.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/gerstner.h"
#include "core/optics.h"
#include "export/constants.h"
#include "export/gltf.h"
#include "gl/gl.h"
#include "gl/glctx.h"
#include "realtime/shafts.h"
#include "scene/scene.h"

static unsigned char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)len + 1);
    if (b && fread(b, 1, (size_t)len, f) != (size_t)len) {
        free(b);
        b = NULL;
    }
    fclose(f);
    if (b) b[len] = 0;
    *n = (size_t)len;
    return b;
}

static uint32_t u32(const unsigned char *p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }
static double num(const cJSON *o, const char *k) { return cJSON_GetNumberValue(cJSON_GetObjectItem(o, k)); }

/* float data of accessor `acc` (VEC3 float expected) */
static const float *accessor_f3(const cJSON *g, const unsigned char *bin, int acc, int *count)
{
    const cJSON *a = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "accessors"), acc);
    const cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "bufferViews"), (int)num(a, "bufferView"));
    CHECK(num(a, "componentType") == 5126);
    CHECK(!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(a, "type")), "VEC3"));
    *count = (int)num(a, "count");
    double off = num(v, "byteOffset") + (cJSON_HasObjectItem(a, "byteOffset") ? num(a, "byteOffset") : 0);
    return (const float *)(bin + (size_t)off);
}

static void check_gltf(const gr_scene *s, const char *dir)
{
    char gpath[1024], bpath[1024], glb[1024];
    snprintf(gpath, sizeof gpath, "%s/export_c.gltf", dir);
    snprintf(bpath, sizeof bpath, "%s/export_c.bin", dir);
    snprintf(glb, sizeof glb, "%s/export_c.glb", dir);
    gr_gltf_options o = {.grid_cells = 96, .half_size_m = 20.0};
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_gltf_write(s, &o, gpath, &err), err);
    CHECK_OK(gr_gltf_write(s, &o, glb, &err), err);
    size_t nj = 0, nb = 0, ng = 0;
    unsigned char *js = read_all(gpath, &nj), *bin = read_all(bpath, &nb), *gb = read_all(glb, &ng);
    CHECK(js && bin && gb);
    if (!js || !bin || !gb) return;
    cJSON *g = cJSON_Parse((const char *)js);
    CHECK(g != NULL);

    /* GLB: header, JSON chunk, BIN chunk identical to the .bin */
    CHECK(u32(gb) == 0x46546C67u && u32(gb + 4) == 2 && u32(gb + 8) == ng);
    uint32_t jl = u32(gb + 12);
    CHECK(u32(gb + 16) == 0x4E4F534Au && jl % 4 == 0);
    uint32_t bl = u32(gb + 20 + jl);
    CHECK(u32(gb + 24 + jl) == 0x004E4942u && bl % 4 == 0 && 28u + jl + bl == ng);
    CHECK(bl >= nb && bl - nb < 4 && !memcmp(gb + 28 + jl, bin, nb));

    /* water: node "water" with its translation, mesh 0's POSITION and NORMAL */
    const cJSON *nodes = cJSON_GetObjectItem(g, "nodes"), *wn = NULL, *it;
    cJSON_ArrayForEach(it, nodes) if (!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(it, "name")), "water")) wn = it;
    CHECK(wn != NULL);
    if (!wn) return;
    const cJSON *tr = cJSON_GetObjectItem(wn, "translation");
    double T[3] = {cJSON_GetArrayItem(tr, 0)->valuedouble, cJSON_GetArrayItem(tr, 1)->valuedouble,
                   cJSON_GetArrayItem(tr, 2)->valuedouble};
    const cJSON *mesh = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "meshes"), (int)num(wn, "mesh"));
    const cJSON *attr = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(mesh, "primitives"), 0), "attributes");
    int np = 0, nn = 0;
    const float *pos = accessor_f3(g, bin, (int)num(attr, "POSITION"), &np);
    const float *nrm = accessor_f3(g, bin, (int)num(attr, "NORMAL"), &nn);
    CHECK(np == 97 * 97 && nn == np);
    double worst = 0.0, worstn = 0.0;
    int checked = 0;
    for (int v = 0; v < np; v += 37) {
        double x = T[0] + pos[3 * v], y = T[1] + pos[3 * v + 1], z = T[2] + pos[3 * v + 2], h, x0, z0;
        CHECK(gr_gerstner_height_at(&s->water, x, z, s->water.time_s, &h, &x0, &z0) == 0);
        worst = fmax(worst, fabs(h - y));
        gr_dvec3 n;
        gr_gerstner_frame(&s->water, x0, z0, s->water.time_s, NULL, NULL, &n);
        worstn = fmax(worstn, fmax(fabs(n.x - nrm[3 * v]), fmax(fabs(n.y - nrm[3 * v + 1]), fabs(n.z - nrm[3 * v + 2]))));
        checked++;
    }
    printf("glTF: %d sampled vertices: max |y - Gerstner height| = %.3g m, max normal component error %.3g\n", checked,
           worst, worstn);
    CHECK(checked > 200);
    CHECK(worst <= 1e-5);
    CHECK(worstn <= 1e-5);
    cJSON_Delete(g);
    free(js), free(bin), free(gb);
}

/* column-major m times (x, y, z, w) */
static void apply(const double *m, const double in[4], double out[4])
{
    for (int r = 0; r < 4; r++) out[r] = m[r] * in[0] + m[4 + r] * in[1] + m[8 + r] * in[2] + m[12 + r] * in[3];
}

/* The seed's listing evaluated in double from the packed rows: displacement of (x0, z0). */
static gr_dvec3 seed_displacement(const float (*rows)[4], int groups, double x0, double z0)
{
    gr_dvec3 d = gr_d3(0, 0, 0);
    for (int gi = 0; gi < groups; gi++)
        for (int l = 0; l < 4; l++) {
            double kx = rows[gi * 5][l], kz = rows[gi * 5 + 1][l], A = rows[gi * 5 + 3][l], wt = rows[gi * 5 + 4][l];
            double k = sqrt(kx * kx + kz * kz);
            if (k == 0.0) continue;
            double ph = kx * x0 + kz * z0 - wt;
            d.x -= A * kx / k * sin(ph);
            d.z -= A * kz / k * sin(ph);
            d.y += A * cos(ph);
        }
    return d;
}

static void check_constants(const gr_scene *s, gr_shader_constants *c)
{
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_constants_compute(s, c, &err), err);
    const gr_camera *cam = &s->camera;
    double e4[4] = {cam->position_m[0], cam->position_m[1], cam->position_m[2], 1}, o[4];
    apply(c->view, e4, o);
    CHECK(fabs(o[0]) < 1e-12 && fabs(o[1]) < 1e-12 && fabs(o[2]) < 1e-12 && o[3] == 1.0);
    double f4[4] = {cam->forward[0], cam->forward[1], cam->forward[2], 0};
    apply(c->view, f4, o);
    CHECK(fabs(o[0]) < 1e-12 && fabs(o[1]) < 1e-12 && fabs(o[2] + 1.0) < 1e-12);
    /* pixel rays: un-project two depths of a pixel centre, compare with scene.h's formula */
    double tf = tan(0.5 * cam->fov_deg * GR_PI / 180.0), aspect = (double)cam->width / cam->height, worst = 0;
    int px[3][2] = {{0, 0}, {cam->width - 1, cam->height / 3}, {cam->width / 2, cam->height - 1}};
    for (int k = 0; k < 3; k++) {
        double nx = 2.0 * (px[k][0] + 0.5) / cam->width - 1.0, ny = 1.0 - 2.0 * (px[k][1] + 0.5) / cam->height;
        double a[4] = {nx, ny, -1, 1}, b[4] = {nx, ny, 0.5, 1}, pa[4], pb[4], d[3], want[3], la = 0, lw = 0;
        apply(c->inv_view_proj, a, pa);
        apply(c->inv_view_proj, b, pb);
        for (int q = 0; q < 3; q++) {
            d[q] = pb[q] / pb[3] - pa[q] / pa[3];
            want[q] = cam->forward[q] + nx * tf * aspect * cam->right[q] + ny * tf * cam->up[q];
            la += d[q] * d[q], lw += want[q] * want[q];
        }
        for (int q = 0; q < 3; q++) worst = fmax(worst, fabs(d[q] / sqrt(la) - want[q] / sqrt(lw)));
    }
    printf("constants: pixel-ray direction error %.3g\n", worst);
    CHECK(worst < 1e-6);
    /* P and T: seed eq. 5.5.5 and Snell's law sin t = sin i / n about the normal +y */
    CHECK_NEAR(c->P[1], s->water.rest_height_m, 1e-12);
    double dp[3] = {c->P[0] - cam->position_m[0], c->P[1] - cam->position_m[1], c->P[2] - cam->position_m[2]};
    double cr = hypot(hypot(dp[1] * c->refr_dir[2] - dp[2] * c->refr_dir[1], dp[2] * c->refr_dir[0] - dp[0] * c->refr_dir[2]),
                      dp[0] * c->refr_dir[1] - dp[1] * c->refr_dir[0]);
    CHECK(cr < 1e-9 * (1 + fabs(dp[1])));
    CHECK(dp[1] * -c->refr_dir[1] > 0); /* P lies up the beam from the eye */
    double sin_i = sqrt(1 - s->sun.dir[1] * s->sun.dir[1]), sin_t = sqrt(1 - c->refr_dir[1] * c->refr_dir[1]);
    CHECK_NEAR(sin_t, sin_i / s->medium.ior, 1e-12);
    const gr_shafts_settings *sh = gr_shafts_scene_settings(s);
    CHECK(sh != NULL);
    if (sh) CHECK_NEAR(c->S, sh->K * 2 * c->depth_m * tan(0.5 * cam->fov_deg * GR_PI / 180.0) / sh->N, 1e-12);
    /* packed waves: the seed's formula gives gr_gerstner_position (float-rounded constants) */
    double werr = 0;
    for (int k = 0; k < 5; k++) {
        double x0 = -7.3 + 3.1 * k, z0 = 2.2 - 4.4 * k;
        gr_dvec3 want = gr_gerstner_position(&s->water, x0, z0, s->water.time_s);
        gr_dvec3 dw = seed_displacement((const float (*)[4])c->waves_world, c->n_groups, x0, z0);
        gr_dvec3 dr = seed_displacement((const float (*)[4])c->waves_rel_p, c->n_groups, x0 - c->P[0], z0 - c->P[2]);
        werr = fmax(werr, fabs(x0 + dw.x - want.x) + fabs(s->water.rest_height_m + dw.y - want.y) + fabs(z0 + dw.z - want.z));
        werr = fmax(werr, fabs(x0 + dr.x - want.x) + fabs(s->water.rest_height_m + dr.y - want.y) + fabs(z0 + dr.z - want.z));
    }
    printf("constants: packed-wave surface error %.3g m\n", werr);
    CHECK(werr < 1e-5);
}

#define NPTS 6
static void check_glsl(const gr_scene *s, const gr_shader_constants *c, const char *dir)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/export_c.glsl", dir);
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_constants_write_glsl(s, c, path, &err), err);
    size_t n = 0;
    unsigned char *text = read_all(path, &n);
    CHECK(text != NULL);
    if (!text) return;
    gr_gl *gl = NULL;
    gr_status st = gr_gl_create(NULL, &gl, &err);
    CHECK_OK(st, err);
    if (st != GR_OK) {
        free(text);
        return;
    }
    static const char *vs = "#version 330 core\nvoid main() {\n"
                            "  vec2 p[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));\n"
                            "  gl_Position = vec4(p[gl_VertexID], 0.0, 1.0);\n}\n";
    /* pixel i < NPTS: seed displacement at (x0_i, z0_i); pixel NPTS: clip position of P */
    static const char *fs_tail =
        "out vec4 color;\n"
        "void main() {\n"
        "  int i = int(gl_FragCoord.x);\n"
        "  if (i >= 6) { color = GR_VIEW_PROJ * vec4(GR_P, 1.0); return; }\n"
        "  float x0 = -7.3 + 3.1 * float(i), z0 = 2.2 - 4.4 * float(i);\n"
        "  vec3 d = vec3(0.0);\n"
        "  for (int g = 0; g < GR_NUM_WAVE_GROUPS; g++) {\n"
        "    vec4 kx = GR_WAVES[g * 5], kz = GR_WAVES[g * 5 + 1], Ainvk = GR_WAVES[g * 5 + 2];\n"
        "    vec4 A = GR_WAVES[g * 5 + 3], wt = GR_WAVES[g * 5 + 4];\n"
        "    vec4 ph = kx * x0 + kz * z0 - wt;\n"
        "    d.x -= dot(Ainvk * kx, sin(ph)); d.z -= dot(Ainvk * kz, sin(ph)); d.y += dot(A, cos(ph));\n"
        "  }\n"
        "  color = vec4(d, GR_S);\n"
        "}\n";
    size_t fl = n + strlen(fs_tail) + 64;
    char *fs = malloc(fl);
    snprintf(fs, fl, "#version 330 core\n%s\n%s", (const char *)text, fs_tail);
    unsigned prog = 0;
    st = gr_gl_build_program(path, vs, fs, &prog, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) {
        GLuint tex = 0, fbo = 0, vao = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, NPTS + 1, 1, 0, GL_RGBA, GL_FLOAT, NULL);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
        glGenVertexArrays(1, &vao);
        glBindVertexArray(vao);
        glViewport(0, 0, NPTS + 1, 1);
        glUseProgram(prog);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        float px[(NPTS + 1) * 4];
        glReadPixels(0, 0, NPTS + 1, 1, GL_RGBA, GL_FLOAT, px);
        CHECK_OK(gr_gl_check("render", &err), err);
        double worst = 0;
        for (int i = 0; i < NPTS; i++) {
            double x0 = (double)(-7.3f + 3.1f * (float)i), z0 = (double)(2.2f - 4.4f * (float)i);
            gr_dvec3 want = gr_gerstner_position(&s->water, x0, z0, s->water.time_s);
            worst = fmax(worst, fabs(px[4 * i] - (want.x - x0)));
            worst = fmax(worst, fabs(px[4 * i + 1] - (want.y - s->water.rest_height_m)));
            worst = fmax(worst, fabs(px[4 * i + 2] - (want.z - z0)));
            CHECK_REL(px[4 * i + 3], c->S, 1e-6);
        }
        double P4[4] = {c->P[0], c->P[1], c->P[2], 1}, clip[4];
        apply(c->view_proj, P4, clip);
        double cerr = 0;
        for (int k = 0; k < 4; k++) cerr = fmax(cerr, fabs(px[4 * NPTS + k] - clip[k]) / (1 + fabs(clip[k])));
        printf("GLSL (%s): surface error %.3g m, clip(P) relative error %.3g\n", gr_gl_renderer(gl), worst, cerr);
        CHECK(worst < 2e-5);
        CHECK(cerr < 1e-5);
        glDeleteProgram(prog);
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &tex);
        glDeleteVertexArrays(1, &vao);
    }
    free(fs);
    free(text);
    gr_gl_destroy(gl);
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR"), *out = getenv("GODRAYS_TEST_OUT");
    if (!src) src = ".";
    if (!out) out = "/tmp";
    char path[1024];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src);
    gr_scene *s = malloc(sizeof *s);
    gr_shader_constants *c = malloc(sizeof *c);
    gr_error err = {GR_OK, ""};
    gr_status st = gr_scene_load_file(path, NULL, 0, s, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) {
        check_gltf(s, out);
        check_constants(s, c);
        check_glsl(s, c, out);
        /* an unknown extension is refused before anything is written */
        snprintf(path, sizeof path, "%s/export_c.obj", out);
        CHECK(gr_gltf_write(s, NULL, path, &err) == GR_E_USAGE);
        FILE *f = fopen(path, "rb");
        CHECK(f == NULL);
        if (f) fclose(f);
    }
    free(s);
    free(c);
    CHECK_DONE();
}
