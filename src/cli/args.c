/* Shared argument handling of the godrays commands (args.h). */
#include "cli/args.h"
#include "common/memlimit.h"
#include "common/outfile.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/cli.h"
#include "common/paths.h"
#include "tune/preset.h"
#include "tune/session.h"

void gr_args_create(gr_args *a, const char *cmd, int argc, char **argv)
{
    memset(a, 0, sizeof *a);
    a->cmd = cmd;
    a->argc = argc;
    a->argv = argv;
    a->i = 1;
}

void gr_args_free(gr_args *a)
{
    if (!a) return;
    for (int k = 0; k < a->n_sets; k++) {
        free(a->sets[k]);
        free(a->origins[k]);
    }
    free(a->sets);
    free(a->origins);
    for (int k = 0; k < a->n_outs; k++) {
        free(a->out_roles[k]);
        free(a->out_paths[k]);
    }
    a->n_outs = 0;
    a->sets = NULL;
    a->origins = NULL;
    a->n_sets = a->cap_sets = 0;
}

int gr_args_main(const char *cmd, int argc, char **argv, int (*fn)(gr_args *a))
{
    gr_args a;
    gr_args_create(&a, cmd, argc, argv);
    const int rc = fn(&a);
    gr_args_free(&a);
    return rc;
}

const char *const *gr_args_sets(const gr_args *a)
{
    return (const char *const *)a->sets;
}

static int out_of_memory(const gr_args *a)
{
    fprintf(stderr, "godrays %s: out of memory for the command line\n", a->cmd);
    return 1;
}

/* Appends an override the caller allocated (taken over, freed on failure). */
static int push_set(gr_args *a, char *s)
{
    if (!s) return out_of_memory(a);
    if (a->n_sets == a->cap_sets) {
        int cap = a->cap_sets ? 2 * a->cap_sets : 16;
        char **p = realloc(a->sets, (size_t)cap * sizeof *p);
        if (p) a->sets = p;
        char **o = p ? realloc(a->origins, (size_t)cap * sizeof *o) : NULL;
        if (!o) {
            free(s);
            return out_of_memory(a);
        }
        a->origins = o;
        a->cap_sets = cap;
    }
    a->origins[a->n_sets] = NULL;
    a->sets[a->n_sets++] = s;
    return 0;
}

/* The last override came from the flag before argv[i] and its value argv[i]. */
static int set_origin(gr_args *a)
{
    const char *flag = a->argv[a->i - 1], *v = a->argv[a->i];
    size_t n = strlen(flag) + strlen(v) + 2;
    char *o = malloc(n);
    if (!o) return out_of_memory(a);
    snprintf(o, n, "%s %s", flag, v);
    free(a->origins[a->n_sets - 1]);
    a->origins[a->n_sets - 1] = o;
    return 0;
}

int gr_args_add_set(gr_args *a, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (s) {
        va_start(ap, fmt);
        vsnprintf(s, (size_t)n + 1, fmt, ap);
        va_end(ap);
    }
    return push_set(a, s);
}

int gr_args_value(gr_args *a, const char **value)
{
    const char *flag = a->argv[a->i];
    if (a->i + 1 >= a->argc) return gr_cli_usage_error(a->cmd, "%s needs a value", flag);
    *value = a->argv[++a->i];
    return 0;
}

int gr_args_dir(gr_args *a, const char **dir)
{
    const char *flag = a->argv[a->i];
    int rc = gr_args_value(a, dir);
    if (rc) return rc;
    if (!(*dir)[0]) return gr_cli_usage_error(a->cmd, "%s: empty directory name", flag);
    return 0;
}

int gr_args_take_set(gr_args *a)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    if (!strchr(v, '=')) return gr_cli_usage_error(a->cmd, "--set %s: expected KEY=VALUE", v);
    return gr_args_add_set(a, "%s", v);
}

