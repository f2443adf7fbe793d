/* The user's own technique from a folder: the class made from its manifest
 * (usertech_manifest.h), the generated GLSL prelude and a generic multi-pass GL executor
 * (usertech.h, docs/techniques.md). */
#include "realtime/usertech.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/memlimit.h"
#include "core/optics.h"
#include "gl/gl.h"
#include "realtime/frame.h"
#include "realtime/caustics.h"
#include "realtime/readback.h"
#include "realtime/scenecolour.h"
#include "realtime/scenegl.h"
#include "realtime/shaders.h"
#include "realtime/toolkit.h"
#include "realtime/usertech_manifest.h"
#include "realtime/volume.h"


/* ---- class callbacks (declared here, GL part below) ------------------------------------- */

static gr_status ut_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err);
static void ut_destroy(void *state);
static gr_status ut_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err);
static gr_status ut_metadata(void *state, const gr_scene *scene, const void *settings, const gr_technique_stats *stats,
                             gr_metadata *meta, gr_error *err);
static gr_status ut_read_target(void *state, gr_image **out, gr_error *err);
static void ut_set_reuse(void *state, int on);

/* Settings of a user technique have no scene-derived defaults: resolving is a copy. */
static void ut_resolve(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out)
{
    (void)scene;
    memmove(out, in, cls->settings_size);
}

int gr_usertech_is_user(const gr_technique_class *cls) { return cls && cls->create == ut_create; }

void gr_usertech_free(gr_technique_class *cls)
{
    if (!gr_usertech_is_user(cls)) return;
    gr_ut_manifest_free((gr_ut_manifest *)cls->class_data);
}

gr_status gr_usertech_load(const char *dir, gr_technique_class **out, gr_error *err)
{
    *out = NULL;
    gr_ut_manifest *m = NULL;
    gr_status st = gr_ut_manifest_load(dir, &m, err);
    if (st != GR_OK) return st;
    gr_technique_class *cls = &m->cls;
    cls->name = m->name;
    cls->description = m->description;
    cls->params = &m->table;
    cls->settings_size = m->settings_size;
    cls->origin = m->path;
    cls->class_data = m;
    cls->ladder = m->n_ladder ? m->ladder : NULL;
    cls->n_ladder = m->n_ladder;
    cls->check = NULL;
    cls->resolve = ut_resolve;
    cls->create = ut_create;
    cls->destroy = ut_destroy;
    cls->render = ut_render;
    cls->metadata = ut_metadata;
    cls->read_target = ut_read_target;
    cls->set_reuse = ut_set_reuse;
    *out = cls;
    return GR_OK;
}

gr_status gr_technique_add_dir(const char *dir, gr_error *err)
{
    gr_technique_class *cls = NULL;
    gr_status st = gr_usertech_load(dir, &cls, err);
    if (st) return st;
    const gr_technique_class *old = gr_technique_find(cls->name);
    if (old) {
        st = gr_fail(err, GR_E_INPUT, "%s: name: '%s' is already a technique (%s)", cls->origin, cls->name,
                     old->origin ? old->origin : "built-in");
        gr_usertech_free(cls);
        return st;
    }
    if ((st = gr_technique_register(cls, err)) != GR_OK) {
        gr_error_prefix(err, "%s: name", cls->origin);
        gr_usertech_free(cls);
        return st;
    }
    /* registered classes live as long as the process (the registry keeps the pointer) */
    return GR_OK;
}

/* ---- the GLSL prelude --------------------------------------------------------------------- */

/* Every harness uniform: enum id, GLSL declaration. docs/techniques.md lists the same names
 * (tests/unit/test_usertech_doc.c checks that each is documented there). */
#define GR_UT_UNIFORMS(X)                                                   \
    X(RESOLUTION, "vec2 u_resolution")                                   \
    X(TARGET_SIZE, "vec2 u_target_size")                                 \
    X(TIME, "float u_time")                                              \
    X(PASS, "int u_pass")                                                \
    X(VIEW, "mat4 u_view")                                               \
    X(PROJ, "mat4 u_proj")                                               \
    X(VIEW_PROJ, "mat4 u_view_proj")                                     \
    X(INV_VIEW_PROJ, "mat4 u_inv_view_proj")                             \
    X(EYE, "vec3 u_eye")                                                 \
    X(CAM_FORWARD, "vec3 u_cam_forward")                                 \
    X(CAM_RIGHT, "vec3 u_cam_right")                                     \
    X(CAM_UP, "vec3 u_cam_up")                                           \
    X(FOV_Y, "float u_fov_y")                                            \
    X(ASPECT, "float u_aspect")                                          \
    X(NEAR, "float u_near")                                              \
    X(FAR, "float u_far")                                                \
    X(TO_SUN, "vec3 u_to_sun")                                           \
    X(SUN_DIR, "vec3 u_sun_dir")                                         \
    X(REFR_DIR, "vec3 u_refr_dir")                                       \
    X(TO_REFR_SUN, "vec3 u_to_refr_sun")                                 \
    X(SUN_IRRADIANCE, "vec3 u_sun_irradiance")                           \
    X(TRANSMITTANCE_FLAT, "float u_transmittance_flat")                  \
    X(SUN_ANGULAR_RADIUS, "float u_sun_angular_radius")                  \
    X(SUN_NDC, "vec2 u_sun_ndc")                                         \
    X(SUN_UV, "vec2 u_sun_uv")                                           \
    X(SUN_CLIP_W, "float u_sun_clip_w")                                  \
    X(SUN_COS_VIEW, "float u_sun_cos_view")                              \
    X(SNELL_HALF_ANGLE, "float u_snell_half_angle")                      \
    X(REST_HEIGHT, "float u_rest_height")                                \
    X(N_WAVES, "int u_n_waves")                                          \
    X(WAVE_A, "vec4 u_wave_a[GR_MAX_WAVES]")                             \
    X(WAVE_B, "vec4 u_wave_b[GR_MAX_WAVES]")                             \
    X(WAVE_GROUPS, "int u_wave_groups")                                  \
    X(WAVES, "vec4 u_waves[GR_MAX_WAVES / 4 * 5]")                       \
    X(ABSORPTION, "vec3 u_absorption")                                   \
    X(SCATTERING, "vec3 u_scattering")                                   \
    X(EXTINCTION, "vec3 u_extinction")                                   \
    X(G, "float u_g")                                                    \
    X(IOR, "float u_ior")                                                \
    X(SEABED_Y, "float u_seabed_y")                                      \
    X(LIGHT_VIEW_PROJ, "mat4 u_light_view_proj")                         \
    X(SHADOW_HALF_EXTENT, "float u_shadow_half_extent")                  \
    X(LIGHT_RADIANCE, "vec3 u_sun_light_radiance")                           \
    X(LIGHT_UNITS, "vec3 u_sun_light_units")                                 \
    X(LIGHT_SIZE, "vec2 u_sun_light_size")                               \
    X(CAUSTIC_LAYERS, "int u_caustic_layers")                            \
    X(CAUSTIC_DEPTH, "float u_caustic_depth[64]")                        \
    X(CAUSTIC_ORIGIN, "vec2 u_caustic_origin")                           \
    X(CAUSTIC_PATCH, "float u_caustic_patch")                            \
    X(CAUSTIC_TEXEL, "float u_caustic_texel")                            \
    X(CAUSTIC_SUN_RW, "float u_caustic_sun_rw")                          \
    X(SCENE_COLOUR_RADIANCE, "vec3 u_scene_colour_radiance")             \
    X(SCENE_COLOUR_SIZE, "vec2 u_scene_colour_size")

enum {
#define X(id, decl) U_##id,
    GR_UT_UNIFORMS(X)
#undef X
    U_COUNT
};
static const char *const ut_uniform_decl[U_COUNT] = {
#define X(id, decl) decl,
    GR_UT_UNIFORMS(X)
#undef X
};

/* Full-screen triangle from gl_VertexID (no vertex buffer): v_uv covers [0, 1]^2 on screen. */
static const char ut_fullscreen_vs[] =
    "out vec2 v_uv;\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n"
    "    v_uv = p;\n"
    "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
    "}\n";

