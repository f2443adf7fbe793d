/* The user's own technique from a folder: manifest parsing and validation, the generated GLSL
 * prelude, and a generic multi-pass GL executor (usertech.h, docs/techniques.md). */
#include "realtime/usertech.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "realtime/frame.h"
#include "realtime/readback.h"
#include "realtime/scenegl.h"

#define UT_MAX_SETTINGS 64
#define UT_MAX_TARGETS 8
#define UT_MAX_PASSES 6   /* + the two harness inputs = GR_TECH_MAX_PASSES timed passes */
#define UT_MAX_INPUTS 8
#define UT_MAX_FACTORS 4
#define UT_NAME_MAX 24
#define UT_MAX_SIZE 16384
#define UT_MAX_LADDER 16

/* ---- the parsed manifest ---------------------------------------------------------------- */

typedef enum { UT_NUMBER, UT_INT, UT_BOOL, UT_RGB } ut_type;
static const char *const ut_type_names[] = {"number", "int", "bool", "rgb", NULL};

typedef enum { UT_FMT_RGBA8, UT_FMT_RGBA16F, UT_FMT_RGBA32F } ut_format;
static const char *const ut_format_names[] = {"rgba8", "rgba16f", "rgba32f", NULL};

typedef enum { UT_BLEND_NONE, UT_BLEND_ADDITIVE, UT_BLEND_ALPHA } ut_blend;
static const char *const ut_blend_names[] = {"none", "additive", "alpha", NULL};

typedef enum { UT_PRIM_TRIANGLES, UT_PRIM_TRIANGLE_STRIP, UT_PRIM_LINES, UT_PRIM_POINTS } ut_prim;
static const char *const ut_prim_names[] = {"triangles", "triangle_strip", "lines", "points", NULL};

/* Harness textures a pass may list among its inputs (bound as t_NAME). */
enum { UT_IN_SHADOW_MAP = -1, UT_IN_EYE_DEPTH = -2 };

typedef struct ut_setting {
    char key[GR_TECH_NAME_MAX];
    ut_type type;
    size_t offset;
} ut_setting;

/* A number given in the manifest or taken from a setting (setting >= 0). */
typedef struct ut_value {
    double v;
    int setting;
} ut_value;

/* A count: literal * product of int settings ("6*N*N"). */
typedef struct ut_count {
    long long literal;
    int n_factors;
    int factor[UT_MAX_FACTORS];
} ut_count;

typedef struct ut_target {
    char name[UT_NAME_MAX];
    int absolute, width, height; /* "size": [w, h] */
    ut_value scale;              /* "scale": relative to the frame, per axis */
    ut_format format;
    int linear;
} ut_target;

typedef struct ut_pass {
    char name[UT_NAME_MAX];
    char *vertex_file, *fragment_file; /* as written in the manifest; vertex NULL = built-in */
    char *vertex_src, *fragment_src;
    int fullscreen;
    ut_prim prim;
    ut_count vertices, instances;
    int target;
    ut_blend blend;
    int has_clear;
    float clear[4];
    int n_inputs;
    int inputs[UT_MAX_INPUTS]; /* target index, or UT_IN_* */
} ut_pass;

typedef struct ut_manifest {
    char name[GR_TECH_NAME_MAX];
    char *description;
    char *dir, *path; /* folder, and folder/manifest.json */
    int n_settings;
    ut_setting settings[UT_MAX_SETTINGS];
    gr_param params[UT_MAX_SETTINGS];
    char *param_strings[UT_MAX_SETTINGS][2]; /* unit, doc (owned) */
    gr_param_table table;
    size_t settings_size;
    int n_targets;
    ut_target targets[UT_MAX_TARGETS];
    int n_passes;
    ut_pass passes[UT_MAX_PASSES];
    int output;
    int allow_black;
    int uses_shadow_map, uses_eye_depth;
    ut_value shadow_size, shadow_half_extent;
    char source_hash[17]; /* FNV-1a 64 of the manifest and every shader file, hex */
    int n_ladder;
    gr_technique_level ladder[UT_MAX_LADDER];
    char *ladder_text[UT_MAX_LADDER];
    gr_technique_class cls;
} ut_manifest;

/* ---- small helpers ------------------------------------------------------------------------ */

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

typedef struct strbuf {
    char *s;
    size_t len, cap;
    int failed;
} strbuf;

static void sb_add(strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_add(strbuf *b, const char *fmt, ...)
{
    if (b->failed) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? b->cap - b->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->failed = 1;
            return;
        }
        if (b->s && b->len + (size_t)n < b->cap) {
            b->len += (size_t)n;
            return;
        }
        size_t nc = (b->cap ? b->cap * 2 : 4096);
        while (nc < b->len + (size_t)n + 1) nc *= 2;
        char *ns = realloc(b->s, nc);
        if (!ns) {
            b->failed = 1;
            return;
        }
        b->s = ns;
        b->cap = nc;
    }
}

typedef struct ut_ctx {
    gr_error *err;
    const char *path; /* manifest path, prefixes every message */
} ut_ctx;

static gr_status vfail(ut_ctx *c, const char *jpath, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static gr_status vfail(ut_ctx *c, const char *jpath, const char *fmt, ...)
{
    char msg[700];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* one line: a message never carries a newline (file names could) */
    for (char *q = msg; *q; q++)
        if (*q == '\n' || *q == '\r') *q = ' ';
    return gr_fail(c->err, GR_E_INPUT, "%s: %s: %s", c->path, jpath, msg);
}

/* out = "parent.key" (or "key"), truncated to n - 1 characters */
static void join(char *out, size_t n, const char *parent, const char *key)
{
    size_t k = 0;
    for (const char *q = parent ? parent : ""; *q && k + 1 < n; q++) out[k++] = *q;
    if (k > 0 && k + 1 < n) out[k++] = '.';
    for (const char *q = key; *q && k + 1 < n; q++) out[k++] = *q;
    out[k] = '\0';
}

static const char *type_name(const cJSON *v)
{
    if (!v) return "nothing";
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "?";
}

static int in_list(const char *key, const char *const *names)
{
    for (int i = 0; names[i]; i++)
        if (!strcmp(key, names[i])) return i;
    return -1;
}

static void list_text(const char *const *names, char *out, size_t n)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; names[i]; i++) {
        int w = snprintf(out + used, n - used, "%s%s", i ? ", " : "", names[i]);
        if (w < 0 || (size_t)w >= n - used) break;
        used += (size_t)w;
    }
}

/* Object with keys among names (NULL-terminated), each at most once. */
static gr_status check_object(ut_ctx *c, const cJSON *obj, const char *path, const char *const *names)
{
    char p[320], list[400];
    if (!cJSON_IsObject(obj)) return vfail(c, path[0] ? path : "(top level)", "must be an object, got %s", type_name(obj));
    for (const cJSON *it = obj->child; it; it = it->next) {
        const char *k = it->string ? it->string : "";
        join(p, sizeof p, path, k);
        if (names && in_list(k, names) < 0) {
            list_text(names, list, sizeof list);
            return vfail(c, p, "unknown key (known keys: %s)", list);
        }
        for (const cJSON *prev = obj->child; prev != it; prev = prev->next)
            if (!strcmp(prev->string, k)) return vfail(c, p, "duplicate key");
    }
    return GR_OK;
}

/* [a-z][a-z0-9_]* (lower = 1) or [A-Za-z][A-Za-z0-9_]* (lower = 0), no "__", < max chars. */
static int is_identifier(const char *s, int lower, size_t max)
{
    size_t n = strlen(s);
    if (n == 0 || n >= max) return 0;
    if (lower ? !(s[0] >= 'a' && s[0] <= 'z') : !isalpha((unsigned char)s[0])) return 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char ch = (unsigned char)s[i];
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || (!lower && ch >= 'A' && ch <= 'Z');
        if (!ok) return 0;
        if (ch == '_' && s[i + 1] == '_') return 0;
    }
    return 1;
}

