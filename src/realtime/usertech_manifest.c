/* A user technique's manifest: parsing and validation (usertech_manifest.h,
 * docs/techniques.md). */
/* realpath (XSI) beside the project's _POSIX_C_SOURCE */
#define _DEFAULT_SOURCE
#include "realtime/usertech_manifest.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "realtime/volsettings.h"
#include "scene/scene.h"

const char *const gr_ut_type_names[] = {"number", "int", "bool", "rgb", NULL};
const char *const gr_ut_format_names[] = {"rgba8", "rgba16f", "rgba32f", NULL};
const char *const gr_ut_blend_names[] = {"none", "additive", "alpha", NULL};
const char *const gr_ut_prim_names[] = {"triangles", "triangle_strip", "lines", "points", NULL};

/* ---- small helpers ------------------------------------------------------------------------ */

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

void gr_ut_sb_add(gr_ut_strbuf *b, const char *fmt, ...)
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
    if (!cJSON_IsObject(obj)) return vfail(c, path[0] ? path : "(top level)", "must be an object, got %s", gr_json_type_name(obj));
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
    if (!cJSON_IsString(v)) return vfail(c, p, "must be a string, got %s", gr_json_type_name(v));
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
    if (!cJSON_IsNumber(v)) return vfail(c, p, "must be a number, got %s", gr_json_type_name(v));
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
    if (!cJSON_IsBool(v)) return vfail(c, p, "must be true or false, got %s", gr_json_type_name(v));
    *out = cJSON_IsTrue(v) ? 1 : 0;
    return GR_OK;
}

static int find_setting(const gr_ut_manifest *m, const char *key)
{
    for (int i = 0; i < m->n_settings; i++)
        if (!strcmp(m->settings[i].key, key)) return i;
    return -1;
}

const char *gr_ut_input_name(const gr_ut_manifest *m, int in)
{
    switch (in) {
    case GR_UT_IN_SHADOW_MAP: return "shadow_map";
    case GR_UT_IN_EYE_DEPTH: return "eye_depth";
    case GR_UT_IN_LIGHT: return "sun_light";
    case GR_UT_IN_CAUSTICS: return "caustics";
    case GR_UT_IN_SCENE_COLOUR: return "scene_colour";
    default: return m->targets[in].name;
    }
}

int gr_ut_harness_input(const char *name)
{
    for (int in = -1; in >= -GR_UT_N_HARNESS_INPUTS; in--)
        if (!strcmp(name, gr_ut_input_name(NULL, in))) return in;
    return 0;
}

static int find_target(const gr_ut_manifest *m, const char *name)
{
    for (int i = 0; i < m->n_targets; i++)
        if (!strcmp(m->targets[i].name, name)) return i;
    return -1;
}

/* A number, or the name of a setting of type `want` (GR_UT_NUMBER accepts int settings too)
 * whose whole range lies within [lo, hi]. */
static gr_status value_at(ut_ctx *c, const gr_ut_manifest *m, const cJSON *v, const char *p, gr_ut_type want, double lo,
                          double hi, gr_ut_value *out)
{
    if (cJSON_IsString(v)) {
        int s = find_setting(m, v->valuestring);
        if (s < 0) return vfail(c, p, "'%s' is not a setting of this technique", v->valuestring);
        gr_ut_type t = m->settings[s].type;
        if (!(t == want || (want == GR_UT_NUMBER && t == GR_UT_INT)))
            return vfail(c, p, "setting '%s' is of type %s, this field needs %s", v->valuestring, gr_ut_type_names[t],
                         want == GR_UT_INT ? "an int setting" : "a number or int setting");
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
    if (want == GR_UT_INT && d != floor(d)) return vfail(c, p, "must be an integer, got %g", d);
    if (d < lo || d > hi) return vfail(c, p, "must be in [%g, %g], got %g", lo, hi, d);
    out->setting = -1;
    out->v = d;
    return GR_OK;
}

/* A count: a positive integer, the name of an int setting, or "a*b*..." of those. */
static gr_status count_at(ut_ctx *c, const gr_ut_manifest *m, const cJSON *v, const char *p, gr_ut_count *out)
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
        return vfail(c, p, "must be an integer, an int setting's name or a product such as \"6*N\", got %s", gr_json_type_name(v));
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
        if (m->settings[s].type != GR_UT_INT) return vfail(c, p, "'%s': setting '%s' must be of type int", v->valuestring, tok);
        if (m->params[s].min < 0) return vfail(c, p, "'%s': setting '%s' must have min >= 0", v->valuestring, tok);
        if (out->n_factors == GR_UT_MAX_FACTORS) return vfail(c, p, "'%s': at most %d setting factors", v->valuestring, GR_UT_MAX_FACTORS);
        out->factor[out->n_factors++] = s;
    }
    if (!any) return vfail(c, p, "empty count");
    return GR_OK;
}

/* 1 when real (a resolved path) is root itself or lies below it. */
static int path_inside(const char *root, const char *real)
{
    size_t n = strlen(root);
    if (n == 1 && root[0] == '/') return 1;
    return !strncmp(root, real, n) && (real[n] == '\0' || real[n] == '/');
}