/* Helpers every stage gets (docs/techniques.md "Helper functions"). */
static const char ut_helpers[] =
    "// Henyey-Greenstein phase function (1/sr), seed 000 eq. 5.5.4 with its 1/(4 pi).\n"
    "float gr_hg(float cos_theta, float g) {\n"
    "    float d = max(1.0 + g * g - 2.0 * g * cos_theta, 1e-6);\n"
    "    return (1.0 - g * g) / (4.0 * GR_PI * d * sqrt(d));\n"
    "}\n"
    "// World-space unit view ray through uv in [0,1]^2 of the frame (x right, y up).\n"
    "vec3 gr_view_ray(vec2 uv) {\n"
    "    float t = tan(0.5 * u_fov_y);\n"
    "    vec2 ndc = uv * 2.0 - 1.0;\n"
    "    return normalize(u_cam_forward + ndc.x * t * u_aspect * u_cam_right + ndc.y * t * u_cam_up);\n"
    "}\n"
    "// Distance along dir from p to the water at rest (y = u_rest_height); -1 if it never gets there.\n"
    "float gr_dist_to_surface(vec3 p, vec3 dir) {\n"
    "    return dir.y > 1e-6 ? (u_rest_height - p.y) / dir.y : -1.0;\n"
    "}\n"
    "// Gerstner surface normal at rest position xz (seed eq. 5.5.8 with the per-wave packing).\n"
    "vec3 gr_water_normal(vec2 xz) {\n"
    "    vec3 tx = vec3(1.0, 0.0, 0.0), tz = vec3(0.0, 0.0, 1.0);\n"
    "    for (int i = 0; i < u_n_waves; i++) {\n"
    "        vec4 a = u_wave_a[i], b = u_wave_b[i];\n"
    "        float ph = a.z * dot(a.xy, xz) - a.w * u_time + b.y;\n"
    "        float s = sin(ph), c = cos(ph), ak = b.x * a.z;\n"
    "        tx += ak * vec3(-a.x * a.x * c, -a.x * s, -a.x * a.y * c);\n"
    "        tz += ak * vec3(-a.x * a.y * c, -a.y * s, -a.y * a.y * c);\n"
    "    }\n"
    "    return normalize(cross(tz, tx));\n"
    "}\n";

static const char ut_shadow_helper[] =
    "// 1 where world point p is lit along the refracted sun, 0 in an occluder's shadow\n"
    "// (outside the map: lit). bias in window depth units, e.g. 1e-3.\n"
    "float gr_shadow(vec3 p, float bias) {\n"
    "    vec4 c = u_light_view_proj * vec4(p, 1.0);\n"
    "    vec3 s = c.xyz / c.w * 0.5 + 0.5;\n"
    "    if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s.xy, vec2(1.0))) || s.z <= 0.0) return 1.0;\n"
    "    float d = texture(t_shadow_map, s.xy).r;  // 1: no caster in this texel\n"
    "    return (d >= 1.0 || s.z <= d + bias) ? 1.0 : 0.0;\n"
    "}\n";

static const char ut_depth_helper[] =
    "// Distance (m) from the eye to the first occluder or the seabed through uv (u_far if none).\n"
    "float gr_eye_depth(vec2 uv) { return texture(t_eye_depth, uv).r; }\n";

/* After the caustic stack's own GLSL (caustic_stack.glsl, the volume techniques' source). */
static const char ut_caustic_helper[] =
    "// Horizontal irradiance per unit E_sun at world point p, without extinction (the caustic stack;\n"
    "// flat water: cos(theta_i) F_t). Irradiance across the beam: times E_sun / mu_t, mu_t = -u_refr_dir.y.\n"
    "float gr_caustic_irradiance(vec3 p) { return gr_caustic_stack(p, u_refr_dir, u_rest_height - p.y); }\n";

static const char *glsl_version_for(int major, int minor)
{
    if (major > 4 || (major == 4 && minor >= 5)) return "450 core";
    if (major == 4 && minor >= 3) return "430 core";
    return "330 core";
}

/* Prelude of pass ps, stage 0 = vertex, 1 = fragment. */
static char *make_prelude(const gr_ut_manifest *m, const gr_ut_pass *ps, int frag, const char *version)
{
    gr_ut_strbuf b = {0};
    gr_ut_sb_add(&b, "#version %s\n", version);
    gr_ut_sb_add(&b, "// ---- godrays harness prelude (docs/techniques.md): technique '%s', pass '%s', %s stage\n", m->name,
           ps->name, frag ? "fragment" : "vertex");
    gr_ut_sb_add(&b, "#define GODRAYS 1\n#define GR_MAX_WAVES %d\n#define GR_PI 3.14159265358979\n", GR_MAX_WAVES);
    int has_in[GR_UT_N_HARNESS_INPUTS + 1] = {0}; /* by -GR_UT_IN_*: the harness inputs this pass reads */
    for (int k = 0; k < ps->n_inputs; k++)
        if (ps->inputs[k] < 0) has_in[-ps->inputs[k]] = 1;
    for (int i = 0; i < U_COUNT; i++) {
        /* a harness input's uniforms only where the pass reads it */
        if ((i == U_LIGHT_VIEW_PROJ || i == U_SHADOW_HALF_EXTENT) && !has_in[-GR_UT_IN_SHADOW_MAP]) continue;
        if ((i == U_LIGHT_RADIANCE || i == U_LIGHT_UNITS || i == U_LIGHT_SIZE) && !has_in[-GR_UT_IN_LIGHT]) continue;
        if ((i == U_SCENE_COLOUR_RADIANCE || i == U_SCENE_COLOUR_SIZE) && !has_in[-GR_UT_IN_SCENE_COLOUR]) continue;
        /* the caustic stack's uniforms come with its GLSL (caustic_stack.glsl), below */
        if (i >= U_CAUSTIC_LAYERS && i <= U_CAUSTIC_SUN_RW) continue;
        gr_ut_sb_add(&b, "uniform %s;\n", ut_uniform_decl[i]);
    }
    for (int i = 0; i < m->n_settings; i++) {
        static const char *const glsl_types[] = {"float", "int", "bool", "vec3"};
        gr_ut_sb_add(&b, "uniform %s u_set_%s;\n", glsl_types[m->settings[i].type], m->settings[i].key);
    }
    for (int k = 0; k < ps->n_inputs; k++)
        if (ps->inputs[k] != GR_UT_IN_CAUSTICS) /* a sampler2DArray, declared with its GLSL */
            gr_ut_sb_add(&b, "uniform sampler2D t_%s;\n", gr_ut_input_name(m, ps->inputs[k]));
    if (ps->defines) gr_ut_sb_add(&b, "// the pass's \"defines\"\n%s", ps->defines);
    if (frag && !ps->vertex_src) gr_ut_sb_add(&b, "in vec2 v_uv;\n");
    if (frag) gr_ut_sb_add(&b, "#define GR_FRAGMENT_STAGE 1\n");
    gr_ut_sb_add(&b, "%s", ut_helpers);
    if (has_in[-GR_UT_IN_SHADOW_MAP]) gr_ut_sb_add(&b, "%s", ut_shadow_helper);
    if (has_in[-GR_UT_IN_EYE_DEPTH]) gr_ut_sb_add(&b, "%s", ut_depth_helper);
    if (has_in[-GR_UT_IN_CAUSTICS]) {
        /* the volume techniques' own sampling code, not a copy (embedded shader) */
        char *caus = NULL;
        gr_error e;
        if (gr_shader_source(NULL, "caustic_stack.glsl", &caus, NULL, &e) != GR_OK) b.failed = 1;
        else gr_ut_sb_add(&b, "%s%s", caus, ut_caustic_helper);
        free(caus);
    }
    gr_ut_sb_add(&b, "// ---- end of the prelude\n#line 1\n");
    if (b.failed) {
        free(b.s);
        return NULL;
    }
    return b.s;
}

char *gr_usertech_prelude(const gr_technique_class *cls, int pass, const char *stage)
{
    if (!gr_usertech_is_user(cls) || !stage) return NULL;
    const gr_ut_manifest *m = cls->class_data;
    if (pass < 0 || pass >= m->n_passes) return NULL;
    return make_prelude(m, &m->passes[pass], !strcmp(stage, "fragment"), "450 core");
}

/* prelude + source, with a leading "#version" line of the source blanked (the prelude sets it;
 * line numbers stay the file's). */