int gr_args_take_size(gr_args *a)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    /* digits only, any length: the scene's range check then names the limit (an int
     * parse wrapped 99999999999 around to 1215752191) */
    const size_t nw = strspn(v, "0123456789");
    const size_t nh = v[nw] == 'x' ? strspn(v + nw + 1, "0123456789") : 0;
    if (!nw || !nh || v[nw + 1 + nh] || strtod(v, NULL) < 1 || strtod(v + nw + 1, NULL) < 1)
        return gr_cli_usage_error(a->cmd, "--size %s: expected WxH, e.g. %s", v,
                                  a->size_example ? a->size_example : "640x360");
    a->have_size = 1;
    if ((rc = gr_args_add_set(a, "camera.width=%.*s", (int)nw, v)) != 0 || (rc = set_origin(a)) != 0) return rc;
    if ((rc = gr_args_add_set(a, "camera.height=%s", v + nw + 1)) != 0) return rc;
    return set_origin(a);
}

int gr_args_take_setting(gr_args *a, const char *key)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    if ((rc = gr_args_add_set(a, "%s=%s", key, v)) != 0) return rc;
    return set_origin(a);
}

int gr_args_take_gl_platform(gr_args *a, gr_gl_platform *platform)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    if (!strcmp(v, "auto")) *platform = GR_GL_AUTO;
    else if (!strcmp(v, "surfaceless")) *platform = GR_GL_SURFACELESS;
    else if (!strcmp(v, "device")) *platform = GR_GL_DEVICE;
    else return gr_cli_usage_error(a->cmd, "--gl-platform %s: expected auto, surfaceless or device", v);
    return 0;
}

/* The preset of --preset (tune/preset.h), once its technique is registered: its settings as
 * overrides at the place of --preset among the others (a later --set wins), each named
 * "--preset FILE" in messages. Exit 2 naming the file and JSON path for a bad preset. */
static int apply_preset(gr_args *a)
{
    if (!a->preset_path || a->preset_technique[0]) return 0;
    gr_preset p;
    gr_error err = {GR_OK, ""};
    if (gr_preset_load(a->preset_path, &p, &err) != GR_OK) return gr_cli_report(a->cmd, &err);
    int rc = 0;
    for (int k = 0; k < p.n_sets && !rc; k++) {
        const size_t n = strlen(a->preset_path) + 12;
        char *origin = malloc(n);
        if ((rc = push_set(a, p.sets[k])) != 0 || !origin) {
            free(origin);
            rc = rc ? rc : out_of_memory(a);
            p.sets[k] = NULL;
            break;
        }
        p.sets[k] = NULL; /* taken over */
        snprintf(origin, n, "--preset %s", a->preset_path);
        a->origins[a->n_sets - 1] = origin;
        /* moved to the place of --preset */
        const int at = a->preset_pos + k;
        char *ss = a->sets[a->n_sets - 1], *oo = a->origins[a->n_sets - 1];
        memmove(&a->sets[at + 1], &a->sets[at], (size_t)(a->n_sets - 1 - at) * sizeof *a->sets);
        memmove(&a->origins[at + 1], &a->origins[at], (size_t)(a->n_sets - 1 - at) * sizeof *a->origins);
        a->sets[at] = ss;
        a->origins[at] = oo;
    }
    for (int k = 0; k < p.n_sets; k++) free(p.sets[k]);
    if (!rc) snprintf(a->preset_technique, sizeof a->preset_technique, "%s", p.technique);
    return rc;
}

int gr_args_take_common(gr_args *a, const char **dir, gr_gl_platform *platform, int *taken)
{
    const char *f = a->argv[a->i];
    *taken = 1;
    if (!strcmp(f, "-o") || !strcmp(f, "--output")) return gr_args_dir(a, dir);
    if (!strcmp(f, "--set")) return gr_args_take_set(a);
    if (!strcmp(f, "--size")) return gr_args_take_size(a);
    if (platform && !strcmp(f, "--gl-platform")) return gr_args_take_gl_platform(a, platform);
    if (!strcmp(f, "--technique-dir")) return gr_args_take_technique_dir(a);
    if (!strcmp(f, "--max-memory")) return gr_args_take_max_memory(a);
    if (!strcmp(f, "--time-limit")) return gr_args_take_time_limit(a);
    if (!strcmp(f, "--preset")) return gr_args_take_preset(a);
    *taken = 0;
    return 0;
}