static gr_status get_string(ut_ctx *c, const cJSON *obj, const char *parent, const char *key, int required,
                            const char **out)
{
    char p[320];
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    join(p, sizeof p, parent, key);
    if (!v) {
        if (required) return vfail(c, p, "missing (required)");
        return GR_OK;
    }
    if (!cJSON_IsString(v)) return vfail(c, p, "must be a string, got %s", type_name(v));
    *out = v->valuestring;
    return GR_OK;
}

static gr_status get_enum(ut_ctx *c, const cJSON *obj, const char *parent, const char *key,
                          const char *const *names, int *out)
{
    const char *s = NULL;
    char p[320], list[200];
    gr_status st = get_string(c, obj, parent, key, 0, &s);
    if (st || !s) return st;
    join(p, sizeof p, parent, key);
    int i = in_list(s, names);
    if (i < 0) {
        list_text(names, list, sizeof list);
        return vfail(c, p, "unknown value '%s', expected one of %s", s, list);
    }
    *out = i;
    return GR_OK;
}

static gr_status number_at(ut_ctx *c, const cJSON *v, const char *p, double *out)
{
    if (!cJSON_IsNumber(v)) return vfail(c, p, "must be a number, got %s", type_name(v));
    if (!isfinite(v->valuedouble)) return vfail(c, p, "must be a finite number");
    *out = v->valuedouble;
    return GR_OK;
}

static gr_status get_bool(ut_ctx *c, const cJSON *obj, const char *parent, const char *key, int *out)
{
    char p[320];
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    if (!cJSON_IsBool(v)) return vfail(c, p, "must be true or false, got %s", type_name(v));
    *out = cJSON_IsTrue(v) ? 1 : 0;
    return GR_OK;
}

static int find_setting(const ut_manifest *m, const char *key)
{
    for (int i = 0; i < m->n_settings; i++)
        if (!strcmp(m->settings[i].key, key)) return i;
    return -1;
}

static int find_target(const ut_manifest *m, const char *name)
{
    for (int i = 0; i < m->n_targets; i++)
        if (!strcmp(m->targets[i].name, name)) return i;
    return -1;
}

/* A number, or the name of a setting of type `want` (UT_NUMBER accepts int settings too)
 * whose whole range lies within [lo, hi]. */
static gr_status value_at(ut_ctx *c, const ut_manifest *m, const cJSON *v, const char *p, ut_type want, double lo,
                          double hi, ut_value *out)
{
    if (cJSON_IsString(v)) {
        int s = find_setting(m, v->valuestring);
        if (s < 0) return vfail(c, p, "'%s' is not a setting of this technique", v->valuestring);
        ut_type t = m->settings[s].type;
        if (!(t == want || (want == UT_NUMBER && t == UT_INT)))
            return vfail(c, p, "setting '%s' is of type %s, this field needs %s", v->valuestring, ut_type_names[t],
                         want == UT_INT ? "an int setting" : "a number or int setting");
        const gr_param *gp = &m->params[s];
        if (gp->min < lo || gp->max > hi)
            return vfail(c, p, "setting '%s' has range [%g, %g], this field needs values within [%g, %g]",
                         v->valuestring, gp->min, gp->max, lo, hi);
        out->setting = s;
        out->v = gp->def;
        return GR_OK;
    }
    double d = 0;
    gr_status st = number_at(c, v, p, &d);
    if (st) return st;
    if (want == UT_INT && d != floor(d)) return vfail(c, p, "must be an integer, got %g", d);
    if (d < lo || d > hi) return vfail(c, p, "must be in [%g, %g], got %g", lo, hi, d);
    out->setting = -1;
    out->v = d;
    return GR_OK;
}

/* A count: a positive integer, the name of an int setting, or "a*b*..." of those. */
static gr_status count_at(ut_ctx *c, const ut_manifest *m, const cJSON *v, const char *p, ut_count *out)
{
    memset(out, 0, sizeof *out);
    out->literal = 1;
    if (cJSON_IsNumber(v)) {
        double d = v->valuedouble;
        if (!(d >= 1 && d <= 1e8 && d == floor(d))) return vfail(c, p, "must be an integer in [1, 100000000], got %g", d);
        out->literal = (long long)d;
        return GR_OK;
    }
    if (!cJSON_IsString(v))
        return vfail(c, p, "must be an integer, an int setting's name or a product such as \"6*N\", got %s", type_name(v));
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v->valuestring);
    char *save = NULL;
    int any = 0;
    for (char *tok = strtok_r(buf, "*", &save); tok; tok = strtok_r(NULL, "*", &save)) {
        while (*tok == ' ') tok++;
        char *e = tok + strlen(tok);
        while (e > tok && e[-1] == ' ') *--e = '\0';
        any = 1;
        if (isdigit((unsigned char)tok[0])) {
            char *end = NULL;
            long long k = strtoll(tok, &end, 10);
            if (*end || k < 1 || k > 100000000) return vfail(c, p, "'%s': factor '%s' is not an integer in [1, 100000000]", v->valuestring, tok);
            out->literal *= k;
            if (out->literal > 100000000) return vfail(c, p, "'%s': more than 100000000", v->valuestring);
            continue;
        }
        int s = find_setting(m, tok);
        if (s < 0) return vfail(c, p, "'%s': '%s' is not a setting of this technique", v->valuestring, tok);
        if (m->settings[s].type != UT_INT) return vfail(c, p, "'%s': setting '%s' must be of type int", v->valuestring, tok);
        if (m->params[s].min < 0) return vfail(c, p, "'%s': setting '%s' must have min >= 0", v->valuestring, tok);
        if (out->n_factors == UT_MAX_FACTORS) return vfail(c, p, "'%s': at most %d setting factors", v->valuestring, UT_MAX_FACTORS);
        out->factor[out->n_factors++] = s;
    }
    if (!any) return vfail(c, p, "empty count");
    return GR_OK;
}

static gr_status read_file_text(const char *path, char **out, char *why, size_t why_n)
{
    FILE *f = fopen(path, "rb");
    *out = NULL;
    if (!f) {
        snprintf(why, why_n, "%s", strerror(errno));
        return GR_E_IO;
    }
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        fclose(f);
        snprintf(why, why_n, "not a regular file");
        return GR_E_IO;
    }
    size_t cap = (size_t)sb.st_size + 1, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        snprintf(why, why_n, "out of memory");
        return GR_E_NOMEM;
    }
    len = fread(buf, 1, cap - 1, f);
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        snprintf(why, why_n, "read error");
        return GR_E_IO;
    }
    buf[len] = '\0';
    if (strlen(buf) != len) {
        free(buf);
        snprintf(why, why_n, "contains a NUL byte (not a text file)");
        return GR_E_IO;
    }
    *out = buf;
    return GR_OK;
}

/* Reads DIR/file named at JSON path p; a missing or unreadable file is bad input (exit 2). */
static gr_status shader_file(ut_ctx *c, const ut_manifest *m, const char *file, const char *p, char **src)
{
    char full[4096], why[256];
    if (!file[0]) return vfail(c, p, "empty file name");
    if (file[0] == '/') snprintf(full, sizeof full, "%s", file);
    else snprintf(full, sizeof full, "%s/%s", m->dir, file);
    gr_status st = read_file_text(full, src, why, sizeof why);
    if (st == GR_E_NOMEM) return gr_fail(c->err, st, "%s: %s: out of memory", c->path, p);
    if (st) return vfail(c, p, "cannot read shader %s: %s", full, why);
    return GR_OK;
}

/* ---- manifest sections ------------------------------------------------------------------- */