static char *with_prelude(const char *prelude, const char *src)
{
    size_t lp = strlen(prelude), ls = strlen(src);
    char *out = malloc(lp + ls + 2);
    if (!out) return NULL;
    memcpy(out, prelude, lp);
    memcpy(out + lp, src, ls + 1);
    /* #version may follow comments and blank lines only (GLSL 4.50 section 3.3) */
    char *q = out + lp;
    for (;;) {
        while (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r') q++;
        if (q[0] == '/' && q[1] == '/') {
            while (*q && *q != '\n') q++;
        } else if (q[0] == '/' && q[1] == '*') {
            char *e = strstr(q + 2, "*/");
            if (!e) break;
            q = e + 2;
        } else {
            break;
        }
    }
    if (!strncmp(q, "#version", 8))
        while (*q && *q != '\n') *q++ = ' ';
    return out;
}

/* ---- compiler errors in the user's own files and lines -------------------------------------- */

static int edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 63 || lb > 63) return 99;
    int d[64][64];
    for (size_t i = 0; i <= la; i++) d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++) d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int sub = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            int del = d[i - 1][j] + 1, ins = d[i][j - 1] + 1;
            d[i][j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
        }
    return d[la][lb];
}

/* A hint for an undeclared identifier `name` in pass p: a harness texture or target the pass
 * does not list in its inputs, or the nearest uniform (harness or setting) to a misspelt one. */
static void undeclared_hint(const gr_ut_manifest *m, int p, const char *name, gr_ut_strbuf *b)
{
    if (!strncmp(name, "t_", 2)) {
        const char *in = name + 2;
        int known = gr_ut_harness_input(in) < 0;
        for (int t = 0; t < m->n_targets && !known; t++) known = !strcmp(m->targets[t].name, in);
        if (known) {
            gr_ut_sb_add(b, " (hint: add \"%s\" to passes[%d].inputs in %s)", in, p, m->path);
            return;
        }
    }
    char best[64] = "";
    int bd = 99;
    for (int i = 0; i < U_COUNT + m->n_settings; i++) {
        char cand[64];
        if (i < U_COUNT) {
            const char *sp = strchr(ut_uniform_decl[i], ' ') + 1;
            snprintf(cand, sizeof cand, "%.*s", (int)strcspn(sp, "["), sp);
        } else {
            snprintf(cand, sizeof cand, "u_set_%s", m->settings[i - U_COUNT].key);
        }
        int d = edit_distance(name, cand);
        if (d < bd) {
            bd = d;
            snprintf(best, sizeof best, "%s", cand);
        }
    }
    int len = (int)strlen(name);
    if (bd <= (len > 12 ? 3 : 2)) gr_ut_sb_add(b, " (did you mean %s?)", best);
    else if (!strncmp(name, "u_set_", 6))
        gr_ut_sb_add(b, " (%s has no setting '%s': settings are u_set_KEY for KEY in \"settings\")", m->name, name + 6);
}

/* One driver diagnostic line mapped to "FILE:LINE:COL: message" (Mesa "S:L(C): msg", NVIDIA
 * "S(L) : msg"; anything else verbatim), line numbers through GR_UT_LINE_BASE to the file. */
static void map_log_line(const gr_ut_manifest *m, int p, const char *stage_file, const char *ln, gr_ut_strbuf *b)
{
    unsigned src = 0, line = 0, col = 0;
    int n = 0;
    const char *msg = NULL;
    if (sscanf(ln, "%u:%u(%u): %n", &src, &line, &col, &n) == 3 && n > 0) msg = ln + n;
    else if (sscanf(ln, "%u(%u) : %n", &src, &line, &n) == 2 && n > 0) msg = ln + n;
    if (!msg) {
        gr_ut_sb_add(b, "\n  %s", ln);
        return;
    }
    unsigned k = line / GR_UT_LINE_BASE;
    char file[600];
    if (k >= 1 && (int)k <= m->n_files) snprintf(file, sizeof file, "%s/%s", m->dir, m->files[k - 1]);
    else snprintf(file, sizeof file, "%s", stage_file); /* the prelude or the built-in vertex shader */
    gr_ut_sb_add(b, "\n  %s:%u:%u: %s", file, line % GR_UT_LINE_BASE, col, msg);
    /* Mesa: "`name' undeclared"; NVIDIA: "undefined variable \"name\"" */
    const char *q = strstr(msg, "`");
    char name[64] = "";
    if (q && strstr(msg, "undeclared")) sscanf(q + 1, "%63[A-Za-z0-9_]", name);
    else if ((q = strstr(msg, "undefined variable \"")) != NULL) sscanf(q + 20, "%63[A-Za-z0-9_]", name);
    if (name[0]) undeclared_hint(m, p, name, b);
}

/* Compiles one stage; on failure the driver's log, one diagnostic per line. */
static gr_status compile_stage(const gr_ut_manifest *m, int p, unsigned type, const char *src, const char *label,
                               GLuint *out, gr_error *err)
{
    const gr_ut_pass *ps = &m->passes[p];
    const int frag = type == GL_FRAGMENT_SHADER;
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (ok) {
        *out = sh;
        return GR_OK;
    }
    char log[8192] = "", stage_file[600];
    glGetShaderInfoLog(sh, (GLsizei)sizeof log, NULL, log);
    glDeleteShader(sh);
    if (frag || ps->vertex_file) snprintf(stage_file, sizeof stage_file, "%s (prelude)", label);
    else snprintf(stage_file, sizeof stage_file, "built-in full-screen triangle");
    gr_ut_strbuf b = {0};
    int lines = 0, left = 0, cands = 0;
    for (char *ln = strtok(log, "\n"); ln; ln = strtok(NULL, "\n")) {
        if (!ln[0]) continue;
        lines++;
        /* Mesa lists every overload of a builtin as "error:    vec4 texture(...)": counted, not shown */
        const char *e = strstr(ln, "error:    ");
        if (e && e[10] != ' ' && e[10]) {
            cands++;
            continue;
        }
        /* whole lines only, within the message's room */
        if (b.len > GR_ERROR_MSG_MAX - 300) {
            left++;
            continue;
        }
        map_log_line(m, p, stage_file, ln, &b);
    }
    if (cands) gr_ut_sb_add(&b, "\n  (%d candidate overload%s listed by the driver left out)", cands, cands == 1 ? "" : "s");
    if (left) gr_ut_sb_add(&b, "\n  ... %d more line%s", left, left == 1 ? "" : "s");
    /* The one exception to one-line errors (issue 29): a compiler's log is a list, one
     * "FILE:LINE:COL: message" per line as editors and CI logs read them, after a summary
     * line. gr_fail joins lines, so the message is written here. */
    gr_status st = gr_fail(err, GR_E_GL, "%s: passes[%d] '%s': %s shader does not compile", m->path, p, ps->name,
                           frag ? "fragment" : "vertex");
    if (err)
        snprintf(err->msg, sizeof err->msg, "%s: passes[%d] '%s': %s shader does not compile (%d line%s of the driver's log):%s",
                 m->path, p, ps->name, frag ? "fragment" : "vertex", lines, lines == 1 ? "" : "s", b.s ? b.s : " (empty)");
    free(b.s);
    return st;
}

static gr_status build_program(const gr_ut_manifest *m, int p, const char *label, const char *vs, const char *fs,
                               GLuint *prog, gr_error *err)
{
    GLuint v = 0, f = 0;
    *prog = 0;
    gr_status st = compile_stage(m, p, GL_VERTEX_SHADER, vs, label, &v, err);
    if (st == GR_OK) st = compile_stage(m, p, GL_FRAGMENT_SHADER, fs, label, &f, err);
    if (st != GR_OK) {
        if (v) glDeleteShader(v);
        return st;
    }
    /* linking: the toolkit's (gl/glctx.h), whose message is one line */
    return gr_gl_link_program(label, v, f, prog, err);
}

/* ---- instances ------------------------------------------------------------------------------ */

typedef struct ut_prog_locs {
    GLint u[U_COUNT];
    gr_vol_caustic_locs caus; /* caustic_stack.glsl's, set by the volume code's function */
    GLint set[GR_UT_MAX_SETTINGS];
    GLint in[GR_UT_MAX_INPUTS];
} ut_prog_locs;

