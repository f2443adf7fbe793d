/* A view suite: the suite file (docs/scene-format.md "Suites") parsed with cJSON, checked key by
 * key, and every case's scene loaded through the scene loader with the case's overrides, so that
 * a case is validated exactly as `godrays validate SCENE --set ...` would validate it.
 *
 * A case's overrides are "json.path=value" strings (the `--set` syntax): the suite's size
 * (camera.width, camera.height), then the case's "set" list, then the members of its structured
 * "camera", "sun", "water" and "medium" objects (each member KEY: "SECTION.KEY=VALUE", the value
 * printed back as JSON), then the caller's (the command line's --set/--size). Each override
 * remembers where it came from in the suite file, so that the scene loader's error about an
 * override ("--set OV: reason") is reworded to name the suite file and that JSON path. */
#include "suite/suite.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/outfile.h"

#define SUITE_MAX_BYTES (4u << 20)  /* a suite file is a short list: refuse anything near this */
#define SUITE_MAX_CASES 1024
#define SUITE_MAX_OVERRIDES 256     /* per case */

static const char *const suite_keys[] = {"version", "name", "description", "size", "cases", NULL};
static const char *const case_keys[] = {"name", "split", "scene", "description", "set",
                                        "camera", "sun", "water", "medium", NULL};
/* the structured overrides: a case's object under each of these names becomes SECTION.KEY=V */
static const char *const struct_sections[] = {"camera", "sun", "water", "medium", NULL};

const char *gr_split_name(gr_split split)
{
    return split == GR_SPLIT_TEST ? "test" : "train";
}

int gr_suite_count(const gr_suite *suite, gr_split split)
{
    int n = 0;
    for (int i = 0; suite && i < suite->n_cases; i++) n += suite->cases[i].split == split;
    return n;
}

int gr_suite_find(const gr_suite *suite, const char *name)
{
    for (int i = 0; suite && name && i < suite->n_cases; i++)
        if (!strcmp(suite->cases[i].name, name)) return i;
    return -1;
}

void gr_suite_destroy(gr_suite *suite)
{
    if (!suite) return;
    free(suite->cases);
    free(suite);
}

/* Every key of object v is one of allowed; else "FILE: WHERE.KEY: unknown key (known: ...)". */
static gr_status check_keys(const char *file, const char *where, const cJSON *v, const char *const *allowed,
                            gr_error *err)
{
    for (const cJSON *c = v->child; c; c = c->next) {
        int ok = 0;
        for (int k = 0; allowed[k] && !ok; k++) ok = !strcmp(c->string, allowed[k]);
        if (ok) continue;
        char known[256] = "";
        for (int k = 0; allowed[k]; k++) {
            const size_t l = strlen(known);
            snprintf(known + l, sizeof known - l, "%s%s", k ? ", " : "", allowed[k]);
        }
        return gr_fail(err, GR_E_INPUT, "%s: %s%s%.64s: unknown key (known: %s)", file, where, where[0] ? "." : "",
                       c->string, known);
    }
    return GR_OK;
}

/* A name: 1..GR_SUITE_NAME_MAX-1 characters of [a-z0-9_-]. */
static gr_status check_name(const char *file, const char *where, const cJSON *v, char *out, gr_error *err)
{
    if (!cJSON_IsString(v))
        return gr_fail(err, GR_E_INPUT, "%s: %s: must be a string, got %s", file, where, gr_json_type_name(v));
    const char *s = v->valuestring;
    const size_t n = strlen(s);
    if (n == 0 || n >= GR_SUITE_NAME_MAX)
        return gr_fail(err, GR_E_INPUT, "%s: %s: must have 1 to %d characters", file, where, GR_SUITE_NAME_MAX - 1);
    if (strspn(s, "abcdefghijklmnopqrstuvwxyz0123456789_-") != n)
        return gr_fail(err, GR_E_INPUT, "%s: %s: '%.64s': only a-z, 0-9, '_' and '-' (it names files)", file, where, s);
    memcpy(out, s, n + 1);
    return GR_OK;
}