gr_status gr_ut_read_file(const char *dir, const char *path, char **out, char *why, size_t why_n)
{
    *out = NULL;
    /* Containment (docs/techniques.md "The folder and the manifest"): the file's real path,
     * symbolic links and ".." resolved, must lie inside the folder's. Checked before the open,
     * so that nothing outside the folder is read, and no message ever quotes it. */
    char *root = realpath(dir, NULL), *real = root ? realpath(path, NULL) : NULL;
    if (!root || !real) {
        snprintf(why, why_n, "%s", strerror(errno));
        free(root);
        return GR_E_IO;
    }
    int inside = path_inside(root, real);
    free(root);
    if (!inside) {
        free(real);
        snprintf(why, why_n, "outside the technique folder (a link or '..' out of it): not read");
        return GR_E_IO;
    }
    /* O_NONBLOCK: a FIFO or a device must not block the open; fstat then refuses them */
    int fd = open(real, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
    free(real);
    if (fd < 0) {
        snprintf(why, why_n, "%s", strerror(errno));
        return GR_E_IO;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        snprintf(why, why_n, "not a regular file");
        return GR_E_IO;
    }
    if (sb.st_size > GR_UT_MAX_FILE_BYTES) {
        close(fd);
        snprintf(why, why_n, "%lld bytes, over the cap of %d bytes (%d MiB) for a technique's file",
                 (long long)sb.st_size, GR_UT_MAX_FILE_BYTES, GR_UT_MAX_FILE_BYTES >> 20);
        return GR_E_IO;
    }
    /* one byte more than the size: a file that grew since fstat is caught, not truncated */
    size_t cap = (size_t)sb.st_size + 2, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        close(fd);
        snprintf(why, why_n, "out of memory");
        return GR_E_NOMEM;
    }
    int bad = 0;
    for (;;) {
        ssize_t r = read(fd, buf + len, cap - 1 - len);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            snprintf(why, why_n, "read error (%s)", strerror(errno));
            bad = 1;
            break;
        }
        if (r == 0) break;
        len += (size_t)r;
        if (len == cap - 1) {
            snprintf(why, why_n, "changed while read (grew past its size of %lld bytes)", (long long)sb.st_size);
            bad = 1;
            break;
        }
    }
    close(fd);
    if (bad) {
        free(buf);
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

/* The index of `file` (relative to the folder) in m's file table, added if new; -1 when full. */
static int file_index(gr_ut_manifest *m, const char *file)
{
    for (int k = 0; k < m->n_files; k++)
        if (!strcmp(m->files[k], file)) return k;
    if (m->n_files == GR_UT_MAX_FILES || !(m->files[m->n_files] = dup_string(file))) return -1;
    return m->n_files++;
}

/* `#include "NAME"` on this line (leading blanks allowed): 1 with NAME in name, 0 when the
 * line is no include, -1 when it is a malformed one. */
static int include_line(const char *line, size_t len, char *name, size_t n)
{
    size_t i = 0;
    while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
    if (i == len || line[i] != '#') return 0;
    i++;
    while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
    if (len - i < 7 || strncmp(line + i, "include", 7)) return 0;
    i += 7;
    while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
    if (i == len || line[i] != '"') return -1;
    const char *e = memchr(line + i + 1, '"', len - i - 1);
    if (!e || (size_t)(e - (line + i + 1)) >= n || e == line + i + 1) return -1;
    snprintf(name, n, "%.*s", (int)(e - (line + i + 1)), line + i + 1);
    for (const char *q = e + 1; q < line + len; q++)
        if (*q != ' ' && *q != '\t' && *q != '\r') return -1;
    return 1;
}

/* Appends file (relative to the folder) to b with its includes expanded in place (docs/
 * techniques.md "Shared GLSL"): "#line" directives keep every line's file and number
 * (GR_UT_LINE_BASE * (K + 1) + L for line L of files[K]); a
 * "#version" line is blanked (the prelude sets it). from/from_line: the including file and
 * line (NULL for a pass's own file). */
static gr_status expand_file(ut_ctx *c, gr_ut_manifest *m, const char *file, const char *p, const char *from,
                             int from_line, int depth, gr_ut_strbuf *b)
{
    char full[4096], why[256], *src = NULL, at[600] = "";
    if (from) snprintf(at, sizeof at, "%s:%d: #include \"%s\": ", from, from_line, file);
    if (!file[0]) return vfail(c, p, "%sempty file name", at);
    if (file[0] == '/') return vfail(c, p, "%s'%s': an absolute path; a shader's file is relative to the technique folder", at, file);
    if (depth > GR_UT_MAX_INCLUDE_DEPTH)
        return vfail(c, p, "%sincludes nested deeper than %d (an include cycle?)", at, GR_UT_MAX_INCLUDE_DEPTH);
    if (snprintf(full, sizeof full, "%s/%s", m->dir, file) >= (int)sizeof full) return vfail(c, p, "%sfile name too long", at);
    gr_status st = gr_ut_read_file(m->dir, full, &src, why, sizeof why);
    if (st == GR_E_NOMEM) return gr_fail(c->err, st, "%s: %s: out of memory", c->path, p);
    if (st) return vfail(c, p, "%scannot read shader %s: %s", at, full, why);
    int k = file_index(m, file);
    if (k < 0) {
        free(src);
        return vfail(c, p, "%smore than %d shader files (includes counted)", at, GR_UT_MAX_FILES);
    }
    gr_ut_sb_add(b, "#line %d\n", GR_UT_LINE_BASE * (k + 1) + 1);
    int line = 1;
    for (const char *q = src; *q; line++) {
        const char *e = strchr(q, '\n');
        size_t len = e ? (size_t)(e - q) : strlen(q);
        char inc[512], rel[1024];
        int kind = include_line(q, len, inc, sizeof inc);
        if (kind < 0) {
            free(src);
            return vfail(c, p, "%s:%d: malformed #include (expected #include \"file.glsl\")", file, line);
        }
        if (kind > 0) {
            /* relative to the including file's folder, as in C; gr_ut_read_file keeps it inside */
            const char *slash = strrchr(file, '/');
            snprintf(rel, sizeof rel, "%.*s%s", slash ? (int)(slash - file + 1) : 0, file, inc);
            if ((st = expand_file(c, m, rel, p, file, line, depth + 1, b))) {
                free(src);
                return st;
            }
            gr_ut_sb_add(b, "#line %d\n", GR_UT_LINE_BASE * (k + 1) + line + 1);
        } else {
            const char *v = q;
            while (v < q + len && (*v == ' ' || *v == '\t')) v++;
            if ((size_t)(q + len - v) >= 8 && !strncmp(v, "#version", 8)) gr_ut_sb_add(b, "\n");
            else gr_ut_sb_add(b, "%.*s\n", (int)len, q);
        }
        q = e ? e + 1 : q + len;
    }
    free(src);
    return b->failed ? gr_fail(c->err, GR_E_NOMEM, "%s: %s: out of memory", c->path, p) : GR_OK;
}

/* Reads DIR/file named at JSON path p, includes expanded; a missing or unreadable file is bad
 * input (exit 2). */
static gr_status shader_file(ut_ctx *c, gr_ut_manifest *m, const char *file, const char *p, char **src)
{
    gr_ut_strbuf b = {0};
    gr_status st = expand_file(c, m, file, p, NULL, 0, 0, &b);
    if (st) {
        free(b.s);
        return st;
    }
    *src = b.s;
    return GR_OK;
}

/* "defines": {"NAME": number | bool | "text"} -> "#define NAME VALUE" lines. */
static gr_status parse_defines(ut_ctx *c, gr_ut_pass *ps, const cJSON *d, const char *p)
{
    if (!cJSON_IsObject(d)) return vfail(c, p, "must be an object {\"NAME\": value}, got %s", gr_json_type_name(d));
    gr_ut_strbuf b = {0};
    for (const cJSON *e = d->child; e; e = e->next) {
        char q[400], num[40];
        join(q, sizeof q, p, e->string);
        const char *nm = e->string;
        int ok = (isalpha((unsigned char)nm[0]) || nm[0] == '_') && strlen(nm) < 64 && !strstr(nm, "__") &&
                 strncmp(nm, "GL_", 3) && strncmp(nm, "GR_", 3) && strcmp(nm, "GODRAYS");
        for (const char *z = nm; ok && *z; z++) ok = isalnum((unsigned char)*z) || *z == '_';
        if (!ok) {
            free(b.s);
            return vfail(c, q, "'%s' is not a macro name: [A-Za-z_][A-Za-z0-9_]*, under 64 characters, no '__', not GL_*, GR_* or GODRAYS", nm);
        }
        for (const cJSON *f = d->child; f != e; f = f->next)
            if (!strcmp(f->string, nm)) {
                free(b.s);
                return vfail(c, q, "defined twice");
            }
        if (cJSON_IsBool(e)) {
            gr_ut_sb_add(&b, "#define %s %d\n", nm, cJSON_IsTrue(e) ? 1 : 0);
        } else if (cJSON_IsNumber(e) && isfinite(e->valuedouble)) {
            /* an integer stays one (GLSL int), anything else is a float literal */
            if (e->valuedouble == floor(e->valuedouble) && fabs(e->valuedouble) < 2e9) snprintf(num, sizeof num, "%.0f", e->valuedouble);
            else snprintf(num, sizeof num, "%.9g", e->valuedouble);
            if (e->valuedouble != floor(e->valuedouble) && !strpbrk(num, ".e")) strcat(num, ".0");
            gr_ut_sb_add(&b, "#define %s %s\n", nm, num);
        } else if (cJSON_IsString(e) && !strpbrk(e->valuestring, "\n\r\\")) {
            gr_ut_sb_add(&b, "#define %s %s\n", nm, e->valuestring);
        } else {
            free(b.s);
            return vfail(c, q, "must be a number, true/false or a one-line string, got %s", gr_json_type_name(e));
        }
    }
    if (b.failed) {
        free(b.s);
        return gr_fail(c->err, GR_E_NOMEM, "%s: out of memory", c->path);
    }
    ps->defines = b.s;
    return GR_OK;
}

/* ---- manifest sections ------------------------------------------------------------------- */

static gr_status parse_settings(ut_ctx *c, gr_ut_manifest *m, const cJSON *obj)
{
    static const char *const keys[] = {"type", "default", "min", "max", "min_exclusive", "max_exclusive",
                                       "tune", "unit", "doc", NULL};
    gr_status st = check_object(c, obj, "settings", NULL);
    if (st) return st;
    size_t offset = 0;
    for (const cJSON *it = obj->child; it; it = it->next) {
        char p[320], q[360];
        join(p, sizeof p, "settings", it->string);
        if (m->n_settings == GR_UT_MAX_SETTINGS) return vfail(c, p, "more than %d settings", GR_UT_MAX_SETTINGS);
        if (!is_identifier(it->string, 0, GR_TECH_NAME_MAX))
            return vfail(c, p, "a setting's key must be a GLSL-friendly name [A-Za-z][A-Za-z0-9_]* of at most %d characters without '__'",
                         GR_TECH_NAME_MAX - 1);
        if ((st = check_object(c, it, p, keys))) return st;
        int i = m->n_settings;
        gr_ut_setting *s = &m->settings[i];
        gr_param *gp = &m->params[i];
        snprintf(s->key, sizeof s->key, "%s", it->string);
        int type = -1;
        if ((st = get_enum(c, it, p, "type", gr_ut_type_names, &type))) return st;
        if (type < 0) {
            join(q, sizeof q, p, "type");
            return vfail(c, q, "missing (required: number, int, bool or rgb)");
        }
        s->type = (gr_ut_type)type;
        size_t size = s->type == GR_UT_RGB ? 3 * sizeof(double) : sizeof(double);
        s->offset = offset;
        offset += size;
        if (offset > GR_TECH_SETTINGS_MAX) return vfail(c, p, "settings take more than %d bytes", GR_TECH_SETTINGS_MAX);
        gp->name = s->key;
        gp->offset = s->offset;
        gp->type = s->type == GR_UT_NUMBER ? GR_PT_DOUBLE : s->type == GR_UT_INT ? GR_PT_INT : s->type == GR_UT_BOOL ? GR_PT_BOOL : GR_PT_RGB;
        /* range */
        const cJSON *vmin = cJSON_GetObjectItemCaseSensitive(it, "min");
        const cJSON *vmax = cJSON_GetObjectItemCaseSensitive(it, "max");
        if (s->type == GR_UT_BOOL) {
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
            if (s->type == GR_UT_INT && (gp->min != floor(gp->min) || gp->max != floor(gp->max) ||
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
        if (s->type == GR_UT_BOOL) {
            if (!cJSON_IsBool(vdef)) return vfail(c, q, "must be true or false, got %s", gr_json_type_name(vdef));
            gp->def = cJSON_IsTrue(vdef) ? 1 : 0;
        } else {
            if (s->type == GR_UT_RGB && cJSON_IsArray(vdef))
                return vfail(c, q, "an rgb setting's default is one number (the same for r, g and b)");
            if ((st = number_at(c, vdef, q, &gp->def))) return st;
            if (s->type == GR_UT_INT && gp->def != floor(gp->def)) return vfail(c, q, "must be an integer, got %g", gp->def);
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
            if (s->type != GR_UT_NUMBER && s->type != GR_UT_RGB)
                return vfail(c, q, "only number and rgb settings are tuned (int settings are swept)");
            if (!cJSON_IsArray(vt) || cJSON_GetArraySize(vt) != 2) return vfail(c, q, "must be [lo, hi]");
            double lh[2] = {0, 0};
            for (int k = 0; k < 2; k++) {
                char e[380];
                snprintf(e, sizeof e, "%s[%d]", q, k);
                if ((st = number_at(c, cJSON_GetArrayItem(vt, k), e, &lh[k]))) return st;
            }
            if (!(lh[0] < lh[1])) return vfail(c, q, "lo (%g) must be below hi (%g)", lh[0], lh[1]);
            if (s->type == GR_UT_NUMBER && (lh[0] < gp->min || lh[1] > gp->max))
                return vfail(c, q, "[%g, %g] is not within the setting's range [%g, %g]", lh[0], lh[1], gp->min, gp->max);
            if (s->type == GR_UT_RGB && lh[0] < 0) return vfail(c, q, "an rgb setting is tuned as a scale: lo must be >= 0");
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

static gr_status parse_targets(ut_ctx *c, gr_ut_manifest *m, const cJSON *obj)
{
    static const char *const keys[] = {"scale", "size", "format", "filter", NULL};
    static const char *const filters[] = {"linear", "nearest", NULL};
    gr_status st = check_object(c, obj, "targets", NULL);
    if (st) return st;
    if (!obj->child) return vfail(c, "targets", "must name at least one render target");
    for (const cJSON *it = obj->child; it; it = it->next) {
        char p[320], q[360];
        join(p, sizeof p, "targets", it->string);
        if (m->n_targets == GR_UT_MAX_TARGETS) return vfail(c, p, "more than %d targets", GR_UT_MAX_TARGETS);
        if (!is_identifier(it->string, 1, GR_UT_NAME_MAX))
            return vfail(c, p, "a target's name must be [a-z][a-z0-9_]* of at most %d characters without '__'", GR_UT_NAME_MAX - 1);
        if (gr_ut_harness_input(it->string) < 0) return vfail(c, p, "'%s' is the name of a harness texture", it->string);
        if ((st = check_object(c, it, p, keys))) return st;
        gr_ut_target *t = &m->targets[m->n_targets];
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
            if ((st = value_at(c, m, vs, q, GR_UT_NUMBER, 1.0 / 64.0, 4.0, &t->scale))) return st;
        } else if (vz) {
            join(q, sizeof q, p, "size");
            if (!cJSON_IsArray(vz) || cJSON_GetArraySize(vz) != 2) return vfail(c, q, "must be [width, height] in pixels");
            double d[2] = {0, 0};
            for (int k = 0; k < 2; k++) {
                char e[380];
                snprintf(e, sizeof e, "%s[%d]", q, k);
                if ((st = number_at(c, cJSON_GetArrayItem(vz, k), e, &d[k]))) return st;
                if (!(d[k] >= 1 && d[k] <= GR_UT_MAX_SIZE && d[k] == floor(d[k])))
                    return vfail(c, e, "must be an integer in [1, %d], got %g", GR_UT_MAX_SIZE, d[k]);
            }
            t->absolute = 1;
            t->width = (int)d[0];
            t->height = (int)d[1];
        }
        int fmt = -1, filt = 0;
        if ((st = get_enum(c, it, p, "format", gr_ut_format_names, &fmt))) return st;
        if (fmt < 0) {
            join(q, sizeof q, p, "format");
            return vfail(c, q, "missing (required: rgba8, rgba16f or rgba32f)");
        }
        t->format = (gr_ut_format)fmt;
        if ((st = get_enum(c, it, p, "filter", filters, &filt))) return st;
        t->linear = filt == 0;
        m->n_targets++;
    }
    return GR_OK;
}

static gr_status parse_pass(ut_ctx *c, gr_ut_manifest *m, const cJSON *it, int idx, const int *written)
{
    static const char *const keys[] = {"name", "vertex", "fragment", "draw", "target", "blend", "clear", "inputs", "defines", NULL};
    static const char *const draw_keys[] = {"primitive", "vertices", "instances", NULL};
    char p[64], q[320], list[400];
    gr_status st;
    snprintf(p, sizeof p, "passes[%d]", idx);
    if ((st = check_object(c, it, p, keys))) return st;
    gr_ut_pass *ps = &m->passes[idx];
    const char *s = NULL;
    if ((st = get_string(c, it, p, "name", 0, &s))) return st;
    if (s) {
        join(q, sizeof q, p, "name");
        if (!is_identifier(s, 1, GR_UT_NAME_MAX))
            return vfail(c, q, "a pass's name must be [a-z][a-z0-9_]* of at most %d characters", GR_UT_NAME_MAX - 1);
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
        if ((st = get_enum(c, d, q, "primitive", gr_ut_prim_names, &prim))) return st;
        if (prim < 0) {
            char r[360];
            join(r, sizeof r, q, "primitive");
            list_text(gr_ut_prim_names, list, sizeof list);
            return vfail(c, r, "missing (required: one of %s)", list);
        }
        ps->fullscreen = 0;
        ps->prim = (gr_ut_prim)prim;
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
        const char *names[GR_UT_MAX_TARGETS + 1];
        for (int k = 0; k < m->n_targets; k++) names[k] = m->targets[k].name;
        names[m->n_targets] = NULL;
        list_text(names, list, sizeof list);
        return vfail(c, q, "unknown target '%s' (targets: %s)", s, list);
    }
    int blend = GR_UT_BLEND_NONE;
    if ((st = get_enum(c, it, p, "blend", gr_ut_blend_names, &blend))) return st;
    ps->blend = (gr_ut_blend)blend;
    /* clear */
    const cJSON *vc = cJSON_GetObjectItemCaseSensitive(it, "clear");
    join(q, sizeof q, p, "clear");
    if (vc && !cJSON_IsFalse(vc)) {
        if (!cJSON_IsArray(vc) || cJSON_GetArraySize(vc) != 4)
            return vfail(c, q, "must be [r, g, b, a] or false, got %s", gr_json_type_name(vc));
        for (int k = 0; k < 4; k++) {
            char r[360];
            double x = 0;
            snprintf(r, sizeof r, "%s[%d]", q, k);
            if ((st = number_at(c, cJSON_GetArrayItem(vc, k), r, &x))) return st;
            ps->clear[k] = (float)x;
        }
        ps->has_clear = 1;
    }
    const cJSON *vdef = cJSON_GetObjectItemCaseSensitive(it, "defines");
    join(q, sizeof q, p, "defines");
    if (vdef && (st = parse_defines(c, ps, vdef, q))) return st;
    /* inputs */
    const cJSON *vin = cJSON_GetObjectItemCaseSensitive(it, "inputs");
    join(q, sizeof q, p, "inputs");
    if (vin) {
        if (!cJSON_IsArray(vin)) return vfail(c, q, "must be an array of names, got %s", gr_json_type_name(vin));
        int k = 0;
        for (const cJSON *e = vin->child; e; e = e->next, k++) {
            char r[360];
            snprintf(r, sizeof r, "%s[%d]", q, k);
            if (k == GR_UT_MAX_INPUTS) return vfail(c, q, "more than %d inputs", GR_UT_MAX_INPUTS);
            if (!cJSON_IsString(e)) return vfail(c, r, "must be a string, got %s", gr_json_type_name(e));
            const char *nm = e->valuestring;
            int in = gr_ut_harness_input(nm);
            if (in == GR_UT_IN_SHADOW_MAP) m->uses_shadow_map = 1;
            else if (in == GR_UT_IN_EYE_DEPTH) m->uses_eye_depth = 1;
            else if (in == GR_UT_IN_LIGHT) m->uses_light = 1;
            else if (in == GR_UT_IN_CAUSTICS) m->uses_caustics = 1;
            else if (in == GR_UT_IN_SCENE_COLOUR) m->uses_scene_colour = 1;
            if (in == 0) {
                in = find_target(m, nm);
                if (in < 0) return vfail(c, r, "unknown input '%s' (a target's name, " GR_UT_HARNESS_INPUTS ")", nm);
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
static gr_status parse_ladder(ut_ctx *c, gr_ut_manifest *m, const cJSON *lad)
{
    static const char *const keys[] = {"settings", "quick", NULL};
    if (!cJSON_IsArray(lad)) return vfail(c, "ladder", "must be an array of levels, got %s", gr_json_type_name(lad));
    if (cJSON_GetArraySize(lad) > GR_UT_MAX_LADDER) return vfail(c, "ladder", "more than %d levels", GR_UT_MAX_LADDER);
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
        gr_ut_strbuf b = {0};
        for (const cJSON *e = set->child; e; e = e->next) {
            char r[360], num[40];
            join(r, sizeof r, q, e->string);
            int k = find_setting(m, e->string);
            if (k < 0) {
                free(b.s);
                return vfail(c, r, "'%s' is not a setting of this technique", e->string);
            }
            double v = 0;
            if (m->settings[k].type == GR_UT_BOOL) {
                if (!cJSON_IsBool(e)) {
                    free(b.s);
                    return vfail(c, r, "must be true or false, got %s", gr_json_type_name(e));
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
            if (m->settings[k].type == GR_UT_BOOL) snprintf(num, sizeof num, "%s", v != 0 ? "true" : "false");
            else gr_format_double(v, num, sizeof num);
            gr_ut_sb_add(&b, "%s%s=%s", b.len ? "," : "", e->string, num);
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

/* "sun_light": {"scale", "format", "radius_deg", "threshold", "occluders"} (docs/techniques.md
 * "Harness textures"); the defaults are radial_blur's. */
static gr_status parse_light(ut_ctx *c, gr_ut_manifest *m, const cJSON *lt)
{
    static const char *const keys[] = {"scale", "format", "radius_deg", "threshold", "occluders", NULL};
    m->light_scale = (gr_ut_value){0.5, -1};
    m->light_radius_deg = (gr_ut_value){4.0, -1};
    m->light_threshold = (gr_ut_value){0.0, -1};
    m->light_format = GR_UT_FMT_RGBA16F;
    m->light_occluders = 1;
    if (!lt) return GR_OK;
    gr_status st = check_object(c, lt, "sun_light", keys);
    if (st) return st;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(lt, "scale");
    if (v && (st = value_at(c, m, v, "sun_light.scale", GR_UT_NUMBER, 1.0 / 64.0, 4.0, &m->light_scale))) return st;
    v = cJSON_GetObjectItemCaseSensitive(lt, "radius_deg");
    if (v && (st = value_at(c, m, v, "sun_light.radius_deg", GR_UT_NUMBER, 0.01, 90, &m->light_radius_deg))) return st;
    v = cJSON_GetObjectItemCaseSensitive(lt, "threshold");
    if (v && (st = value_at(c, m, v, "sun_light.threshold", GR_UT_NUMBER, 0, 0.999, &m->light_threshold))) return st;
    int fmt = GR_UT_FMT_RGBA16F;
    if ((st = get_enum(c, lt, "sun_light", "format", gr_ut_format_names, &fmt))) return st;
    if (fmt >= 0) m->light_format = (gr_ut_format)fmt;
    return get_bool(c, lt, "sun_light", "occluders", &m->light_occluders);
}

/* "caustics": the volume techniques' caustic settings (realtime/volsettings.h
 * gr_vol_caustic_descriptors: the same keys, ranges and defaults), each a number or a setting's
 * name, sun_disc a bool; caustic_last_m >= caustic_first_m (gr_vol_check) when both are numbers. */
static gr_status parse_caustics(ut_ctx *c, gr_ut_manifest *m, const cJSON *obj)
{
    size_t n = 0;
    const gr_param *d = gr_vol_caustic_descriptors(&n);
    const char *keys[GR_UT_CAUSTIC_VALUES + 1] = {NULL};
    if (n > GR_UT_CAUSTIC_VALUES) return gr_fail(c->err, GR_E_RUNTIME, "caustics: %zu descriptors", n);
    m->n_caustic_values = (int)n;
    for (size_t i = 0; i < n; i++) {
        keys[i] = d[i].name;
        m->caustic[i] = (gr_ut_value){d[i].def, -1};
    }
    if (!obj) return GR_OK;
    gr_status st = check_object(c, obj, "caustics", keys);
    if (st) return st;
    gr_vol_settings vs;
    memset(&vs, 0, sizeof vs);
    int literal = 1;
    for (size_t i = 0; i < n; i++) {
        char p[96];
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, d[i].name);
        snprintf(p, sizeof p, "caustics.%s", d[i].name);
        if (d[i].type == GR_PT_BOOL) {
            int b = d[i].def != 0;
            if ((st = get_bool(c, obj, "caustics", d[i].name, &b))) return st;
            m->caustic[i].v = b;
        } else if (v) {
            gr_ut_type t = d[i].type == GR_PT_INT ? GR_UT_INT : GR_UT_NUMBER;
            if ((st = value_at(c, m, v, p, t, d[i].min, d[i].max, &m->caustic[i]))) return st;
            const gr_ut_value *u = &m->caustic[i];
            /* an exclusive lower end (patch_m, the depths: > 0): a number equal to it, or a
             * setting whose range reaches it inclusively */
            const gr_param *sp = u->setting >= 0 ? &m->params[u->setting] : NULL;
            if ((d[i].flags & GR_PF_MIN_EXCL) &&
                (sp ? sp->min <= d[i].min && !(sp->flags & GR_PF_MIN_EXCL) : u->v <= d[i].min))
                return vfail(c, p, "must be > %g%s", d[i].min, u->setting < 0 ? "" : " over the setting's whole range");
        }
        if (m->caustic[i].setting >= 0) literal = 0;
        const gr_param_table tab = {"caustics", d, n};
        if ((st = gr_param_set_number(&tab, &vs, d[i].name, -1, m->caustic[i].v, c->err))) return st;
    }
    if (literal && gr_vol_check("caustics", &vs, c->err) != GR_OK) {
        gr_error_prefix(c->err, "%s", c->path);
        return GR_E_INPUT;
    }
    return GR_OK;
}

/* "scene_colour": {"scale", "format", "albedo", "radius_deg"} (realtime/scenecolour.h); albedo
 * a number, [r, g, b] or a number or rgb setting's name, in [0, 1]. */
static gr_status parse_scene_colour(ut_ctx *c, gr_ut_manifest *m, const cJSON *obj)
{
    static const char *const keys[] = {"scale", "format", "albedo", "radius_deg", NULL};
    m->scol_scale = (gr_ut_value){1.0, -1};
    m->scol_radius_deg = (gr_ut_value){4.0, -1};
    m->scol_format = GR_UT_FMT_RGBA32F;
    m->scol_albedo[0] = m->scol_albedo[1] = m->scol_albedo[2] = 0.3;
    m->scol_albedo_setting = -1;
    if (!obj) return GR_OK;
    gr_status st = check_object(c, obj, "scene_colour", keys);
    if (st) return st;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (v && (st = value_at(c, m, v, "scene_colour.scale", GR_UT_NUMBER, 1.0 / 64.0, 4.0, &m->scol_scale))) return st;
    v = cJSON_GetObjectItemCaseSensitive(obj, "radius_deg");
    if (v && (st = value_at(c, m, v, "scene_colour.radius_deg", GR_UT_NUMBER, 0.01, 90, &m->scol_radius_deg)))
        return st;
    int fmt = GR_UT_FMT_RGBA16F;
    if ((st = get_enum(c, obj, "scene_colour", "format", gr_ut_format_names, &fmt))) return st;
    if (fmt >= 0) m->scol_format = (gr_ut_format)fmt;
    v = cJSON_GetObjectItemCaseSensitive(obj, "albedo");
    if (!v) return GR_OK;
    const char *p = "scene_colour.albedo";
    if (cJSON_IsString(v)) {
        int k = find_setting(m, v->valuestring);
        if (k < 0) return vfail(c, p, "'%s' is not a setting of this technique", v->valuestring);
        gr_ut_type t = m->settings[k].type;
        const gr_param *gp = &m->params[k];
        if (t != GR_UT_NUMBER && t != GR_UT_RGB)
            return vfail(c, p, "setting '%s' is of type %s, this field needs a number or rgb setting", v->valuestring,
                         gr_ut_type_names[t]);
        if (gp->min < 0 || gp->max > 1)
            return vfail(c, p, "setting '%s' has range [%g, %g], an albedo needs values within [0, 1]", v->valuestring,
                         gp->min, gp->max);
        m->scol_albedo_setting = k;
        return GR_OK;
    }
    if (cJSON_IsArray(v)) {
        if (cJSON_GetArraySize(v) != 3) return vfail(c, p, "must be a number or [r, g, b] in [0, 1]");
        for (int k = 0; k < 3; k++) {
            char q[64];
            snprintf(q, sizeof q, "%s[%d]", p, k);
            if ((st = number_at(c, cJSON_GetArrayItem(v, k), q, &m->scol_albedo[k]))) return st;
            if (!(m->scol_albedo[k] >= 0 && m->scol_albedo[k] <= 1))
                return vfail(c, q, "must be in [0, 1] (an albedo), got %g", m->scol_albedo[k]);
        }
        return GR_OK;
    }
    double a = 0;
    if (!cJSON_IsNumber(v))
        return vfail(c, p, "must be a number, [r, g, b] or a setting's name, got %s", gr_json_type_name(v));
    if ((st = number_at(c, v, p, &a))) return st;
    if (!(a >= 0 && a <= 1)) return vfail(c, p, "must be in [0, 1] (an albedo), got %g", a);
    m->scol_albedo[0] = m->scol_albedo[1] = m->scol_albedo[2] = a;
    return GR_OK;
}

static gr_status parse_manifest(ut_ctx *c, gr_ut_manifest *m, const cJSON *root)
{
    static const char *const keys[] = {"version", "name", "description", "settings", "gain", "ladder", "shadow_map",
                                       "sun_light", "caustics", "scene_colour", "targets", "passes", "output",
                                       "allow_black", NULL};
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
        if (!cJSON_IsString(gain)) return vfail(c, "gain", "must be a setting's name, got %s", gr_json_type_name(gain));
        int g = find_setting(m, gain->valuestring);
        if (g < 0) return vfail(c, "gain", "'%s' is not a setting of this technique", gain->valuestring);
        if (m->settings[g].type != GR_UT_NUMBER && m->settings[g].type != GR_UT_RGB)
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
    if (cJSON_GetArraySize(ps) > GR_UT_MAX_PASSES) return vfail(c, "passes", "more than %d passes", GR_UT_MAX_PASSES);
    int written[GR_UT_MAX_TARGETS] = {0};
    int i = 0;
    for (const cJSON *it = ps->child; it; it = it->next, i++) {
        if ((st = parse_pass(c, m, it, i, written))) return st;
        written[m->passes[i].target] = 1;
        m->n_passes = i + 1;
    }

    const cJSON *out = cJSON_GetObjectItemCaseSensitive(root, "output");
    m->output = m->passes[m->n_passes - 1].target;
    if (out) {
        if (!cJSON_IsString(out)) return vfail(c, "output", "must be a target's name, got %s", gr_json_type_name(out));
        m->output = find_target(m, out->valuestring);
        if (m->output < 0) return vfail(c, "output", "unknown target '%s'", out->valuestring);
        if (!written[m->output]) return vfail(c, "output", "no pass writes target '%s'", out->valuestring);
    }
    const gr_ut_target *ot = &m->targets[m->output];
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
        if (v && (st = value_at(c, m, v, "shadow_map.size", GR_UT_INT, 16, 8192, &m->shadow_size))) return st;
        v = cJSON_GetObjectItemCaseSensitive(sm, "half_extent_m");
        if (v && (st = value_at(c, m, v, "shadow_map.half_extent_m", GR_UT_NUMBER, 0.01, 1e5, &m->shadow_half_extent)))
            return st;
    }
    if ((st = parse_light(c, m, cJSON_GetObjectItemCaseSensitive(root, "sun_light")))) return st;
    if ((st = parse_caustics(c, m, cJSON_GetObjectItemCaseSensitive(root, "caustics")))) return st;
    if ((st = parse_scene_colour(c, m, cJSON_GetObjectItemCaseSensitive(root, "scene_colour")))) return st;
    /* the scene colour needs the shadow map (with occluders) and the caustic stack too */
    int timed = m->n_passes + (m->uses_shadow_map || m->uses_scene_colour) + m->uses_eye_depth + m->uses_light +
                (m->uses_caustics || m->uses_scene_colour) + m->uses_scene_colour;
    if (timed > GR_TECH_MAX_PASSES)
        return vfail(c, "passes", "%d passes and %d harness inputs make %d timed passes, at most %d", m->n_passes,
                     timed - m->n_passes, timed, GR_TECH_MAX_PASSES);
    return GR_OK;
}

void gr_ut_manifest_free(gr_ut_manifest *m)
{
    if (!m) return;
    for (int i = 0; i < GR_UT_MAX_PASSES; i++) {
        free(m->passes[i].vertex_file);
        free(m->passes[i].fragment_file);
        free(m->passes[i].vertex_src);
        free(m->passes[i].fragment_src);
        free(m->passes[i].defines);
    }
    for (int i = 0; i < m->n_files; i++) free(m->files[i]);
    for (int i = 0; i < GR_UT_MAX_SETTINGS; i++) {
        free(m->param_strings[i][0]);
        free(m->param_strings[i][1]);
    }
    for (int i = 0; i < GR_UT_MAX_LADDER; i++) free(m->ladder_text[i]);
    free(m->description);
    free(m->dir);
    free(m->path);
    free(m);
}

static unsigned long long fnv1a(unsigned long long h, const char *s)
{
    for (const unsigned char *q = (const unsigned char *)s; *q; q++) {
        h ^= *q;
        h *= 1099511628211ULL;
    }
    return h;
}

gr_status gr_ut_manifest_load(const char *dir, gr_ut_manifest **out, gr_error *err)
{
    *out = NULL;
    struct stat sb;
    if (!dir || !dir[0]) return gr_fail(err, GR_E_USAGE, "--technique-dir: empty folder name");
    if (stat(dir, &sb) != 0) return gr_fail(err, GR_E_INPUT, "--technique-dir %s: %s", dir, strerror(errno));
    if (!S_ISDIR(sb.st_mode)) return gr_fail(err, GR_E_INPUT, "--technique-dir %s: not a folder", dir);
    gr_ut_manifest *m = calloc(1, sizeof *m);
    if (!m) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", dir);
    size_t dl = strlen(dir);
    while (dl > 1 && dir[dl - 1] == '/') dl--;
    m->dir = malloc(dl + 1);
    m->path = malloc(dl + sizeof "/" GR_USERTECH_MANIFEST);
    if (!m->dir || !m->path) {
        gr_ut_manifest_free(m);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", dir);
    }
    memcpy(m->dir, dir, dl);
    m->dir[dl] = '\0';
    sprintf(m->path, "%s/%s", m->dir, GR_USERTECH_MANIFEST);
    char *text = NULL, why[256];
    gr_status st = gr_ut_read_file(m->dir, m->path, &text, why, sizeof why);
    if (st) {
        st = gr_fail(err, st == GR_E_NOMEM ? GR_E_NOMEM : GR_E_INPUT, "%s: cannot read the manifest: %s", m->path, why);
        gr_ut_manifest_free(m);
        return st;
    }
    cJSON *root = NULL;
    st = gr_json_parse(text, m->path, &root, err);
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
            if (m->passes[i].defines) h = fnv1a(h, m->passes[i].defines);
        }
        snprintf(m->source_hash, sizeof m->source_hash, "%016llx", h);
    }
    free(text);
    cJSON_Delete(root);
    if (st) {
        gr_ut_manifest_free(m);
        return st;
    }
    m->table.section = m->name;
    m->table.params = m->params;
    m->table.count = (size_t)m->n_settings;
    *out = m;
    return GR_OK;
}