typedef struct ut_state {
    const gr_ut_manifest *m;
    gr_gl *gl;
    gr_scenegl *sgl;
    GLuint prog[GR_UT_MAX_PASSES];
    ut_prog_locs locs[GR_UT_MAX_PASSES];
    GLuint vao;
    gr_target tgt[GR_UT_MAX_TARGETS];
    gr_light_pass light_pass; /* the toolkit's: the "sun_light" input, as radial_blur's light pass */
    gr_target light;
    gr_caustics *caus;        /* the "caustics" input: the volume techniques' stack */
    gr_caustics_params cp;    /* of its last build */
    gr_scene_colour scol;     /* the "scene_colour" input (realtime/scenecolour.h) */
    int scol_ready;
    gr_target scol_tgt;
    GLuint q_samples[GR_UT_MAX_PASSES];
    gr_gl_timer timer;
    int timer_ready;
    gr_readback rb;
    /* what the last render did, for metadata */
    long long samples[GR_UT_MAX_PASSES];
    int last_w[GR_UT_MAX_TARGETS], last_h[GR_UT_MAX_TARGETS];
    double shadow_size, shadow_half_extent;
} ut_state;

static gr_status ut_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)opts; /* a user technique's shaders are its folder's; --shader-dir does not apply */
    *state = NULL;
    const gr_ut_manifest *m = cls->class_data;
    ut_state *s = calloc(1, sizeof *s);
    if (!s) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", m->name);
    s->m = m;
    s->gl = gl;
    gr_status st = GR_OK;
    int major = 4, minor = 5;
    gr_gl_context_version(gl, &major, &minor);
    const char *version = glsl_version_for(major, minor);
    for (int p = 0; p < m->n_passes; p++) {
        const gr_ut_pass *ps = &m->passes[p];
        char *pv = make_prelude(m, ps, 0, version), *pf = make_prelude(m, ps, 1, version);
        char *vs = pv ? with_prelude(pv, ps->vertex_src ? ps->vertex_src : ut_fullscreen_vs) : NULL;
        char *fs = pf ? with_prelude(pf, ps->fragment_src) : NULL;
        free(pv);
        free(pf);
        if (!vs || !fs) {
            free(vs);
            free(fs);
            st = gr_fail(err, GR_E_NOMEM, "%s: out of memory", m->name);
            goto fail;
        }
        char label[600];
        snprintf(label, sizeof label, "%s: passes[%d] '%s' (vertex %s%s%s, fragment %s/%s)", m->path, p, ps->name,
                 ps->vertex_file ? m->dir : "", ps->vertex_file ? "/" : "",
                 ps->vertex_file ? ps->vertex_file : "built-in full-screen triangle", m->dir, ps->fragment_file);
        st = build_program(m, p, label, vs, fs, &s->prog[p], err);
        free(vs);
        free(fs);
        if (st) goto fail;
        ut_prog_locs *l = &s->locs[p];
        for (int i = 0; i < U_COUNT; i++) {
            /* "type name[...]" -> "name" */
            char nm[64];
            const char *sp = strchr(ut_uniform_decl[i], ' ') + 1;
            size_t n = strcspn(sp, "[");
            snprintf(nm, sizeof nm, "%.*s", (int)n, sp);
            l->u[i] = glGetUniformLocation(s->prog[p], nm);
        }
        for (int i = 0; i < m->n_settings; i++) {
            char nm[64];
            snprintf(nm, sizeof nm, "u_set_%s", m->settings[i].key);
            l->set[i] = glGetUniformLocation(s->prog[p], nm);
        }
        for (int k = 0; k < ps->n_inputs; k++) {
            char nm[64];
            snprintf(nm, sizeof nm, "t_%s", gr_ut_input_name(m, ps->inputs[k]));
            l->in[k] = glGetUniformLocation(s->prog[p], nm);
        }
        gr_vol_caustic_locations(s->prog[p], &l->caus);
    }
    if (m->uses_shadow_map || m->uses_eye_depth || m->uses_light || m->uses_scene_colour) {
        if ((st = gr_scenegl_create(gl, &s->sgl, err)) != GR_OK) goto fail;
    }
    if (m->uses_light && (st = gr_light_pass_init(&s->light_pass, NULL, err)) != GR_OK) goto fail;
    if ((m->uses_caustics || m->uses_scene_colour) && (st = gr_caustics_create(NULL, &s->caus, err)) != GR_OK) goto fail;
    if (m->uses_scene_colour) {
        s->scol_ready = 1;
        if ((st = gr_scene_colour_init(&s->scol, NULL, err)) != GR_OK) goto fail;
    }
    glGenVertexArrays(1, &s->vao);
    glGenQueries(m->n_passes, s->q_samples);
    gr_gl_timer_init(&s->timer);
    s->timer_ready = 1;
    if ((st = gr_gl_check(m->name, err)) != GR_OK) goto fail;
    *state = s;
    return GR_OK;
fail:
    ut_destroy(s);
    return st;
}

static void ut_destroy(void *state)
{
    ut_state *s = state;
    if (!s) return;
    gr_gl_make_current(s->gl, NULL);
    for (int p = 0; p < GR_UT_MAX_PASSES; p++)
        if (s->prog[p]) glDeleteProgram(s->prog[p]);
    for (int t = 0; t < GR_UT_MAX_TARGETS; t++) gr_target_release(&s->tgt[t]);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->q_samples[0]) glDeleteQueries(s->m->n_passes, s->q_samples);
    if (s->timer_ready) gr_gl_timer_free(&s->timer);
    gr_scenegl_destroy(s->sgl);
    gr_light_pass_free(&s->light_pass);
    gr_target_release(&s->light);
    gr_caustics_destroy(s->caus);
    if (s->scol_ready) gr_scene_colour_free(&s->scol);
    gr_target_release(&s->scol_tgt);
    gr_readback_free(&s->rb);
    free(s);
}

static double setting_number(const gr_ut_manifest *m, const void *settings, int i)
{
    return gr_param_get_number(&m->params[i], settings, 0);
}

static double value_of(const gr_ut_manifest *m, const void *settings, const gr_ut_value *v)
{
    return v->setting >= 0 ? setting_number(m, settings, v->setting) : v->v;
}

static long long count_of(const gr_ut_manifest *m, const void *settings, const gr_ut_count *c)
{
    long long n = c->literal;
    for (int i = 0; i < c->n_factors; i++) {
        n *= (long long)setting_number(m, settings, c->factor[i]);
        if (n > 2000000000LL) return 2000000001LL;
    }
    return n;
}

static gr_status ensure_target(ut_state *s, int t, int w, int h, gr_error *err)
{
    static const GLenum fmts[] = {GL_RGBA8, GL_RGBA16F, GL_RGBA32F};
    const gr_ut_target *tg = &s->m->targets[t];
    char what[600];
    snprintf(what, sizeof what, "%s: targets.%s (%s)", s->m->path, tg->name, gr_ut_format_names[tg->format]);
    return gr_target_ensure(&s->tgt[t], fmts[tg->format], w, h, tg->linear ? GR_TARGET_LINEAR : 0, what, err);
}

/* The "caustics" object's values at these settings as the volume techniques' settings block
 * (its caustic fields; their descriptors check the ranges and caustic_last_m >= caustic_first_m:
 * GR_E_INPUT naming NAME.caustics.KEY). */
static gr_status caustic_block(const gr_ut_manifest *m, const void *settings, gr_vol_settings *vs, gr_error *err)
{
    size_t n = 0;
    const gr_param *d = gr_vol_caustic_descriptors(&n);
    char section[64];
    snprintf(section, sizeof section, "%s.caustics", m->name);
    const gr_param_table tab = {section, d, n};
    memset(vs, 0, sizeof *vs);
    for (size_t i = 0; i < n && (int)i < m->n_caustic_values; i++) {
        gr_status st = gr_param_set_number(&tab, vs, d[i].name, -1, value_of(m, settings, &m->caustic[i]), err);
        if (st != GR_OK) return st;
    }
    return gr_vol_check(section, vs, err);
}

/* The render's memory before any target is made (docs/reliability.md, issue 31 finding 5: five
 * 8192^2 rgba32f targets, 7.6 GB, were made under a 1 GB limit): every target at its size and
 * format, the readback (RGBA float per pixel) and the harness inputs (the shadow map's 32-bit
 * depth; the eye depth's R32F texture and its 32-bit depth buffer). */