int gr_args_take_max_memory(gr_args *a)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    gr_error err = {GR_OK, ""};
    double bytes;
    if (gr_memlimit_parse("--max-memory", v, &bytes, &err) != GR_OK) return gr_cli_usage_error(a->cmd, "%s", err.msg);
    gr_memlimit_set(bytes);
    return 0;
}

int gr_args_take_technique_dir(gr_args *a)
{
    const char *d = NULL;
    int rc = gr_args_dir(a, &d);
    if (rc) return rc;
    if (a->n_tech_dirs >= GR_TECH_MAX)
        return gr_cli_usage_error(a->cmd, "--technique-dir %s: more than %d technique folders", d, GR_TECH_MAX);
    a->tech_dirs[a->n_tech_dirs++] = d;
    return 0;
}

int gr_args_take_time_limit(gr_args *a)
{
    const char *v = NULL;
    double s = 0;
    gr_error err = {GR_OK, ""};
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    if (gr_technique_parse_time_limit("--time-limit", v, &s, &err) != GR_OK) return gr_cli_usage_error(a->cmd, "%s", err.msg);
    gr_technique_set_time_limit(s);
    return 0;
}

int gr_args_add_technique_dirs(gr_args *a)
{
    gr_error err = {GR_OK, ""};
    gr_technique_count(); /* the built-in techniques first: theirs are the first sections */
    for (int i = 0; i < a->n_tech_dirs; i++)
        if (gr_technique_add_dir(a->tech_dirs[i], &err) != GR_OK) return gr_cli_report(a->cmd, &err);
    return apply_preset(a);
}

int gr_args_take_preset(gr_args *a)
{
    const char *v = NULL;
    int rc = gr_args_value(a, &v);
    if (rc) return rc;
    if (a->preset_path) return gr_cli_usage_error(a->cmd, "--preset %s: one preset only (%s was given)", v, a->preset_path);
    a->preset_path = v;
    a->preset_pos = a->n_sets;
    return gr_args_add_input(a, "--preset", v);
}

int gr_args_find_technique(const gr_args *a, const char *what, const char *name, const gr_technique_class **cls)
{
    gr_error err = {GR_OK, ""};
    const gr_technique_class *one[1];
    int n = 0;
    if (strchr(name, ',')) return gr_cli_usage_error(a->cmd, "%s %s: one technique expected", what, name);
    if (gr_technique_parse_list(what, name, one, 1, &n, &err) != GR_OK || n != 1) {
        if (err.status == GR_OK) gr_fail(&err, GR_E_USAGE, "%s: no technique given", what);
        return gr_cli_usage_error(a->cmd, "%s", err.msg);
    }
    *cls = one[0];
    return 0;
}

int gr_args_take_scene(gr_args *a)
{
    const char *v = a->argv[a->i];
    if (v[0] == '-' && v[1] != '\0') return gr_cli_usage_error(a->cmd, "unknown option %s", v);
    if (a->scene_path) return gr_cli_usage_error(a->cmd, "more than one scene given (%s, %s)", a->scene_path, v);
    a->scene_path = v;
    return gr_args_add_input(a, "the scene", v);
}

int gr_args_add_input(gr_args *a, const char *role, const char *path)
{
    gr_error err;
    return gr_paths_add_input(role, path, &err) == GR_OK ? 0 : gr_cli_report(a->cmd, &err);
}

int gr_args_note_output(gr_args *a, const char *role, const char *path)
{
    gr_error err;
    if (gr_paths_check_output(role, path, &err) != GR_OK) return gr_cli_report(a->cmd, &err);
    for (int k = 0; k < a->n_outs; k++)
        if (gr_path_same_file(path, a->out_paths[k]))
            return gr_cli_usage_error(a->cmd, "%s %s: the same file as %s %s: two outputs cannot share a file", role, path,
                                      a->out_roles[k], a->out_paths[k]);
    if (a->n_outs == GR_ARGS_MAX_OUTPUTS) return 0; /* more than any command writes beside each other */
    a->out_roles[a->n_outs] = strdup(role);
    a->out_paths[a->n_outs] = strdup(path);
    if (!a->out_roles[a->n_outs] || !a->out_paths[a->n_outs]) {
        free(a->out_roles[a->n_outs]);
        free(a->out_paths[a->n_outs]);
        return out_of_memory(a);
    }
    a->n_outs++;
    return 0;
}