static gr_status parse_settings(ut_ctx *c, ut_manifest *m, const cJSON *obj)
{
    static const char *const keys[] = {"type", "default", "min", "max", "min_exclusive", "max_exclusive",
                                       "tune", "unit", "doc", NULL};
    gr_status st = check_object(c, obj, "settings", NULL);
    if (st) return st;
    size_t offset = 0;
    for (const cJSON *it = obj->child; it; it = it->next) {
        char p[320], q[360];
        join(p, sizeof p, "settings", it->string);
        if (m->n_settings == UT_MAX_SETTINGS) return vfail(c, p, "more than %d settings", UT_MAX_SETTINGS);
        if (!is_identifier(it->string, 0, GR_TECH_NAME_MAX))
            return vfail(c, p, "a setting's key must be a GLSL-friendly name [A-Za-z][A-Za-z0-9_]* of at most %d characters without '__'",
                         GR_TECH_NAME_MAX - 1);
        if ((st = check_object(c, it, p, keys))) return st;
        int i = m->n_settings;
        ut_setting *s = &m->settings[i];
        gr_param *gp = &m->params[i];
        snprintf(s->key, sizeof s->key, "%s", it->string);
        int type = -1;
        if ((st = get_enum(c, it, p, "type", ut_type_names, &type))) return st;
        if (type < 0) {
            join(q, sizeof q, p, "type");
            return vfail(c, q, "missing (required: number, int, bool or rgb)");
        }
        s->type = (ut_type)type;
        size_t size = s->type == UT_RGB ? 3 * sizeof(double) : sizeof(double);
        s->offset = offset;
        offset += size;
        if (offset > GR_TECH_SETTINGS_MAX) return vfail(c, p, "settings take more than %d bytes", GR_TECH_SETTINGS_MAX);
        gp->name = s->key;
        gp->offset = s->offset;
        gp->type = s->type == UT_NUMBER ? GR_PT_DOUBLE : s->type == UT_INT ? GR_PT_INT : s->type == UT_BOOL ? GR_PT_BOOL : GR_PT_RGB;
        /* range */
        const cJSON *vmin = cJSON_GetObjectItemCaseSensitive(it, "min");
        const cJSON *vmax = cJSON_GetObjectItemCaseSensitive(it, "max");
        if (s->type == UT_BOOL) {
            if (vmin || vmax) {
                join(q, sizeof q, p, vmin ? "min" : "max");
                return vfail(c, q, "a bool setting has no range");
            }
            gp->min = 0;
            gp->max = 1;
        } else {
            if (!vmin || !vmax) {
                join(q, sizeof q, p, !vmin ? "min" : "max");
                return vfail(c, q, "missing (required: the valid range, also the default tuning box)");
            }
            join(q, sizeof q, p, "min");
            if ((st = number_at(c, vmin, q, &gp->min))) return st;
            join(q, sizeof q, p, "max");
            if ((st = number_at(c, vmax, q, &gp->max))) return st;
            if (!(gp->min < gp->max)) return vfail(c, q, "max (%g) must be greater than min (%g)", gp->max, gp->min);
            if (s->type == UT_INT && (gp->min != floor(gp->min) || gp->max != floor(gp->max) ||
                                      fabs(gp->min) > 1e9 || fabs(gp->max) > 1e9))
                return vfail(c, q, "an int setting's range must be integers within +-1e9");
            int ex = 0;
            if ((st = get_bool(c, it, p, "min_exclusive", &ex))) return st;
            if (ex) gp->flags |= GR_PF_MIN_EXCL;
            ex = 0;
            if ((st = get_bool(c, it, p, "max_exclusive", &ex))) return st;
            if (ex) gp->flags |= GR_PF_MAX_EXCL;
        }
        /* default */
        const cJSON *vdef = cJSON_GetObjectItemCaseSensitive(it, "default");
        join(q, sizeof q, p, "default");
        if (!vdef) return vfail(c, q, "missing (required)");
        if (s->type == UT_BOOL) {
            if (!cJSON_IsBool(vdef)) return vfail(c, q, "must be true or false, got %s", type_name(vdef));
            gp->def = cJSON_IsTrue(vdef) ? 1 : 0;
        } else {
            if (s->type == UT_RGB && cJSON_IsArray(vdef))
                return vfail(c, q, "an rgb setting's default is one number (the same for r, g and b)");
            if ((st = number_at(c, vdef, q, &gp->def))) return st;
            if (s->type == UT_INT && gp->def != floor(gp->def)) return vfail(c, q, "must be an integer, got %g", gp->def);
            int below = (gp->flags & GR_PF_MIN_EXCL) ? !(gp->def > gp->min) : !(gp->def >= gp->min);
            int above = (gp->flags & GR_PF_MAX_EXCL) ? !(gp->def < gp->max) : !(gp->def <= gp->max);
            if (below || above) {
                char r[80];
                return vfail(c, q, "%g is outside the setting's range %s", gp->def, gr_param_range_text(gp, r, sizeof r));
            }
        }
        /* default tuning box */
        const cJSON *vt = cJSON_GetObjectItemCaseSensitive(it, "tune");
        if (vt) {
            join(q, sizeof q, p, "tune");
            if (s->type != UT_NUMBER && s->type != UT_RGB)
                return vfail(c, q, "only number and rgb settings are tuned (int settings are swept)");
            if (!cJSON_IsArray(vt) || cJSON_GetArraySize(vt) != 2) return vfail(c, q, "must be [lo, hi]");
            double lh[2] = {0, 0};
            for (int k = 0; k < 2; k++) {
                char e[380];
                snprintf(e, sizeof e, "%s[%d]", q, k);
                if ((st = number_at(c, cJSON_GetArrayItem(vt, k), e, &lh[k]))) return st;
            }
            if (!(lh[0] < lh[1])) return vfail(c, q, "lo (%g) must be below hi (%g)", lh[0], lh[1]);
            if (s->type == UT_NUMBER && (lh[0] < gp->min || lh[1] > gp->max))
                return vfail(c, q, "[%g, %g] is not within the setting's range [%g, %g]", lh[0], lh[1], gp->min, gp->max);
            if (s->type == UT_RGB && lh[0] < 0) return vfail(c, q, "an rgb setting is tuned as a scale: lo must be >= 0");
            gp->tune_lo = lh[0];
            gp->tune_hi = lh[1];
        }
        const char *unit = "", *doc = "";
        if ((st = get_string(c, it, p, "unit", 0, &unit))) return st;
        if ((st = get_string(c, it, p, "doc", 0, &doc))) return st;
        m->param_strings[i][0] = dup_string(unit);
        m->param_strings[i][1] = dup_string(doc);
        if (!m->param_strings[i][0] || !m->param_strings[i][1]) return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);
        for (char *z = m->param_strings[i][1]; *z; z++)
            if (*z == '\n' || *z == '\r') *z = ' ';
        gp->unit = m->param_strings[i][0];
        gp->doc = m->param_strings[i][1];
        m->n_settings++;
    }
    m->settings_size = offset ? offset : sizeof(double);
    return GR_OK;
}