/* An optional string of fewer than n bytes into out. */
static gr_status get_text(const char *file, const char *where, const cJSON *v, char *out, size_t n, gr_error *err)
{
    out[0] = '\0';
    if (!v) return GR_OK;
    if (!cJSON_IsString(v))
        return gr_fail(err, GR_E_INPUT, "%s: %s: must be a string, got %s", file, where, gr_json_type_name(v));
    if (strlen(v->valuestring) >= n)
        return gr_fail(err, GR_E_INPUT, "%s: %s: longer than %zu characters", file, where, n - 1);
    memcpy(out, v->valuestring, strlen(v->valuestring) + 1);
    return GR_OK;
}

/* "size": "WxH", the suite's render size. */
static gr_status get_size(const char *file, const cJSON *v, gr_suite *s, gr_error *err)
{
    if (!v) return GR_OK;
    if (!cJSON_IsString(v))
        return gr_fail(err, GR_E_INPUT, "%s: size: must be a string \"WxH\" (e.g. \"320x180\"), got %s", file,
                       gr_json_type_name(v));
    char tail;
    int w = 0, h = 0;
    if (sscanf(v->valuestring, "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 65536 || h > 65536)
        return gr_fail(err, GR_E_INPUT, "%s: size: '%.64s': expected WxH with positive W and H (e.g. \"320x180\")",
                       file, v->valuestring);
    s->width = w;
    s->height = h;
    return GR_OK;
}

/* One case's overrides and where each came from (NULL: the caller's). */
typedef struct ov_list {
    int n;
    char *ov[SUITE_MAX_OVERRIDES];
    char *where[SUITE_MAX_OVERRIDES];
} ov_list;

static void ov_free(ov_list *l)
{
    for (int i = 0; i < l->n; i++) {
        free(l->ov[i]);
        free(l->where[i]);
    }
    l->n = 0;
}

static gr_status ov_add(ov_list *l, const char *file, const char *ov, const char *where, gr_error *err)
{
    if (l->n >= SUITE_MAX_OVERRIDES)
        return gr_fail(err, GR_E_INPUT, "%s: %s: more than %d overrides in one case", file, where ? where : "--set",
                       SUITE_MAX_OVERRIDES);
    char *o = strdup(ov), *w = where ? strdup(where) : NULL;
    if (!o || (where && !w)) {
        free(o);
        free(w);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", file);
    }
    l->ov[l->n] = o;
    l->where[l->n++] = w;
    return GR_OK;
}

/* The case's "set" list and structured objects as overrides (at is "cases[i]"). */
static gr_status case_overrides(const char *file, const char *at, const cJSON *c, ov_list *l, gr_error *err)
{
    char where[256];
    gr_status st = GR_OK;
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(c, "set");
    if (set && !cJSON_IsArray(set))
        return gr_fail(err, GR_E_INPUT, "%s: %s.set: must be an array of \"json.path=value\" strings, got %s", file,
                       at, gr_json_type_name(set));
    int j = 0;
    for (const cJSON *e = set ? set->child : NULL; e && st == GR_OK; e = e->next, j++) {
        snprintf(where, sizeof where, "%s.set[%d]", at, j);
        if (!cJSON_IsString(e) || !strchr(e->valuestring, '=') || e->valuestring[0] == '=')
            return gr_fail(err, GR_E_INPUT, "%s: %s: must be a string \"json.path=value\"", file, where);
        st = ov_add(l, file, e->valuestring, where, err);
    }
    for (int k = 0; struct_sections[k] && st == GR_OK; k++) {
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(c, struct_sections[k]);
        if (!o) continue;
        if (!cJSON_IsObject(o))
            return gr_fail(err, GR_E_INPUT, "%s: %s.%s: must be an object of scene keys, got %s", file, at,
                           struct_sections[k], gr_json_type_name(o));
        for (const cJSON *m = o->child; m && st == GR_OK; m = m->next) {
            snprintf(where, sizeof where, "%s.%s.%.64s", at, struct_sections[k], m->string);
            char *val = cJSON_PrintUnformatted(m);
            if (!val) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", file);
            char ov[1024];
            const int w = snprintf(ov, sizeof ov, "%s.%s=%s", struct_sections[k], m->string, val);
            free(val);
            if (w < 0 || w >= (int)sizeof ov) return gr_fail(err, GR_E_INPUT, "%s: %s: value too long", file, where);
            st = ov_add(l, file, ov, where, err);
        }
    }
    return st;
}

/* The case's scene path, relative to the suite file's folder unless absolute. */
static gr_status resolve_scene(const char *file, const char *at, const cJSON *v, char *out, size_t n, gr_error *err)
{
    if (!v) return gr_fail(err, GR_E_INPUT, "%s: %s.scene: missing (the case's scene file, relative to the suite)", file, at);
    if (!cJSON_IsString(v) || !v->valuestring[0])
        return gr_fail(err, GR_E_INPUT, "%s: %s.scene: must be a non-empty string, got %s", file, at,
                       gr_json_type_name(v));
    const char *slash = strrchr(file, '/');
    const int dirlen = v->valuestring[0] == '/' || !slash ? 0 : (int)(slash - file) + 1;
    if (snprintf(out, n, "%.*s%s", dirlen, file, v->valuestring) >= (int)n)
        return gr_fail(err, GR_E_INPUT, "%s: %s.scene: path too long", file, at);
    return GR_OK;
}

/* The scene loader's message about the case's scene, reworded to name the suite file: an
 * override's error ("--set OV: reason") names that override's JSON path in the suite. The
 * scene file's own errors keep their file name; unreadable scenes are bad suites (exit 2). */
static gr_status scene_error(const char *file, const char *at, const gr_suite_case *sc, const ov_list *l,
                             gr_status st, gr_error *err)
{
    char msg[GR_ERROR_MSG_MAX];
    snprintf(msg, sizeof msg, "%s", err->msg);
    for (int i = l->n - 1; i >= 0; i--) {
        char head[1100];
        snprintf(head, sizeof head, "--set %s: ", l->ov[i]);
        if (strncmp(msg, head, strlen(head)) != 0) continue;
        if (l->where[i])
            return gr_fail(err, st == GR_E_IO ? GR_E_INPUT : st, "%s: %s: %s", file, l->where[i], msg + strlen(head));
        break; /* the caller's override: its own words, under the case */
    }
    if (st == GR_E_IO) {
        gr_fail(err, GR_E_INPUT, "%s: %s.scene: %s", file, at, msg);
        return GR_E_INPUT;
    }
    gr_fail(err, st, "%s: %s (%s): %s", file, at, sc->name, msg);
    return st;
}

/* cases[i]: name, split, scene and overrides checked, the scene loaded. */
static gr_status load_case(const char *file, int i, const cJSON *c, const gr_suite *s, const char *const *extra,
                           int n_extra, gr_suite_case *sc, gr_error *err)
{
    char at[32], where[64];
    snprintf(at, sizeof at, "cases[%d]", i);
    if (!cJSON_IsObject(c))
        return gr_fail(err, GR_E_INPUT, "%s: %s: must be an object, got %s", file, at, gr_json_type_name(c));
    gr_status st = check_keys(file, at, c, case_keys, err);
    if (st != GR_OK) return st;
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(c, "name");
    snprintf(where, sizeof where, "%s.name", at);
    if (!name) return gr_fail(err, GR_E_INPUT, "%s: %s: missing", file, where);
    if ((st = check_name(file, where, name, sc->name, err)) != GR_OK) return st;
    for (int k = 0; k < i; k++)
        if (!strcmp(s->cases[k].name, sc->name))
            return gr_fail(err, GR_E_INPUT, "%s: %s: '%s' is also the name of cases[%d]", file, where, sc->name, k);
    const cJSON *split = cJSON_GetObjectItemCaseSensitive(c, "split");
    if (!cJSON_IsString(split) || (strcmp(split->valuestring, "train") && strcmp(split->valuestring, "test")))
        return gr_fail(err, GR_E_INPUT, "%s: %s.split: must be \"train\" or \"test\"%s", file, at,
                       split ? "" : " (missing)");
    sc->split = strcmp(split->valuestring, "test") ? GR_SPLIT_TRAIN : GR_SPLIT_TEST;
    char desc[256];
    snprintf(where, sizeof where, "%s.description", at);
    if ((st = get_text(file, where, cJSON_GetObjectItemCaseSensitive(c, "description"), desc, sizeof desc, err)))
        return st;
    if ((st = resolve_scene(file, at, cJSON_GetObjectItemCaseSensitive(c, "scene"), sc->scene_path,
                            sizeof sc->scene_path, err)) != GR_OK)
        return st;
    ov_list l = {0};
    char ov[64];
    if (s->width > 0) {
        snprintf(ov, sizeof ov, "camera.width=%d", s->width);
        st = ov_add(&l, file, ov, "size", err);
        snprintf(ov, sizeof ov, "camera.height=%d", s->height);
        if (st == GR_OK) st = ov_add(&l, file, ov, "size", err);
    }
    if (st == GR_OK) st = case_overrides(file, at, c, &l, err);
    for (int k = 0; k < n_extra && st == GR_OK; k++) st = ov_add(&l, file, extra[k], NULL, err);
    if (st == GR_OK) {
        st = gr_scene_load_file(sc->scene_path, (const char *const *)l.ov, l.n, &sc->scene, err);
        if (st != GR_OK) st = scene_error(file, at, sc, &l, st, err);
    }
    ov_free(&l);
    return st;
}

static gr_status load_tree(const char *file, const cJSON *root, const char *const *extra, int n_extra, gr_suite *s,
                           gr_error *err)
{
    if (!cJSON_IsObject(root))
        return gr_fail(err, GR_E_INPUT, "%s: (root): must be an object, got %s", file, gr_json_type_name(root));
    gr_status st = check_keys(file, "", root, suite_keys, err);
    if (st != GR_OK) return st;
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (version && !(cJSON_IsNumber(version) && version->valuedouble == 1.0))
        return gr_fail(err, GR_E_INPUT, "%s: version: must be 1 (the only suite format version)", file);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (!name) return gr_fail(err, GR_E_INPUT, "%s: name: missing (the suite's name)", file);
    if ((st = check_name(file, "name", name, s->name, err)) ||
        (st = get_text(file, "description", cJSON_GetObjectItemCaseSensitive(root, "description"), s->description,
                       sizeof s->description, err)) ||
        (st = get_size(file, cJSON_GetObjectItemCaseSensitive(root, "size"), s, err)))
        return st;
    const cJSON *cases = cJSON_GetObjectItemCaseSensitive(root, "cases");
    if (!cJSON_IsArray(cases))
        return gr_fail(err, GR_E_INPUT, "%s: cases: %s", file,
                       cases ? "must be an array of cases" : "missing (the suite's array of cases)");
    const int n = cJSON_GetArraySize(cases);
    if (n > SUITE_MAX_CASES) return gr_fail(err, GR_E_INPUT, "%s: cases: more than %d cases", file, SUITE_MAX_CASES);
    if (n > 0 && !(s->cases = calloc((size_t)n, sizeof *s->cases)))
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory for %d cases", file, n);
    int i = 0;
    for (const cJSON *c = cases->child; c; c = c->next, i++) {
        if ((st = load_case(file, i, c, s, extra, n_extra, &s->cases[i], err)) != GR_OK) return st;
        s->n_cases = i + 1;
    }
    /* the point of a suite: tuned on some views, judged on others */
    for (int sp = 0; sp < 2; sp++)
        if (gr_suite_count(s, (gr_split)sp) == 0)
            return gr_fail(err, GR_E_INPUT, "%s: cases: no %s case (a suite needs at least one train and one test case)",
                           file, gr_split_name((gr_split)sp));
    return GR_OK;
}

gr_status gr_suite_load_with(const char *path, const char *const *overrides, int n_overrides, gr_suite **out,
                             gr_error *err)
{
    *out = NULL;
    if (!path) return gr_fail(err, GR_E_RUNTIME, "gr_suite_load: no path");
    if (n_overrides < 0 || (n_overrides > 0 && !overrides))
        return gr_fail(err, GR_E_RUNTIME, "%s: bad override list", path);
    if (strlen(path) >= sizeof((gr_suite *)0)->path) return gr_fail(err, GR_E_INPUT, "%s: path too long", path);
    char *text = NULL;
    gr_status st = gr_json_read_file(path, "suite", SUITE_MAX_BYTES, &text, err);
    if (st != GR_OK) return st;
    cJSON *root = NULL;
    st = gr_json_parse(text, path, &root, err);
    free(text);
    if (st != GR_OK) return st;
    gr_suite *s = calloc(1, sizeof *s);
    if (!s) {
        cJSON_Delete(root);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    snprintf(s->path, sizeof s->path, "%s", path);
    st = load_tree(path, root, overrides, n_overrides, s, err);
    cJSON_Delete(root);
    if (st != GR_OK) {
        gr_suite_destroy(s);
        return st;
    }
    *out = s;
    return GR_OK;
}

gr_status gr_suite_load(const char *path, gr_suite **out, gr_error *err)
{
    return gr_suite_load_with(path, NULL, 0, out, err);
}