static gr_status check_memory(const ut_state *s, const void *settings, const gr_vol_settings *vs, int W, int H,
                              const int *tw, const int *th, gr_error *err)
{
    static const double px_bytes[] = {4, 8, 16}; /* rgba8, rgba16f, rgba32f */
    const gr_ut_manifest *m = s->m;
    double need = 16.0 * W * H;
    for (int t = 0; t < m->n_targets; t++) need += px_bytes[m->targets[t].format] * tw[t] * (double)th[t];
    if (m->uses_shadow_map) {
        double size = value_of(m, settings, &m->shadow_size);
        need += 4.0 * size * size;
    }
    if (m->uses_eye_depth) need += 8.0 * W * H;
    if (m->uses_light) { /* its target and its eye depth */
        double sc = value_of(m, settings, &m->light_scale);
        need += (px_bytes[m->light_format] + 8.0) * (W * sc + 1) * (H * sc + 1);
    }
    if (m->uses_scene_colour) { /* its target and its eye depth; the shadow map */
        double sc = value_of(m, settings, &m->scol_scale);
        need += (px_bytes[m->scol_format] + 8.0) * (W * sc + 1) * (H * sc + 1);
        if (!m->uses_shadow_map) {
            double size = value_of(m, settings, &m->shadow_size);
            need += 4.0 * size * size;
        }
    }
    if (m->uses_caustics || m->uses_scene_colour) { /* R32F layers at twice the size, mip chain (4/3) */
        double side = 2.0 * vs->texture_size;
        need += 4.0 * side * side * vs->caustic_depths * 4.0 / 3.0;
    }
    char what[96], detail[64];
    snprintf(what, sizeof what, "technique %s", m->name);
    snprintf(detail, sizeof detail, "%d render target%s, readback and harness inputs", m->n_targets,
             m->n_targets == 1 ? "" : "s");
    return gr_memlimit_check(what, need, detail, err);
}

static void set_matrix(GLint loc, const double m[16])
{
    float f[16];
    if (loc < 0) return;
    gr_frame_matf(m, f);
    glUniformMatrix4fv(loc, 1, GL_FALSE, f);
}

static void set3(GLint loc, const double v[3])
{
    if (loc >= 0) glUniform3f(loc, (float)v[0], (float)v[1], (float)v[2]);
}

typedef struct ut_frame_inputs {
    gr_frame f;
    double light_vp[16];
    double shadow_half_extent;
    GLuint shadow_tex, depth_tex;
    double light_radiance[3], light_units[3];
    double scol_radiance[3];
    int sun_disc; /* the caustic stack read with the sun disc's blur */
} ut_frame_inputs;