static gr_status parse_targets(ut_ctx *c, ut_manifest *m, const cJSON *obj)
{
    static const char *const keys[] = {"scale", "size", "format", "filter", NULL};
    static const char *const filters[] = {"linear", "nearest", NULL};
    gr_status st = check_object(c, obj, "targets", NULL);
    if (st) return st;
    if (!obj->child) return vfail(c, "targets", "must name at least one render target");
    for (const cJSON *it = obj->child; it; it = it->next) {
        char p[320], q[360];
        join(p, sizeof p, "targets", it->string);
        if (m->n_targets == UT_MAX_TARGETS) return vfail(c, p, "more than %d targets", UT_MAX_TARGETS);
        if (!is_identifier(it->string, 1, UT_NAME_MAX))
            return vfail(c, p, "a target's name must be [a-z][a-z0-9_]* of at most %d characters without '__'", UT_NAME_MAX - 1);
        if (!strcmp(it->string, "shadow_map") || !strcmp(it->string, "eye_depth"))
            return vfail(c, p, "'%s' is the name of a harness texture", it->string);
        if ((st = check_object(c, it, p, keys))) return st;
        ut_target *t = &m->targets[m->n_targets];
        snprintf(t->name, sizeof t->name, "%s", it->string);
        const cJSON *vs = cJSON_GetObjectItemCaseSensitive(it, "scale");
        const cJSON *vz = cJSON_GetObjectItemCaseSensitive(it, "size");
        t->scale.v = 1;
        t->scale.setting = -1;
        if (vs && vz) {
            join(q, sizeof q, p, "size");
            return vfail(c, q, "give either scale (relative to the frame) or size (absolute), not both");
        }
        if (vs) {
            join(q, sizeof q, p, "scale");
            if ((st = value_at(c, m, vs, q, UT_NUMBER, 1.0 / 64.0, 4.0, &t->scale))) return st;
        } else if (vz) {
            join(q, sizeof q, p, "size");
            if (!cJSON_IsArray(vz) || cJSON_GetArraySize(vz) != 2) return vfail(c, q, "must be [width, height] in pixels");
            double d[2] = {0, 0};
            for (int k = 0; k < 2; k++) {
                char e[380];
                snprintf(e, sizeof e, "%s[%d]", q, k);
                if ((st = number_at(c, cJSON_GetArrayItem(vz, k), e, &d[k]))) return st;
                if (!(d[k] >= 1 && d[k] <= UT_MAX_SIZE && d[k] == floor(d[k])))
                    return vfail(c, e, "must be an integer in [1, %d], got %g", UT_MAX_SIZE, d[k]);
            }
            t->absolute = 1;
            t->width = (int)d[0];
            t->height = (int)d[1];
        }
        int fmt = -1, filt = 0;
        if ((st = get_enum(c, it, p, "format", ut_format_names, &fmt))) return st;
        if (fmt < 0) {
            join(q, sizeof q, p, "format");
            return vfail(c, q, "missing (required: rgba8, rgba16f or rgba32f)");
        }
        t->format = (ut_format)fmt;
        if ((st = get_enum(c, it, p, "filter", filters, &filt))) return st;
        t->linear = filt == 0;
        m->n_targets++;
    }
    return GR_OK;
}

static gr_status parse_pass(ut_ctx *c, ut_manifest *m, const cJSON *it, int idx, const int *written)
{
    static const char *const keys[] = {"name", "vertex", "fragment", "draw", "target", "blend", "clear", "inputs", NULL};
    static const char *const draw_keys[] = {"primitive", "vertices", "instances", NULL};
    char p[64], q[320], list[400];
    gr_status st;
    snprintf(p, sizeof p, "passes[%d]", idx);
    if ((st = check_object(c, it, p, keys))) return st;
    ut_pass *ps = &m->passes[idx];
    const char *s = NULL;
    if ((st = get_string(c, it, p, "name", 0, &s))) return st;
    if (s) {
        join(q, sizeof q, p, "name");
        if (!is_identifier(s, 1, UT_NAME_MAX))
            return vfail(c, q, "a pass's name must be [a-z][a-z0-9_]* of at most %d characters", UT_NAME_MAX - 1);
        for (int k = 0; k < idx; k++)
            if (!strcmp(m->passes[k].name, s)) return vfail(c, q, "'%s' names passes[%d] already", s, k);
        snprintf(ps->name, sizeof ps->name, "%s", s);
    } else {
        snprintf(ps->name, sizeof ps->name, "pass%d", idx);
    }
    /* draw */
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(it, "draw");
    join(q, sizeof q, p, "draw");
    ps->fullscreen = 1;
    if (d && cJSON_IsString(d)) {
        if (strcmp(d->valuestring, "fullscreen"))
            return vfail(c, q, "unknown value '%s', expected \"fullscreen\" or an object {primitive, vertices, instances}",
                         d->valuestring);
    } else if (d) {
        if ((st = check_object(c, d, q, draw_keys))) return st;
        int prim = -1;
        if ((st = get_enum(c, d, q, "primitive", ut_prim_names, &prim))) return st;
        if (prim < 0) {
            char r[360];
            join(r, sizeof r, q, "primitive");
            list_text(ut_prim_names, list, sizeof list);
            return vfail(c, r, "missing (required: one of %s)", list);
        }
        ps->fullscreen = 0;
        ps->prim = (ut_prim)prim;
        const cJSON *vv = cJSON_GetObjectItemCaseSensitive(d, "vertices");
        char r[360];
        join(r, sizeof r, q, "vertices");
        if (!vv) return vfail(c, r, "missing (required)");
        if ((st = count_at(c, m, vv, r, &ps->vertices))) return st;
        const cJSON *vi = cJSON_GetObjectItemCaseSensitive(d, "instances");
        join(r, sizeof r, q, "instances");
        if (vi) {
            if ((st = count_at(c, m, vi, r, &ps->instances))) return st;
        } else {
            ps->instances.literal = 1;
        }
    }
    /* shaders */
    const char *vf = NULL, *ff = NULL;
    if ((st = get_string(c, it, p, "vertex", 0, &vf))) return st;
    if ((st = get_string(c, it, p, "fragment", 1, &ff))) return st;
    if (!vf && !ps->fullscreen) {
        join(q, sizeof q, p, "vertex");
        return vfail(c, q, "missing (required unless draw is \"fullscreen\")");
    }
    if (vf) {
        join(q, sizeof q, p, "vertex");
        if (!(ps->vertex_file = dup_string(vf))) return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);
        if ((st = shader_file(c, m, vf, q, &ps->vertex_src))) return st;
    }
    join(q, sizeof q, p, "fragment");
    if (!(ps->fragment_file = dup_string(ff))) return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);
    if ((st = shader_file(c, m, ff, q, &ps->fragment_src))) return st;
    /* target */
    if ((st = get_string(c, it, p, "target", 1, &s))) return st;
    join(q, sizeof q, p, "target");
    ps->target = find_target(m, s);
    if (ps->target < 0) {
        const char *names[UT_MAX_TARGETS + 1];
        for (int k = 0; k < m->n_targets; k++) names[k] = m->targets[k].name;
        names[m->n_targets] = NULL;
        list_text(names, list, sizeof list);
        return vfail(c, q, "unknown target '%s' (targets: %s)", s, list);
    }
    int blend = UT_BLEND_NONE;
    if ((st = get_enum(c, it, p, "blend", ut_blend_names, &blend))) return st;
    ps->blend = (ut_blend)blend;
    /* clear */
    const cJSON *vc = cJSON_GetObjectItemCaseSensitive(it, "clear");
    join(q, sizeof q, p, "clear");
    if (vc && !cJSON_IsFalse(vc)) {
        if (!cJSON_IsArray(vc) || cJSON_GetArraySize(vc) != 4)
            return vfail(c, q, "must be [r, g, b, a] or false, got %s", type_name(vc));
        for (int k = 0; k < 4; k++) {
            char r[360];
            double x = 0;
            snprintf(r, sizeof r, "%s[%d]", q, k);
            if ((st = number_at(c, cJSON_GetArrayItem(vc, k), r, &x))) return st;
            ps->clear[k] = (float)x;
        }
        ps->has_clear = 1;
    }
    /* inputs */
    const cJSON *vin = cJSON_GetObjectItemCaseSensitive(it, "inputs");
    join(q, sizeof q, p, "inputs");
    if (vin) {
        if (!cJSON_IsArray(vin)) return vfail(c, q, "must be an array of names, got %s", type_name(vin));
        int k = 0;
        for (const cJSON *e = vin->child; e; e = e->next, k++) {
            char r[360];
            snprintf(r, sizeof r, "%s[%d]", q, k);
            if (k == UT_MAX_INPUTS) return vfail(c, q, "more than %d inputs", UT_MAX_INPUTS);
            if (!cJSON_IsString(e)) return vfail(c, r, "must be a string, got %s", type_name(e));
            const char *nm = e->valuestring;
            int in;
            if (!strcmp(nm, "shadow_map")) {
                in = UT_IN_SHADOW_MAP;
                m->uses_shadow_map = 1;
            } else if (!strcmp(nm, "eye_depth")) {
                in = UT_IN_EYE_DEPTH;
                m->uses_eye_depth = 1;
            } else {
                in = find_target(m, nm);
                if (in < 0) return vfail(c, r, "unknown input '%s' (a target's name, \"shadow_map\" or \"eye_depth\")", nm);
                if (in == ps->target)
                    return vfail(c, r, "pass reads its own target '%s' (a feedback loop): render into another target", nm);
                if (!written[in]) return vfail(c, r, "target '%s' is read before any earlier pass writes it", nm);
            }
            for (int j = 0; j < ps->n_inputs; j++)
                if (ps->inputs[j] == in) return vfail(c, r, "'%s' is listed twice", nm);
            ps->inputs[ps->n_inputs++] = in;
        }
    }
    return GR_OK;
}

