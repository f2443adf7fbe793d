/* Inputs and outputs of a command (paths.h). */
#define _DEFAULT_SOURCE /* realpath (XSI) */
#include "common/paths.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct input {
    const char *role, *path;
    dev_t dev;
    ino_t ino;
} input;

static input *g_inputs = NULL;
static int g_n = 0, g_cap = 0;

char *gr_path_final_target(const char *path)
{
    char *cur = strdup(path);
    for (int hop = 0; cur && hop < 40; hop++) {
        struct stat sb;
        if (lstat(cur, &sb) != 0 || !S_ISLNK(sb.st_mode)) return cur;
        char link[4096];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) return cur;
        link[n] = '\0';
        char *next;
        const char *slash = strrchr(cur, '/');
        if (link[0] == '/' || !slash) {
            next = strdup(link);
        } else {
            size_t dl = (size_t)(slash - cur) + 1;
            next = malloc(dl + (size_t)n + 1);
            if (next) {
                memcpy(next, cur, dl);
                memcpy(next + dl, link, (size_t)n + 1);
            }
        }
        free(cur);
        cur = next;
    }
    return cur;
}

/* The place path names before it exists: its final target with the folder made absolute and
 * free of links, "." and "..". NULL: no memory; the final target as is when the folder does
 * not resolve (then the write fails anyway). */
static char *place_of(const char *path)
{
    char *t = gr_path_final_target(path);
    if (!t) return NULL;
    char *slash = strrchr(t, '/');
    const char *base = slash ? slash + 1 : t;
    char dir[PATH_MAX];
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == t) snprintf(dir, sizeof dir, "/");
    else snprintf(dir, sizeof dir, "%.*s", (int)(slash - t), t);
    char real[PATH_MAX];
    if (!realpath(dir, real)) return t;
    size_t n = strlen(real) + strlen(base) + 2;
    char *out = malloc(n);
    if (out) snprintf(out, n, "%s%s%s", real, strcmp(real, "/") ? "/" : "", base);
    free(t);
    return out;
}

int gr_path_same_file(const char *a, const char *b)
{
    if (!a || !b) return 0;
    struct stat sa, sb;
    const int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0;
    if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ea != eb) return 0;
    char *pa = place_of(a), *pb = place_of(b);
    const int same = pa && pb && !strcmp(pa, pb);
    free(pa);
    free(pb);
    return same;
}

gr_status gr_paths_add_input(const char *role, const char *path, gr_error *err)
{
    struct stat sb;
    if (!path || stat(path, &sb) != 0) return GR_OK;
    if (g_n == g_cap) {
        int cap = g_cap ? 2 * g_cap : 16;
        input *p = realloc(g_inputs, (size_t)cap * sizeof *p);
        if (!p) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
        g_inputs = p;
        g_cap = cap;
    }
    g_inputs[g_n++] = (input){role, path, sb.st_dev, sb.st_ino};
    return GR_OK;
}

gr_status gr_paths_check_output(const char *role, const char *path, gr_error *err)
{
    struct stat sb;
    if (!path || stat(path, &sb) != 0) return GR_OK; /* a file that is not there replaces no input */
    for (int k = 0; k < g_n; k++)
        if (g_inputs[k].dev == sb.st_dev && g_inputs[k].ino == sb.st_ino)
            return gr_fail(err, GR_E_USAGE, "%s%s%s: the same file as %s %s, an input: refusing to replace it",
                           role ? role : "", role ? " " : "", path, g_inputs[k].role, g_inputs[k].path);
    return GR_OK;
}

void gr_paths_clear(void)
{
    free(g_inputs);
    g_inputs = NULL;
    g_n = g_cap = 0;
}