static void set_uniforms(const ut_state *s, int p, const ut_frame_inputs *fi, const void *settings, int tw, int th)
{
    const ut_prog_locs *l = &s->locs[p];
    const gr_frame *f = &fi->f;
    const GLint *u = l->u;
#define F1(id, v) \
    if (u[U_##id] >= 0) glUniform1f(u[U_##id], (float)(v))
    if (u[U_RESOLUTION] >= 0) glUniform2f(u[U_RESOLUTION], (float)f->width, (float)f->height);
    if (u[U_TARGET_SIZE] >= 0) glUniform2f(u[U_TARGET_SIZE], (float)tw, (float)th);
    F1(TIME, f->time_s);
    if (u[U_PASS] >= 0) glUniform1i(u[U_PASS], p);
    set_matrix(u[U_VIEW], f->view);
    set_matrix(u[U_PROJ], f->proj);
    set_matrix(u[U_VIEW_PROJ], f->view_proj);
    set_matrix(u[U_INV_VIEW_PROJ], f->inv_view_proj);
    set3(u[U_EYE], f->eye);
    set3(u[U_CAM_FORWARD], f->forward);
    set3(u[U_CAM_RIGHT], f->right);
    set3(u[U_CAM_UP], f->up);
    F1(FOV_Y, f->fov_y_rad);
    F1(ASPECT, f->aspect);
    F1(NEAR, GR_FRAME_NEAR_M);
    F1(FAR, GR_FRAME_FAR_M);
    set3(u[U_TO_SUN], f->to_sun);
    set3(u[U_SUN_DIR], f->sun_dir);
    set3(u[U_REFR_DIR], f->refr_dir);
    set3(u[U_TO_REFR_SUN], f->to_refr_sun);
    set3(u[U_SUN_IRRADIANCE], f->sun_irradiance);
    F1(TRANSMITTANCE_FLAT, f->transmittance_flat);
    F1(SUN_ANGULAR_RADIUS, f->sun_angular_radius_rad);
    if (u[U_SUN_NDC] >= 0) glUniform2f(u[U_SUN_NDC], (float)f->sun_ndc[0], (float)f->sun_ndc[1]);
    if (u[U_SUN_UV] >= 0) glUniform2f(u[U_SUN_UV], (float)f->sun_uv[0], (float)f->sun_uv[1]);
    F1(SUN_CLIP_W, f->sun_clip_w);
    F1(SUN_COS_VIEW, f->sun_cos_view);
    F1(SNELL_HALF_ANGLE, f->snell_half_angle_rad);
    F1(REST_HEIGHT, f->rest_height_m);
    if (u[U_N_WAVES] >= 0) glUniform1i(u[U_N_WAVES], f->n_waves);
    if (u[U_WAVE_A] >= 0) glUniform4fv(u[U_WAVE_A], GR_MAX_WAVES, &f->waves_a[0][0]);
    if (u[U_WAVE_B] >= 0) glUniform4fv(u[U_WAVE_B], GR_MAX_WAVES, &f->waves_b[0][0]);
    if (u[U_WAVE_GROUPS] >= 0) glUniform1i(u[U_WAVE_GROUPS], f->n_wave_groups);
    if (u[U_WAVES] >= 0) glUniform4fv(u[U_WAVES], GR_MAX_WAVES / 4 * 5, &f->waves_seed[0][0]);
    set3(u[U_ABSORPTION], f->absorption);
    set3(u[U_SCATTERING], f->scattering);
    set3(u[U_EXTINCTION], f->extinction);
    F1(G, f->g);
    F1(IOR, f->ior);
    F1(SEABED_Y, f->seabed_y);
    set_matrix(u[U_LIGHT_VIEW_PROJ], fi->light_vp);
    F1(SHADOW_HALF_EXTENT, fi->shadow_half_extent);
    set3(u[U_LIGHT_RADIANCE], fi->light_radiance);
    set3(u[U_LIGHT_UNITS], fi->light_units);
    if (u[U_LIGHT_SIZE] >= 0) glUniform2f(u[U_LIGHT_SIZE], (float)s->light.w, (float)s->light.h);
    set3(u[U_SCENE_COLOUR_RADIANCE], fi->scol_radiance);
    if (u[U_SCENE_COLOUR_SIZE] >= 0) glUniform2f(u[U_SCENE_COLOUR_SIZE], (float)s->scol_tgt.w, (float)s->scol_tgt.h);
#undef F1
    const gr_ut_manifest *m = s->m;
    for (int i = 0; i < m->n_settings; i++) {
        GLint loc = l->set[i];
        if (loc < 0) continue;
        const gr_param *gp = &m->params[i];
        switch (m->settings[i].type) {
        case GR_UT_NUMBER: glUniform1f(loc, (float)gr_param_get_number(gp, settings, 0)); break;
        case GR_UT_INT:
        case GR_UT_BOOL: glUniform1i(loc, (int)gr_param_get_number(gp, settings, 0)); break;
        case GR_UT_RGB:
            glUniform3f(loc, (float)gr_param_get_number(gp, settings, 0), (float)gr_param_get_number(gp, settings, 1),
                        (float)gr_param_get_number(gp, settings, 2));
            break;
        }
    }
    const gr_ut_pass *ps = &m->passes[p];
    for (int k = 0; k < ps->n_inputs; k++) {
        int in = ps->inputs[k];
        if (in == GR_UT_IN_CAUSTICS) {
            /* world positions: the frame's origin is the world's */
            gr_vol_caustic_set(&l->caus, s->caus, &s->cp, f, fi->sun_disc, 0.0, 0.0, k);
            continue;
        }
        glActiveTexture(GL_TEXTURE0 + (GLenum)k);
        glBindTexture(GL_TEXTURE_2D, in == GR_UT_IN_SHADOW_MAP  ? fi->shadow_tex
                                     : in == GR_UT_IN_EYE_DEPTH ? fi->depth_tex
                                     : in == GR_UT_IN_LIGHT     ? s->light.tex
                                     : in == GR_UT_IN_SCENE_COLOUR ? s->scol_tgt.tex
                                                                : s->tgt[in].tex);
        if (l->in[k] >= 0) glUniform1i(l->in[k], k);
    }
    glActiveTexture(GL_TEXTURE0);
}

/* The "sun_light" input: the toolkit's light pass (radial_blur's) at the manifest's size, format,
 * kernel radius, threshold and occluders, over the eye depth at its size; its units. */
static gr_status light_input(ut_state *s, const gr_scene *scene, ut_frame_inputs *fi, const void *settings,
                             gr_error *err)
{
    static const GLenum fmts[] = {GL_RGBA8, GL_RGBA16F, GL_RGBA32F};
    const gr_ut_manifest *m = s->m;
    const int W = fi->f.width, H = fi->f.height;
    double sc = value_of(m, settings, &m->light_scale);
    int lw = (int)lround(W * sc), lh = (int)lround(H * sc);
    if (lw < 1) lw = 1;
    if (lh < 1) lh = 1;
    char what[600];
    snprintf(what, sizeof what, "%s: sun_light (%s)", m->path, gr_ut_format_names[m->light_format]);
    gr_status st = gr_target_ensure(&s->light, fmts[m->light_format], lw, lh, GR_TARGET_LINEAR | GR_TARGET_BLACK_BORDER,
                                    what, err);
    if (st) return st;
    unsigned depth_tex = 0;
    if ((st = gr_scenegl_eye_depth(s->sgl, scene, &fi->f, lw, lh, &depth_tex, err))) return st;
    const gr_light_params lp = {.radius_deg = value_of(m, settings, &m->light_radius_deg),
                                .threshold = value_of(m, settings, &m->light_threshold),
                                .occluders = m->light_occluders,
                                .dither8 = 0};
    if ((st = gr_light_pass_draw(&s->light_pass, scene, &fi->f, &lp, &s->light, depth_tex, m->name, err))) return st;
    static const double one[3] = {1, 1, 1};
    gr_light_radiance(&fi->f, lp.radius_deg, fi->light_radiance);
    /* seed 004's exposure 0.2 and sample scale 0.4, fade 1: toolkit.h gr_light_units */
    gr_light_units(scene, &fi->f, lp.radius_deg, one, 0.2, 0.4, 1.0, fi->light_units);
    glBindVertexArray(0);
    return gr_gl_check("sun_light", err);
}

/* The "scene_colour" input (realtime/scenecolour.h) at the manifest's size, format, albedo and
 * kernel radius, over the eye depth at its size, the caustic stack just built and the shadow
 * map (if any); its radiance of 1. */
static gr_status scene_colour_input(ut_state *s, const gr_scene *scene, ut_frame_inputs *fi, const void *settings,
                                    gr_error *err)
{
    static const GLenum fmts[] = {GL_RGBA8, GL_RGBA16F, GL_RGBA32F};
    const gr_ut_manifest *m = s->m;
    const int W = fi->f.width, H = fi->f.height;
    double sc = value_of(m, settings, &m->scol_scale);
    int w = (int)lround(W * sc), h = (int)lround(H * sc);
    if (w < 1) w = 1;
    if (h < 1) h = 1;
    char what[600];
    snprintf(what, sizeof what, "%s: scene_colour (%s)", m->path, gr_ut_format_names[m->scol_format]);
    gr_status st = gr_target_ensure(&s->scol_tgt, fmts[m->scol_format], w, h, GR_TARGET_LINEAR, what, err);
    if (st) return st;
    unsigned depth_tex = 0;
    if ((st = gr_scenegl_eye_depth(s->sgl, scene, &fi->f, w, h, &depth_tex, err))) return st;
    gr_scene_colour_params p = {.radius_deg = value_of(m, settings, &m->scol_radius_deg),
                                .shadow_texel_m = fi->shadow_tex ? 2.0 * fi->shadow_half_extent / s->shadow_size : 0.0};
    for (int c = 0; c < 3; c++)
        p.albedo[c] = m->scol_albedo_setting >= 0 ? gr_param_get_number(&m->params[m->scol_albedo_setting], settings, c)
                                                  : m->scol_albedo[c];
    gr_vol_inputs in;
    memset(&in, 0, sizeof in);
    in.f = &fi->f;
    in.caustics = s->caus;
    in.cp = &s->cp;
    in.sun_disc = fi->sun_disc;
    in.shadow_tex = fi->shadow_tex;
    for (int i = 0; i < 16; i++) in.light_vp[i] = fi->shadow_tex ? fi->light_vp[i] : (double)(i % 5 == 0);
    for (int c = 0; c < 3; c++) {
        in.sigma_t[c] = fi->f.extinction[c];
        in.sigma_s[c] = fi->f.scattering[c];
        in.gain[c] = 1.0;
    }
    in.g = fi->f.g;
    if ((st = gr_scene_colour_draw(&s->scol, scene, &in, &p, &s->scol_tgt, depth_tex, m->name, err))) return st;
    gr_scene_colour_radiance(&fi->f, &p, fi->scol_radiance);
    glBindVertexArray(0);
    return gr_gl_check("scene_colour", err);
}

static GLenum prim_mode(gr_ut_prim p)
{
    switch (p) {
    case GR_UT_PRIM_TRIANGLE_STRIP: return GL_TRIANGLE_STRIP;
    case GR_UT_PRIM_LINES: return GL_LINES;
    case GR_UT_PRIM_POINTS: return GL_POINTS;
    default: return GL_TRIANGLES;
    }
}

static gr_status ut_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    ut_state *s = state;
    const gr_ut_manifest *m = s->m;
    double t0 = gr_clock_ms();
    gr_status st;
    ut_frame_inputs *fi = calloc(1, sizeof *fi);
    if (!fi) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", m->name);
    gr_frame_init(scene, &fi->f);
    const int W = fi->f.width, H = fi->f.height;
    int ch[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
    if (out->width != W || out->height != H || ch[0] < 0 || ch[1] < 0 || ch[2] < 0) {
        st = gr_fail(err, GR_E_INPUT, "%s: output image is %dx%d (needs %dx%d with R, G, B channels)", m->name, out->width,
                     out->height, W, H);
        goto done;
    }
    /* target sizes and draw counts from the settings: checked before any GL work */
    int tw[GR_UT_MAX_TARGETS], th[GR_UT_MAX_TARGETS];
    for (int t = 0; t < m->n_targets; t++) {
        const gr_ut_target *tg = &m->targets[t];
        if (tg->absolute) {
            tw[t] = tg->width;
            th[t] = tg->height;
            continue;
        }
        double sc = value_of(m, settings, &tg->scale);
        tw[t] = (int)lround(W * sc);
        th[t] = (int)lround(H * sc);
        if (tw[t] < 1) tw[t] = 1;
        if (th[t] < 1) th[t] = 1;
        if (tw[t] > GR_UT_MAX_SIZE || th[t] > GR_UT_MAX_SIZE) {
            st = gr_fail(err, GR_E_INPUT, "%s.%s: target '%s' would be %dx%d (at most %d per side)", m->name,
                         tg->scale.setting >= 0 ? m->settings[tg->scale.setting].key : "scale", tg->name, tw[t], th[t],
                         GR_UT_MAX_SIZE);
            goto done;
        }
    }
    long long nv[GR_UT_MAX_PASSES], ni[GR_UT_MAX_PASSES];
    for (int p = 0; p < m->n_passes; p++) {
        const gr_ut_pass *ps = &m->passes[p];
        nv[p] = ps->fullscreen ? 3 : count_of(m, settings, &ps->vertices);
        ni[p] = ps->fullscreen ? 1 : count_of(m, settings, &ps->instances);
        if (nv[p] > 100000000LL || ni[p] > 100000000LL || nv[p] * ni[p] > 1000000000LL) {
            st = gr_fail(err, GR_E_INPUT, "%s: passes[%d] '%s': %lld vertices x %lld instances is too many for one draw",
                         m->name, p, ps->name, nv[p], ni[p]);
            goto done;
        }
    }
    gr_vol_settings vs;
    memset(&vs, 0, sizeof vs);
    if ((m->uses_caustics || m->uses_scene_colour) && (st = caustic_block(m, settings, &vs, err)) != GR_OK) goto done;
    fi->sun_disc = vs.sun_disc;
    if ((st = check_memory(s, settings, &vs, W, H, tw, th, err)) != GR_OK) goto done;
    if ((st = gr_gl_make_current(s->gl, err)) != GR_OK) goto done;
    for (int t = 0; t < m->n_targets; t++)
        if ((st = ensure_target(s, t, tw[t], th[t], err)) != GR_OK) goto done;

    gr_gl_timer_reset(&s->timer);
    /* harness inputs, timed as passes of their own */
    int slot = 0;
    char names[GR_TECH_MAX_PASSES][24];
    if (m->uses_light) {
        /* first: its eye depth (at the light's size) is remade below by "eye_depth" */
        gr_gl_timer_begin(&s->timer, slot);
        st = light_input(s, scene, fi, settings, err);
        gr_gl_timer_end(&s->timer);
        if (st) goto done;
        snprintf(names[slot++], 24, "sun_light");
    }
    /* the scene colour needs the shadow map where there are occluders, and the caustic stack */
    if (m->uses_shadow_map || (m->uses_scene_colour && scene->n_occluders > 0)) {
        int size = (int)value_of(m, settings, &m->shadow_size);
        fi->shadow_half_extent = value_of(m, settings, &m->shadow_half_extent);
        gr_gl_timer_begin(&s->timer, slot);
        /* centred on the eye: covers every point within half_extent_m of the camera */
        st = gr_scenegl_shadow_map(s->sgl, scene, &fi->f, size, fi->f.eye, fi->shadow_half_extent, &fi->shadow_tex,
                                   fi->light_vp, err);
        gr_gl_timer_end(&s->timer);
        if (st) goto done;
        snprintf(names[slot++], 24, "shadow_map");
        s->shadow_size = size;
        s->shadow_half_extent = fi->shadow_half_extent;
    }
    if (m->uses_caustics || m->uses_scene_colour) {
        /* the volume techniques' stack, its parameters derived by their function */
        gr_vol_caustics_params(&vs, &s->cp);
        gr_gl_timer_begin(&s->timer, slot);
        st = gr_caustics_build(s->caus, scene, &fi->f, &s->cp, err);
        gr_gl_timer_end(&s->timer);
        if (st) {
            gr_error_prefix(err, "%s", m->name);
            goto done;
        }
        snprintf(names[slot++], 24, "caustics");
    }
    if (m->uses_scene_colour) {
        gr_gl_timer_begin(&s->timer, slot);
        st = scene_colour_input(s, scene, fi, settings, err);
        gr_gl_timer_end(&s->timer);
        if (st) goto done;
        snprintf(names[slot++], 24, "scene_colour");
    }
    if (m->uses_eye_depth) {
        gr_gl_timer_begin(&s->timer, slot);
        st = gr_scenegl_eye_depth(s->sgl, scene, &fi->f, W, H, &fi->depth_tex, err);
        gr_gl_timer_end(&s->timer);
        if (st) goto done;
        snprintf(names[slot++], 24, "eye_depth");
    }

    int cleared[GR_UT_MAX_TARGETS] = {0}, cleared_by[GR_UT_MAX_PASSES] = {0};
    const int first_pass_slot = slot;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_DITHER); /* dithering would make 8-bit targets depend on the pixel position */
    glDepthMask(GL_FALSE);
    glBindVertexArray(s->vao);
    for (int p = 0; p < m->n_passes; p++) {
        const gr_ut_pass *ps = &m->passes[p];
        int t = ps->target;
        snprintf(names[slot], 24, "%s", ps->name);
        gr_gl_timer_begin(&s->timer, slot++);
        glBeginQuery(GL_SAMPLES_PASSED, s->q_samples[p]);
        glBindFramebuffer(GL_FRAMEBUFFER, s->tgt[t].fbo);
        glViewport(0, 0, tw[t], th[t]);
        if (!cleared[t] || ps->has_clear) {
            /* every target starts the frame at 0; "clear" clears again before this pass */
            if (ps->has_clear) glClearColor(ps->clear[0], ps->clear[1], ps->clear[2], ps->clear[3]);
            else glClearColor(0, 0, 0, 0);
            glClear(GL_COLOR_BUFFER_BIT);
            cleared[t] = 1;
            cleared_by[p] = 1;
        }
        if (ps->blend == GR_UT_BLEND_NONE) {
            glDisable(GL_BLEND);
        } else {
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_ADD);
            if (ps->blend == GR_UT_BLEND_ADDITIVE) glBlendFunc(GL_ONE, GL_ONE);
            else glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        }
        glUseProgram(s->prog[p]);
        set_uniforms(s, p, fi, settings, tw[t], th[t]);
        if (ps->prim == GR_UT_PRIM_POINTS && !ps->fullscreen) glEnable(GL_PROGRAM_POINT_SIZE);
        if (ps->fullscreen) glDrawArrays(GL_TRIANGLES, 0, 3);
        else glDrawArraysInstanced(prim_mode(ps->prim), 0, (GLsizei)nv[p], (GLsizei)ni[p]);
        glDisable(GL_PROGRAM_POINT_SIZE);
        glDisable(GL_BLEND);
        glEndQuery(GL_SAMPLES_PASSED);
        gr_gl_timer_end(&s->timer);
        for (int k = 0; k < ps->n_inputs; k++) {
            glActiveTexture(GL_TEXTURE0 + (GLenum)k);
            glBindTexture(ps->inputs[k] == GR_UT_IN_CAUSTICS ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D, 0);
        }
        glActiveTexture(GL_TEXTURE0);
        if ((st = gr_gl_check(ps->name, err)) != GR_OK) {
            gr_error_prefix(err, "%s: passes[%d]", m->path, p);
            goto unbind;
        }
        /* the time limit (technique.h): a pass's shader is the user's and may run for hours */
        char what[64];
        snprintf(what, sizeof what, "passes[%d] '%s'", p, ps->name);
        if ((st = gr_technique_wait_pass(what, err)) == GR_E_TIMEOUT) goto done;
        if (st != GR_OK) goto unbind;
    }

    /* read the output target back (GL rows bottom-up; gr_image top row first) */
    size_t bad = 0, nonzero = 0;
    if ((st = gr_readback_rgb(&s->rb, s->tgt[m->output].fbo, out, &bad, "readback", err)) != GR_OK) {
        gr_error_prefix(err, "%s: output '%s'", m->name, m->targets[m->output].name);
        goto unbind;
    }
    long long drawn = 0;
    int writers = 0;
    for (int p = 0; p < m->n_passes; p++) {
        GLuint64 v = 0;
        glGetQueryObjectui64v(s->q_samples[p], GL_QUERY_RESULT, &v);
        s->samples[p] = (long long)v;
        if (m->passes[p].target == m->output) {
            drawn += (long long)v;
            writers++;
        }
    }
    for (size_t i = 0; i < (size_t)W * H * 4 && !nonzero; i++)
        nonzero = i % 4 != 3 && isfinite(s->rb.rgba[i]) && s->rb.rgba[i] != 0;
    /* Never a silently wrong image (docs/techniques.md "Errors"). */
    if (drawn == 0) {
        st = gr_fail(err, GR_E_RUNTIME, "%s: output '%s': its pass%s drew no fragment (check the draw's vertex count, gl_Position and discard)",
                     m->name, m->targets[m->output].name, writers > 1 ? "es" : "");
        goto unbind;
    }
    if (bad) {
        st = gr_fail(err, GR_E_RUNTIME, "%s: output '%s': %zu of %d values are NaN or infinite (a division by zero or sqrt/log/pow of a negative in a shader?)",
                     m->name, m->targets[m->output].name, bad, W * H * 3);
        goto unbind;
    }
    if (!nonzero && !m->allow_black) {
        st = gr_fail(err, GR_E_RUNTIME, "%s: output '%s' is all zero (black): a uniform not set, the wrong target, or a real zero (then set \"allow_black\": true in %s)",
                     m->name, m->targets[m->output].name, m->path);
        goto unbind;
    }
    for (int t = 0; t < m->n_targets; t++) {
        s->last_w[t] = tw[t];
        s->last_h[t] = th[t];
    }
    if (stats) {
        const char *pass_names[GR_TECH_MAX_PASSES];
        for (int k = 0; k < slot; k++) pass_names[k] = names[k];
        gr_gl_timer_stats(stats, &s->timer, pass_names, slot, t0);
        stats->fragments = 0;
        for (int p = 0; p < m->n_passes; p++) stats->fragments += s->samples[p];
        static const int bpp[] = {4, 8, 16};
        /* cost counters (technique.h): the harness inputs' bytes (DEPTH32F shadow map, R32F eye
         * depth); per pass the queried fragments, the vertices drawn, the bytes of its clear
         * and of one texel per fragment; taps are the user's shader's (not counted) */
        for (int k = 0; k < first_pass_slot; k++) {
            if (!strcmp(names[k], "caustics")) { /* the stack's own counters (caustics.h) */
                gr_vol_cost_caustics(stats, k, s->caus);
                continue;
            }
            long long side = strcmp(names[k], "shadow_map") == 0 ? s->shadow_size : 0;
            long long bytes = side > 0 ? side * side * 4 : (long long)W * H * 4;
            if (!strcmp(names[k], "scene_colour")) /* its eye depth (R32F) and its target */
                bytes = (long long)s->scol_tgt.w * s->scol_tgt.h * (4 + bpp[m->scol_format]);
            gr_technique_cost_set(stats, k, GR_COST_BYTES, bytes, 0);
            gr_technique_cost_set(stats, k, GR_COST_TAPS, 0, 0);
            gr_technique_cost_set(stats, k, GR_COST_INVOCATIONS, 0, 0);
        }
        for (int p = 0; p < m->n_passes; p++) {
            const int k = first_pass_slot + p, t = m->passes[p].target, b = bpp[m->targets[t].format];
            gr_technique_cost_set(stats, k, GR_COST_FRAGMENTS, s->samples[p], 1);
            gr_technique_cost_set(stats, k, GR_COST_VERTICES, nv[p] * ni[p], 0);
            gr_technique_cost_set(stats, k, GR_COST_BYTES,
                                  (cleared_by[p] ? (long long)tw[t] * th[t] * b : 0) + s->samples[p] * b, 0);
            gr_technique_cost_set(stats, k, GR_COST_INVOCATIONS, 0, 0);
        }
        stats->wall_ms = gr_clock_ms() - t0;
    }
    st = GR_OK;
unbind:
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
done:
    free(fi);
    return st;
}