/* "ladder": [{"settings": {KEY: value, ...}, "quick": bool}, ...] -> "KEY=VALUE,..." levels */
static gr_status parse_ladder(ut_ctx *c, ut_manifest *m, const cJSON *lad)
{
    static const char *const keys[] = {"settings", "quick", NULL};
    if (!cJSON_IsArray(lad)) return vfail(c, "ladder", "must be an array of levels, got %s", type_name(lad));
    if (cJSON_GetArraySize(lad) > UT_MAX_LADDER) return vfail(c, "ladder", "more than %d levels", UT_MAX_LADDER);
    int i = 0;
    gr_status st;
    for (const cJSON *lv = lad->child; lv; lv = lv->next, i++) {
        char p[64], q[320];
        snprintf(p, sizeof p, "ladder[%d]", i);
        if ((st = check_object(c, lv, p, keys))) return st;
        const cJSON *set = cJSON_GetObjectItemCaseSensitive(lv, "settings");
        join(q, sizeof q, p, "settings");
        if (!set) return vfail(c, q, "missing (required: {\"KEY\": value, ...})");
        if ((st = check_object(c, set, q, NULL))) return st;
        strbuf b = {0};
        for (const cJSON *e = set->child; e; e = e->next) {
            char r[360], num[40];
            join(r, sizeof r, q, e->string);
            int k = find_setting(m, e->string);
            if (k < 0) {
                free(b.s);
                return vfail(c, r, "'%s' is not a setting of this technique", e->string);
            }
            double v = 0;
            if (m->settings[k].type == UT_BOOL) {
                if (!cJSON_IsBool(e)) {
                    free(b.s);
                    return vfail(c, r, "must be true or false, got %s", type_name(e));
                }
                v = cJSON_IsTrue(e);
            } else if ((st = number_at(c, e, r, &v))) {
                free(b.s);
                return st;
            }
            gr_error perr;
            if (gr_param_check(&m->table, &m->params[k], v, 0, &perr) != GR_OK) {
                free(b.s);
                const char *why = strstr(perr.msg, ": "); /* drop gr_param_check's "NAME.KEY: " */
                return vfail(c, r, "%s", why ? why + 2 : perr.msg);
            }
            if (m->settings[k].type == UT_BOOL) snprintf(num, sizeof num, "%s", v != 0 ? "true" : "false");
            else gr_format_double(v, num, sizeof num);
            sb_add(&b, "%s%s=%s", b.len ? "," : "", e->string, num);
        }
        if (b.failed || !b.s) {
            free(b.s);
            if (!set->child) return vfail(c, q, "must name at least one setting");
            return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);
        }
        m->ladder_text[i] = b.s;
        m->ladder[i].settings = b.s;
        int quick = 0;
        if ((st = get_bool(c, lv, p, "quick", &quick))) return st;
        m->ladder[i].quick = quick;
        m->n_ladder = i + 1;
    }
    return GR_OK;
}

static gr_status parse_manifest(ut_ctx *c, ut_manifest *m, const cJSON *root)
{
    static const char *const keys[] = {"version", "name", "description", "settings", "gain", "ladder", "shadow_map",
                                       "targets", "passes", "output", "allow_black", NULL};
    static const char *const sm_keys[] = {"size", "half_extent_m", NULL};
    gr_status st = check_object(c, root, "", keys);
    if (st) return st;
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (!ver) return vfail(c, "version", "missing (required: 1)");
    if (!cJSON_IsNumber(ver) || ver->valuedouble != 1)
        return vfail(c, "version", "unsupported manifest version (this harness reads version 1)");
    const char *s = NULL;
    if ((st = get_string(c, root, "", "name", 1, &s))) return st;
    if (!is_identifier(s, 1, GR_TECH_NAME_MAX))
        return vfail(c, "name", "'%s' is not a technique name: [a-z][a-z0-9_]*, at most %d characters, no '__'", s,
                     GR_TECH_NAME_MAX - 1);
    snprintf(m->name, sizeof m->name, "%s", s);
    s = "";
    if ((st = get_string(c, root, "", "description", 1, &s))) return st;
    if (!s[0]) return vfail(c, "description", "must not be empty (one line for `godrays techniques`)");
    if (strchr(s, '\n')) return vfail(c, "description", "must be one line");
    if (!(m->description = dup_string(s))) return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);

    const cJSON *set = cJSON_GetObjectItemCaseSensitive(root, "settings");
    m->settings_size = sizeof(double);
    if (set && (st = parse_settings(c, m, set))) return st;
    m->table.section = m->name;
    m->table.params = m->params;
    m->table.count = (size_t)m->n_settings;

    const cJSON *gain = cJSON_GetObjectItemCaseSensitive(root, "gain");
    if (gain) {
        if (!cJSON_IsString(gain)) return vfail(c, "gain", "must be a setting's name, got %s", type_name(gain));
        int g = find_setting(m, gain->valuestring);
        if (g < 0) return vfail(c, "gain", "'%s' is not a setting of this technique", gain->valuestring);
        if (m->settings[g].type != UT_NUMBER && m->settings[g].type != UT_RGB)
            return vfail(c, "gain", "setting '%s' must be of type number or rgb (a linear scale on the output)",
                         gain->valuestring);
        m->cls.gain_key = m->settings[g].key;
    }
    const cJSON *lad = cJSON_GetObjectItemCaseSensitive(root, "ladder");
    if (lad && (st = parse_ladder(c, m, lad))) return st;

    const cJSON *tg = cJSON_GetObjectItemCaseSensitive(root, "targets");
    if (!tg) return vfail(c, "targets", "missing (required: the render targets, e.g. {\"out\": {\"format\": \"rgba32f\"}})");
    if ((st = parse_targets(c, m, tg))) return st;

    const cJSON *ps = cJSON_GetObjectItemCaseSensitive(root, "passes");
    if (!ps) return vfail(c, "passes", "missing (required)");
    if (!cJSON_IsArray(ps) || cJSON_GetArraySize(ps) < 1) return vfail(c, "passes", "must be a non-empty array of passes");
    if (cJSON_GetArraySize(ps) > UT_MAX_PASSES) return vfail(c, "passes", "more than %d passes", UT_MAX_PASSES);
    int written[UT_MAX_TARGETS] = {0};
    int i = 0;
    for (const cJSON *it = ps->child; it; it = it->next, i++) {
        if ((st = parse_pass(c, m, it, i, written))) return st;
        written[m->passes[i].target] = 1;
        m->n_passes = i + 1;
    }

    const cJSON *out = cJSON_GetObjectItemCaseSensitive(root, "output");
    m->output = m->passes[m->n_passes - 1].target;
    if (out) {
        if (!cJSON_IsString(out)) return vfail(c, "output", "must be a target's name, got %s", type_name(out));
        m->output = find_target(m, out->valuestring);
        if (m->output < 0) return vfail(c, "output", "unknown target '%s'", out->valuestring);
        if (!written[m->output]) return vfail(c, "output", "no pass writes target '%s'", out->valuestring);
    }
    const ut_target *ot = &m->targets[m->output];
    if (ot->absolute || ot->scale.setting >= 0 || ot->scale.v != 1.0)
        return vfail(c, "output", "target '%s' must be frame-sized (\"scale\": 1): the harness reads it back pixel for pixel",
                     ot->name);
    if ((st = get_bool(c, root, "", "allow_black", &m->allow_black))) return st;

    m->shadow_size.v = 1024;
    m->shadow_size.setting = -1;
    m->shadow_half_extent.v = 40;
    m->shadow_half_extent.setting = -1;
    const cJSON *sm = cJSON_GetObjectItemCaseSensitive(root, "shadow_map");
    if (sm) {
        if ((st = check_object(c, sm, "shadow_map", sm_keys))) return st;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(sm, "size");
        if (v && (st = value_at(c, m, v, "shadow_map.size", UT_INT, 16, 8192, &m->shadow_size))) return st;
        v = cJSON_GetObjectItemCaseSensitive(sm, "half_extent_m");
        if (v && (st = value_at(c, m, v, "shadow_map.half_extent_m", UT_NUMBER, 0.01, 1e5, &m->shadow_half_extent)))
            return st;
    }
    return GR_OK;
}