int gr_args_note_preview(gr_args *a, const char *flag, const char *exr)
{
    char png[4096], role[4200];
    gr_args_preview_path(exr, png, sizeof png);
    snprintf(role, sizeof role, "%s %s's preview", flag, exr);
    return gr_args_note_output(a, role, png);
}

int gr_args_need_scene(const gr_args *a)
{
    return a->scene_path ? 0 : gr_cli_usage_error(a->cmd, "no scene file given");
}

/* "--set KEY=V: ..." for an override that a flag made: name the flag as typed */
static void name_flag(const gr_args *a, gr_error *err)
{
    for (int k = 0; k < a->n_sets; k++) {
        char typed[GR_ERROR_MSG_MAX];
        const int n = snprintf(typed, sizeof typed, "--set %s", a->sets[k]);
        const char *at = n < 0 || n >= (int)sizeof typed ? NULL : strstr(err->msg, typed);
        /* at the start (a scene's error) or after "SUITE: cases[i] (NAME): " (a suite's) */
        if (!a->origins[k] || !at || (at != err->msg && strncmp(at - 2, ": ", 2))) continue;
        char rest[GR_ERROR_MSG_MAX];
        snprintf(rest, sizeof rest, "%s", at + n);
        const int head = (int)(at - err->msg);
        gr_strbuf b;
        gr_sb_init(&b);
        gr_sb_printf(&b, "%.*s%s%s", head, err->msg, a->origins[k], rest);
        if (gr_sb_str(&b)) snprintf(err->msg, sizeof err->msg, "%.*s", (int)sizeof err->msg - 1, gr_sb_str(&b));
        gr_sb_free(&b);
        break;
    }
}

int gr_args_load_scene(const gr_args *a, gr_scene **scene)
{
    gr_error err = {GR_OK, ""};
    *scene = malloc(sizeof **scene);
    if (!*scene) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        return gr_cli_report(a->cmd, &err);
    }
    if (gr_scene_load_file(a->scene_path, gr_args_sets(a), a->n_sets, *scene, &err) != GR_OK) {
        free(*scene);
        *scene = NULL;
        name_flag(a, &err);
        return gr_cli_report(a->cmd, &err);
    }
    return 0;
}

int gr_args_load_suite(gr_args *a, const char *path, gr_suite **suite)
{
    gr_error err = {GR_OK, ""};
    int rc = gr_args_add_input(a, "the suite", path);
    if (rc) return rc;
    if (gr_suite_load_with(path, gr_args_sets(a), a->n_sets, suite, &err) != GR_OK) {
        name_flag(a, &err);
        return gr_cli_report(a->cmd, &err);
    }
    return 0;
}

void gr_args_scene_words(const gr_args *a, gr_strbuf *b)
{
    if (a->scene_path) gr_sb_shell_word(b, a->scene_path);
    for (int k = 1; k + 1 < a->argc; k++) {
        if (strcmp(a->argv[k], "--set") && strcmp(a->argv[k], "--size")) continue;
        gr_sb_printf(b, " %s ", a->argv[k]);
        gr_sb_shell_word(b, a->argv[++k]);
    }
}

/* ---- output checks -------------------------------------------------------------------------- */

static int output_error(const gr_args *a, const char *flag, const char *path, const char *what, const char *where,
                        int e)
{
    gr_error err;
    gr_fail(&err, GR_E_USAGE, "%s %s: %s%s: %s", flag, path, what, where, strerror(e));
    return gr_cli_report(a->cmd, &err);
}