static gr_status ut_metadata(void *state, const gr_scene *scene, const void *settings, const gr_technique_stats *stats,
                             gr_metadata *meta, gr_error *err)
{
    (void)scene;
    (void)settings;
    (void)stats;
    const ut_state *s = state;
    const gr_ut_manifest *m = s->m;
    char key[96], val[64];
    gr_status st = gr_meta_set_string(meta, "godrays:user_source_hash", m->source_hash);
    for (int t = 0; st == GR_OK && t < m->n_targets; t++) {
        snprintf(key, sizeof key, "godrays:user_target.%s", m->targets[t].name);
        snprintf(val, sizeof val, "%dx%d %s", s->last_w[t], s->last_h[t], gr_ut_format_names[m->targets[t].format]);
        st = gr_meta_set_string(meta, key, val);
    }
    if (st == GR_OK && m->uses_shadow_map) {
        snprintf(val, sizeof val, "%.0f px, half extent %.9g m", s->shadow_size, s->shadow_half_extent);
        st = gr_meta_set_string(meta, "godrays:user_shadow_map", val);
    }
    if (st == GR_OK && (m->uses_caustics || m->uses_scene_colour)) {
        char cv[160];
        const gr_caustics_params *cp = &s->cp;
        snprintf(cv, sizeof cv, "%d texels, grid %d, patch %.9g m, %d depths %.9g..%.9g m", cp->size, cp->grid,
                 cp->patch_m, cp->n_depths, cp->depths_m[0], cp->depths_m[cp->n_depths > 0 ? cp->n_depths - 1 : 0]);
        st = gr_meta_set_string(meta, "godrays:user_caustics", cv);
    }
    if (st == GR_OK && m->uses_scene_colour) {
        snprintf(val, sizeof val, "%dx%d %s", s->scol_tgt.w, s->scol_tgt.h, gr_ut_format_names[m->scol_format]);
        st = gr_meta_set_string(meta, "godrays:user_scene_colour", val);
    }
    if (st != GR_OK) return gr_fail(err, st, "%s metadata: cannot add an entry (%s)", m->name, gr_status_name(st));
    return GR_OK;
}