/* ---- class callbacks (declared here, GL part below) ------------------------------------- */

static gr_status ut_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err);
static void ut_destroy(void *state);
static gr_status ut_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err);
static gr_status ut_metadata(void *state, const gr_scene *scene, const void *settings, const gr_technique_stats *stats,
                             gr_metadata *meta, gr_error *err);

/* Settings of a user technique have no scene-derived defaults: resolving is a copy. */
static void ut_resolve(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out)
{
    (void)scene;
    memmove(out, in, cls->settings_size);
}

static void manifest_free(ut_manifest *m)
{
    if (!m) return;
    for (int i = 0; i < UT_MAX_PASSES; i++) {
        free(m->passes[i].vertex_file);
        free(m->passes[i].fragment_file);
        free(m->passes[i].vertex_src);
        free(m->passes[i].fragment_src);
    }
    for (int i = 0; i < UT_MAX_SETTINGS; i++) {
        free(m->param_strings[i][0]);
        free(m->param_strings[i][1]);
    }
    for (int i = 0; i < UT_MAX_LADDER; i++) free(m->ladder_text[i]);
    free(m->description);
    free(m->dir);
    free(m->path);
    free(m);
}

int gr_usertech_is_user(const gr_technique_class *cls) { return cls && cls->create == ut_create; }

void gr_usertech_free(gr_technique_class *cls)
{
    if (!gr_usertech_is_user(cls)) return;
    manifest_free((ut_manifest *)cls->class_data);
}

static unsigned long long fnv1a(unsigned long long h, const char *s)
{
    for (const unsigned char *q = (const unsigned char *)s; *q; q++) {
        h ^= *q;
        h *= 1099511628211ULL;
    }
    return h;
}

/* "LABEL:LINE:COL: malformed JSON near '...'" (as the scene loader words it) */
static gr_status parse_json(const char *text, const char *label, cJSON **out, gr_error *err)
{
    const char *end = NULL;
    *out = cJSON_ParseWithOpts(text, &end, 1);
    if (*out) return GR_OK;
    if (!end) end = text;
    int line = 1, col = 1;
    for (const char *q = text; q < end && *q; q++) {
        if (*q == '\n') {
            line++;
            col = 1;
        } else {
            col++;
        }
    }
    char near[40];
    size_t k = 0;
    const char *from = end;
    while (from > text && from[-1] != '\n' && end - from < 12) from--;
    while (*from == ' ' || *from == '\t') from++;
    for (const char *q = from; *q && *q != '\n' && *q != '\r' && k < 32 && q < end + 12; q++) near[k++] = *q;
    near[k] = '\0';
    if (!k) return gr_fail(err, GR_E_INPUT, "%s:%d:%d: malformed JSON at end of input", label, line, col);
    return gr_fail(err, GR_E_INPUT, "%s:%d:%d: malformed JSON near '%s'", label, line, col, near);
}