/* The folder part of path ("." for a bare name, "/" for a name at the root). */
static void parent_of(const char *path, char *buf, size_t n)
{
    snprintf(buf, n, "%s", path);
    char *slash = strrchr(buf, '/');
    if (!slash) snprintf(buf, n, ".");
    else if (slash == buf) buf[1] = '\0';
    else *slash = '\0';
}

/* 0 if dir is a folder this process may create files in, else errno's reason. */
static int writable_dir(const char *dir)
{
    struct stat sb;
    if (stat(dir, &sb) != 0) return errno;
    if (!S_ISDIR(sb.st_mode)) return ENOTDIR;
    if (access(dir, W_OK | X_OK) != 0) return errno;
    return 0;
}

int gr_args_check_output_file(gr_args *a, const char *flag, const char *path)
{
    char dir[4096];
    struct stat sb;
    if (!path[0]) return output_error(a, flag, "''", "cannot write", "", ENOENT);
    const int rc = gr_args_note_output(a, flag, path);
    if (rc) return rc;
    if (strlen(path) >= sizeof dir) return output_error(a, flag, path, "cannot write", "", ENAMETOOLONG);
    if (path[strlen(path) - 1] == '/' || (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)))
        return output_error(a, flag, path, "cannot write", "", EISDIR);
    gr_outfile probe; /* an existing device node, FIFO or socket is refused (common/outfile) */
    gr_error perr;
    if (gr_outfile_begin(&probe, path, &perr) != GR_OK) {
        gr_error_prefix(&perr, "%s", flag);
        return gr_cli_report(a->cmd, &perr);
    }
    gr_outfile_abort(&probe); /* nothing was created */
    parent_of(path, dir, sizeof dir);
    const int e = writable_dir(dir);
    return e ? output_error(a, flag, path, "cannot write into ", dir, e) : 0;
}

int gr_args_check_output_dir(const gr_args *a, const char *flag, const char *path)
{
    char buf[4096], self[4096];
    if (!path[0]) return output_error(a, flag, "''", "cannot create", "", ENOENT);
    gr_error perr;
    if (gr_paths_check_output(flag, path, &perr) != GR_OK) return gr_cli_report(a->cmd, &perr);
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return output_error(a, flag, path, "cannot create", "", ENAMETOOLONG);
    /* Walk up to the nearest part that exists: the folder itself, or the ancestor in which
     * the missing folders would be created. */
    self[0] = '\0';
    for (;;) {
        size_t len = strlen(buf);
        while (len > 1 && buf[len - 1] == '/') buf[--len] = '\0';
        if (!self[0]) memcpy(self, buf, len + 1);
        struct stat sb;
        if (stat(buf, &sb) == 0) break;
        if (errno != ENOENT && errno != ENOTDIR) return output_error(a, flag, path, "cannot use ", buf, errno);
        char up[4096];
        parent_of(buf, up, sizeof up);
        if (!strcmp(up, buf)) break;
        snprintf(buf, sizeof buf, "%s", up);
    }
    const int e = writable_dir(buf);
    if (!e) return 0;
    return output_error(a, flag, path, strcmp(buf, self) ? "cannot create a folder in " : "cannot write into ", buf, e);
}

int gr_args_output_dir(const gr_args *a, const gr_scene *scene, const char *given, const char *sub, char *buf,
                       size_t n, const char **dir)
{
    if (given) {
        *dir = given;
        return gr_args_check_output_dir(a, "-o", given);
    }
    gr_scene *loaded = NULL;
    int rc = scene ? 0 : gr_args_load_scene(a, &loaded);
    if (rc) return rc;
    gr_tune_default_dir(scene ? scene->name : loaded->name, sub, buf, n);
    free(loaded);
    *dir = buf;
    return gr_args_check_output_dir(a, "default output folder", buf);
}

void gr_args_preview_path(const char *exr, char *buf, size_t n)
{
    size_t len = strlen(exr);
    if (len > 4 && !strcasecmp(exr + len - 4, ".exr"))
        snprintf(buf, n, "%.*s.png", (int)(len - 4), exr);
    else
        snprintf(buf, n, "%s.png", exr);
}