/* `godrays render --save-target` (issue 29): every target of the last render (the harness
 * inputs first: sun_light, scene_colour, then each layer of the caustic stack, shallowest first,
 * as grey (R = G = B = the texel, alpha 1); then the manifest's targets in their order), side by
 * side in one RGBA strip, top-aligned at their own sizes, 4 black pixels apart; the metadata
 * (ut_metadata) gives each target's size, so x offsets follow from the order. */
/* A search's reuse (technique.h): the "caustics" stack (also scene_colour's) kept per frame. */
static void ut_set_reuse(void *state, int on)
{
    ut_state *s = state;
    if (s && s->caus) gr_caustics_set_reuse(s->caus, on);
}

static gr_status ut_read_target(void *state, gr_image **out, gr_error *err)
{
    ut_state *s = state;
    const gr_ut_manifest *m = s->m;
    enum { GAP = 4 };
    *out = NULL;
    const gr_target *list[GR_UT_MAX_TARGETS + 2];
    int n = 0, W = 0, H = 0, n_layers = 0, ls = 0, n_pre = 0;
    if (m->uses_light && s->light.tex) list[n++] = &s->light;
    if (m->uses_scene_colour && s->scol_tgt.tex) list[n++] = &s->scol_tgt;
    n_pre = n;
    for (int t = 0; t < m->n_targets; t++)
        if (s->tgt[t].tex) list[n++] = &s->tgt[t];
    if (s->caus && gr_caustics_texture(s->caus)) {
        n_layers = s->cp.n_depths;
        ls = s->cp.size;
    }
    if (n == 0) return gr_fail(err, GR_E_RUNTIME, "%s: no render yet, no target to read", m->name);
    for (int k = 0; k < n; k++) {
        W += list[k]->w + (k ? GAP : 0);
        if (list[k]->h > H) H = list[k]->h;
    }
    W += n_layers * (ls + GAP);
    if (n_layers && ls > H) H = ls;
    gr_status st = gr_gl_make_current(s->gl, err);
    if (st != GR_OK) return st;
    gr_image *img = gr_image_create(W, H, 4, NULL);
    if (!img) return gr_fail(err, GR_E_NOMEM, "%s: out of memory for the targets' strip", m->name);
    for (int k = 0, x0 = 0; k < n; x0 += list[k]->w + GAP, k++) {
        const gr_target *t = list[k];
        if (k == n_pre)
            for (int j = 0; j < n_layers; j++, x0 += ls + GAP) { /* the caustic stack, after the inputs */
                gr_image *layer = NULL;
                if ((st = gr_caustics_read(s->caus, j, &layer, err)) != GR_OK) {
                    gr_image_destroy(img);
                    return st;
                }
                for (int y = 0; y < ls; y++) /* texel row y = z increasing: drawn bottom-up as GL rows */
                    for (int x = 0; x < ls; x++) {
                        float v = layer->pixels[(size_t)(ls - 1 - y) * ls + x];
                        float *o = img->pixels + ((size_t)y * W + x0 + x) * 4;
                        o[0] = o[1] = o[2] = v;
                        o[3] = 1.0f;
                    }
                gr_image_destroy(layer);
            }
        if ((st = gr_readback_fbo(&s->rb, t->fbo, t->w, t->h, m->name, err)) != GR_OK) {
            gr_image_destroy(img);
            return st;
        }
        for (int y = 0; y < t->h; y++) /* GL rows bottom-up, the image's top row first */
            memcpy(img->pixels + ((size_t)y * W + (size_t)x0) * 4, s->rb.rgba + (size_t)(t->h - 1 - y) * t->w * 4,
                   (size_t)t->w * 4 * sizeof *img->pixels);
    }
    *out = img;
    return GR_OK;
}