gr_status gr_usertech_load(const char *dir, gr_technique_class **out, gr_error *err)
{
    *out = NULL;
    struct stat sb;
    if (!dir || !dir[0]) return gr_fail(err, GR_E_USAGE, "--technique-dir: empty folder name");
    if (stat(dir, &sb) != 0) return gr_fail(err, GR_E_INPUT, "--technique-dir %s: %s", dir, strerror(errno));
    if (!S_ISDIR(sb.st_mode)) return gr_fail(err, GR_E_INPUT, "--technique-dir %s: not a folder", dir);
    ut_manifest *m = calloc(1, sizeof *m);
    if (!m) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", dir);
    size_t dl = strlen(dir);
    while (dl > 1 && dir[dl - 1] == '/') dl--;
    m->dir = malloc(dl + 1);
    m->path = malloc(dl + sizeof "/" GR_USERTECH_MANIFEST);
    if (!m->dir || !m->path) {
        manifest_free(m);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", dir);
    }
    memcpy(m->dir, dir, dl);
    m->dir[dl] = '\0';
    sprintf(m->path, "%s/%s", m->dir, GR_USERTECH_MANIFEST);
    char *text = NULL, why[256];
    gr_status st = read_file_text(m->path, &text, why, sizeof why);
    if (st) {
        st = gr_fail(err, st == GR_E_NOMEM ? GR_E_NOMEM : GR_E_INPUT, "%s: cannot read the manifest: %s", m->path, why);
        manifest_free(m);
        return st;
    }
    cJSON *root = NULL;
    st = parse_json(text, m->path, &root, err);
    if (st == GR_OK) {
        ut_ctx c = {err, m->path};
        st = parse_manifest(&c, m, root);
    }
    if (st == GR_OK) {
        /* provenance: which version of the technique rendered an image */
        unsigned long long h = fnv1a(14695981039346656037ULL, text);
        for (int i = 0; i < m->n_passes; i++) {
            if (m->passes[i].vertex_src) h = fnv1a(h, m->passes[i].vertex_src);
            h = fnv1a(h, m->passes[i].fragment_src);
        }
        snprintf(m->source_hash, sizeof m->source_hash, "%016llx", h);
    }
    free(text);
    cJSON_Delete(root);
    if (st) {
        manifest_free(m);
        return st;
    }
    m->table.section = m->name;
    m->table.params = m->params;
    m->table.count = (size_t)m->n_settings;
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
#define UT_UNIFORMS(X)                                                   \
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
    X(SHADOW_HALF_EXTENT, "float u_shadow_half_extent")

enum {
#define X(id, decl) U_##id,
    UT_UNIFORMS(X)
#undef X
    U_COUNT
};
static const char *const ut_uniform_decl[U_COUNT] = {
#define X(id, decl) decl,
    UT_UNIFORMS(X)
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

static const char *glsl_version_for(int major, int minor)
{
    if (major > 4 || (major == 4 && minor >= 5)) return "450 core";
    if (major == 4 && minor >= 3) return "430 core";
    return "330 core";
}

/* Prelude of pass ps, stage 0 = vertex, 1 = fragment. */
static char *make_prelude(const ut_manifest *m, const ut_pass *ps, int frag, const char *version)
{
    strbuf b = {0};
    sb_add(&b, "#version %s\n", version);
    sb_add(&b, "// ---- godrays harness prelude (docs/techniques.md): technique '%s', pass '%s', %s stage\n", m->name,
           ps->name, frag ? "fragment" : "vertex");
    sb_add(&b, "#define GODRAYS 1\n#define GR_MAX_WAVES %d\n#define GR_PI 3.14159265358979\n", GR_MAX_WAVES);
    for (int i = 0; i < U_COUNT; i++) {
        if ((i == U_LIGHT_VIEW_PROJ || i == U_SHADOW_HALF_EXTENT)) {
            int has = 0;
            for (int k = 0; k < ps->n_inputs; k++) has |= ps->inputs[k] == UT_IN_SHADOW_MAP;
            if (!has) continue;
        }
        sb_add(&b, "uniform %s;\n", ut_uniform_decl[i]);
    }
    for (int i = 0; i < m->n_settings; i++) {
        static const char *const glsl_types[] = {"float", "int", "bool", "vec3"};
        sb_add(&b, "uniform %s u_set_%s;\n", glsl_types[m->settings[i].type], m->settings[i].key);
    }
    int has_shadow = 0, has_depth = 0;
    for (int k = 0; k < ps->n_inputs; k++) {
        int in = ps->inputs[k];
        if (in == UT_IN_SHADOW_MAP) has_shadow = 1;
        else if (in == UT_IN_EYE_DEPTH) has_depth = 1;
        sb_add(&b, "uniform sampler2D t_%s;\n",
               in == UT_IN_SHADOW_MAP ? "shadow_map" : in == UT_IN_EYE_DEPTH ? "eye_depth" : m->targets[in].name);
    }
    if (frag && !ps->vertex_src) sb_add(&b, "in vec2 v_uv;\n");
    sb_add(&b, "%s", ut_helpers);
    if (has_shadow) sb_add(&b, "%s", ut_shadow_helper);
    if (has_depth) sb_add(&b, "%s", ut_depth_helper);
    sb_add(&b, "// ---- end of the prelude\n#line 1\n");
    if (b.failed) {
        free(b.s);
        return NULL;
    }
    return b.s;
}

char *gr_usertech_prelude(const gr_technique_class *cls, int pass, const char *stage)
{
    if (!gr_usertech_is_user(cls) || !stage) return NULL;
    const ut_manifest *m = cls->class_data;
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

/* ---- instances ------------------------------------------------------------------------------ */

typedef struct ut_prog_locs {
    GLint u[U_COUNT];
    GLint set[UT_MAX_SETTINGS];
    GLint in[UT_MAX_INPUTS];
} ut_prog_locs;

typedef struct ut_state {
    const ut_manifest *m;
    gr_gl *gl;
    gr_scenegl *sgl;
    GLuint prog[UT_MAX_PASSES];
    ut_prog_locs locs[UT_MAX_PASSES];
    GLuint vao;
    GLuint tex[UT_MAX_TARGETS], fbo[UT_MAX_TARGETS];
    int tw[UT_MAX_TARGETS], th[UT_MAX_TARGETS];
    GLuint q_samples[UT_MAX_PASSES];
    gr_gl_timer timer;
    int timer_ready;
    gr_readback rb;
    /* what the last render did, for metadata */
    long long samples[UT_MAX_PASSES];
    int last_w[UT_MAX_TARGETS], last_h[UT_MAX_TARGETS];
    double shadow_size, shadow_half_extent;
} ut_state;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static gr_status ut_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)opts; /* a user technique's shaders are its folder's; --shader-dir does not apply */
    *state = NULL;
    const ut_manifest *m = cls->class_data;
    ut_state *s = calloc(1, sizeof *s);
    if (!s) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", m->name);
    s->m = m;
    s->gl = gl;
    gr_status st = GR_OK;
    int major = 4, minor = 5;
    gr_gl_context_version(gl, &major, &minor);
    const char *version = glsl_version_for(major, minor);
    for (int p = 0; p < m->n_passes; p++) {
        const ut_pass *ps = &m->passes[p];
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
        st = gr_gl_build_program(label, vs, fs, &s->prog[p], err);
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
            int in = ps->inputs[k];
            snprintf(nm, sizeof nm, "t_%s",
                     in == UT_IN_SHADOW_MAP ? "shadow_map" : in == UT_IN_EYE_DEPTH ? "eye_depth" : m->targets[in].name);
            l->in[k] = glGetUniformLocation(s->prog[p], nm);
        }
    }
    if (m->uses_shadow_map || m->uses_eye_depth) {
        if ((st = gr_scenegl_create(gl, &s->sgl, err)) != GR_OK) goto fail;
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
    for (int p = 0; p < UT_MAX_PASSES; p++)
        if (s->prog[p]) glDeleteProgram(s->prog[p]);
    for (int t = 0; t < UT_MAX_TARGETS; t++) {
        if (s->fbo[t]) glDeleteFramebuffers(1, &s->fbo[t]);
        if (s->tex[t]) glDeleteTextures(1, &s->tex[t]);
    }
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->q_samples[0]) glDeleteQueries(s->m->n_passes, s->q_samples);
    if (s->timer_ready) gr_gl_timer_free(&s->timer);
    gr_scenegl_destroy(s->sgl);
    gr_readback_free(&s->rb);
    free(s);
}

static double setting_number(const ut_manifest *m, const void *settings, int i)
{
    return gr_param_get_number(&m->params[i], settings, 0);
}

static double value_of(const ut_manifest *m, const void *settings, const ut_value *v)
{
    return v->setting >= 0 ? setting_number(m, settings, v->setting) : v->v;
}

static long long count_of(const ut_manifest *m, const void *settings, const ut_count *c)
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
    const ut_target *tg = &s->m->targets[t];
    if (s->tex[t] && s->tw[t] == w && s->th[t] == h) return GR_OK;
    if (s->fbo[t]) glDeleteFramebuffers(1, &s->fbo[t]);
    if (s->tex[t]) glDeleteTextures(1, &s->tex[t]);
    s->fbo[t] = s->tex[t] = 0;
    static const GLenum fmts[] = {GL_RGBA8, GL_RGBA16F, GL_RGBA32F};
    glGenTextures(1, &s->tex[t]);
    glBindTexture(GL_TEXTURE_2D, s->tex[t]);
    glTexStorage2D(GL_TEXTURE_2D, 1, fmts[tg->format], w, h);
    GLint filt = tg->linear ? GL_LINEAR : GL_NEAREST;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filt);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filt);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &s->fbo[t]);
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo[t]);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s->tex[t], 0);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return gr_fail(err, GR_E_GL, "%s: targets.%s (%dx%d %s): framebuffer incomplete (0x%04x)", s->m->path, tg->name, w,
                       h, ut_format_names[tg->format], (unsigned)fs);
    s->tw[t] = w;
    s->th[t] = h;
    return gr_gl_check(tg->name, err);
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
#undef F1
    const ut_manifest *m = s->m;
    for (int i = 0; i < m->n_settings; i++) {
        GLint loc = l->set[i];
        if (loc < 0) continue;
        const gr_param *gp = &m->params[i];
        switch (m->settings[i].type) {
        case UT_NUMBER: glUniform1f(loc, (float)gr_param_get_number(gp, settings, 0)); break;
        case UT_INT:
        case UT_BOOL: glUniform1i(loc, (int)gr_param_get_number(gp, settings, 0)); break;
        case UT_RGB:
            glUniform3f(loc, (float)gr_param_get_number(gp, settings, 0), (float)gr_param_get_number(gp, settings, 1),
                        (float)gr_param_get_number(gp, settings, 2));
            break;
        }
    }
    const ut_pass *ps = &m->passes[p];
    for (int k = 0; k < ps->n_inputs; k++) {
        int in = ps->inputs[k];
        glActiveTexture(GL_TEXTURE0 + (GLenum)k);
        glBindTexture(GL_TEXTURE_2D, in == UT_IN_SHADOW_MAP ? fi->shadow_tex : in == UT_IN_EYE_DEPTH ? fi->depth_tex : s->tex[in]);
        if (l->in[k] >= 0) glUniform1i(l->in[k], k);
    }
    glActiveTexture(GL_TEXTURE0);
}

static GLenum prim_mode(ut_prim p)
{
    switch (p) {
    case UT_PRIM_TRIANGLE_STRIP: return GL_TRIANGLE_STRIP;
    case UT_PRIM_LINES: return GL_LINES;
    case UT_PRIM_POINTS: return GL_POINTS;
    default: return GL_TRIANGLES;
    }
}

static gr_status ut_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    ut_state *s = state;
    const ut_manifest *m = s->m;
    double t0 = now_ms();
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
    int tw[UT_MAX_TARGETS], th[UT_MAX_TARGETS];
    for (int t = 0; t < m->n_targets; t++) {
        const ut_target *tg = &m->targets[t];
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
        if (tw[t] > UT_MAX_SIZE || th[t] > UT_MAX_SIZE) {
            st = gr_fail(err, GR_E_INPUT, "%s.%s: target '%s' would be %dx%d (at most %d per side)", m->name,
                         tg->scale.setting >= 0 ? m->settings[tg->scale.setting].key : "scale", tg->name, tw[t], th[t],
                         UT_MAX_SIZE);
            goto done;
        }
    }
    long long nv[UT_MAX_PASSES], ni[UT_MAX_PASSES];
    for (int p = 0; p < m->n_passes; p++) {
        const ut_pass *ps = &m->passes[p];
        nv[p] = ps->fullscreen ? 3 : count_of(m, settings, &ps->vertices);
        ni[p] = ps->fullscreen ? 1 : count_of(m, settings, &ps->instances);
        if (nv[p] > 100000000LL || ni[p] > 100000000LL || nv[p] * ni[p] > 1000000000LL) {
            st = gr_fail(err, GR_E_INPUT, "%s: passes[%d] '%s': %lld vertices x %lld instances is too many for one draw",
                         m->name, p, ps->name, nv[p], ni[p]);
            goto done;
        }
    }
    if ((st = gr_gl_make_current(s->gl, err)) != GR_OK) goto done;
    for (int t = 0; t < m->n_targets; t++)
        if ((st = ensure_target(s, t, tw[t], th[t], err)) != GR_OK) goto done;

    /* harness inputs, timed as passes of their own */
    int slot = 0;
    char names[GR_TECH_MAX_PASSES][24];
    if (m->uses_shadow_map) {
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
    if (m->uses_eye_depth) {
        gr_gl_timer_begin(&s->timer, slot);
        st = gr_scenegl_eye_depth(s->sgl, scene, &fi->f, W, H, &fi->depth_tex, err);
        gr_gl_timer_end(&s->timer);
        if (st) goto done;
        snprintf(names[slot++], 24, "eye_depth");
    }
    int first_pass_slot = slot;

    int cleared[UT_MAX_TARGETS] = {0};
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_DITHER); /* dithering would make 8-bit targets depend on the pixel position */
    glDepthMask(GL_FALSE);
    glBindVertexArray(s->vao);
    for (int p = 0; p < m->n_passes; p++) {
        const ut_pass *ps = &m->passes[p];
        int t = ps->target;
        snprintf(names[slot], 24, "%s", ps->name);
        gr_gl_timer_begin(&s->timer, slot++);
        glBeginQuery(GL_SAMPLES_PASSED, s->q_samples[p]);
        glBindFramebuffer(GL_FRAMEBUFFER, s->fbo[t]);
        glViewport(0, 0, tw[t], th[t]);
        if (!cleared[t] || ps->has_clear) {
            /* every target starts the frame at 0; "clear" clears again before this pass */
            if (ps->has_clear) glClearColor(ps->clear[0], ps->clear[1], ps->clear[2], ps->clear[3]);
            else glClearColor(0, 0, 0, 0);
            glClear(GL_COLOR_BUFFER_BIT);
            cleared[t] = 1;
        }
        if (ps->blend == UT_BLEND_NONE) {
            glDisable(GL_BLEND);
        } else {
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_ADD);
            if (ps->blend == UT_BLEND_ADDITIVE) glBlendFunc(GL_ONE, GL_ONE);
            else glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        }
        glUseProgram(s->prog[p]);
        set_uniforms(s, p, fi, settings, tw[t], th[t]);
        if (ps->prim == UT_PRIM_POINTS && !ps->fullscreen) glEnable(GL_PROGRAM_POINT_SIZE);
        if (ps->fullscreen) glDrawArrays(GL_TRIANGLES, 0, 3);
        else glDrawArraysInstanced(prim_mode(ps->prim), 0, (GLsizei)nv[p], (GLsizei)ni[p]);
        glDisable(GL_PROGRAM_POINT_SIZE);
        glDisable(GL_BLEND);
        glEndQuery(GL_SAMPLES_PASSED);
        gr_gl_timer_end(&s->timer);
        for (int k = 0; k < ps->n_inputs; k++) {
            glActiveTexture(GL_TEXTURE0 + (GLenum)k);
            glBindTexture(GL_TEXTURE_2D, 0);
        }
        glActiveTexture(GL_TEXTURE0);
        if ((st = gr_gl_check(ps->name, err)) != GR_OK) {
            gr_error_prefix(err, "%s: passes[%d]", m->path, p);
            goto unbind;
        }
    }

    /* read the output target back (GL rows bottom-up; gr_image top row first) */
    if ((st = gr_readback_fbo(&s->rb, s->fbo[m->output], W, H, "readback", err)) != GR_OK) {
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
    size_t bad = gr_readback_to_rgb(&s->rb, out), nonzero = 0;
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
        memset(stats, 0, sizeof *stats);
        stats->n_passes = slot;
        stats->fragments = 0;
        double wall_ns = (now_ms() - t0) * 1e6;
        for (int k = 0; k < slot; k++) {
            memcpy(stats->pass_names[k], names[k], sizeof stats->pass_names[k]);
            long long ns = gr_gl_timer_ns(&s->timer, k);
            /* a GPU time longer than the whole call is a broken timer (as in shafts.c) */
            stats->gpu_ns[k] = (ns >= 0 && (double)ns <= wall_ns) ? ns : -1;
        }
        for (int p = 0; p < m->n_passes; p++) stats->fragments += s->samples[p];
        (void)first_pass_slot;
        stats->wall_ms = now_ms() - t0;
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
    const ut_manifest *m = s->m;
    char key[96], val[64];
    gr_status st = gr_meta_set_string(meta, "godrays:user_source_hash", m->source_hash);
    for (int t = 0; st == GR_OK && t < m->n_targets; t++) {
        snprintf(key, sizeof key, "godrays:user_target.%s", m->targets[t].name);
        snprintf(val, sizeof val, "%dx%d %s", s->last_w[t], s->last_h[t], ut_format_names[m->targets[t].format]);
        st = gr_meta_set_string(meta, key, val);
    }
    if (st == GR_OK && m->uses_shadow_map) {
        snprintf(val, sizeof val, "%.0f px, half extent %.9g m", s->shadow_size, s->shadow_half_extent);
        st = gr_meta_set_string(meta, "godrays:user_shadow_map", val);
    }
    if (st != GR_OK) return gr_fail(err, st, "%s metadata: cannot add an entry (%s)", m->name, gr_status_name(st));
    return GR_OK;
}
