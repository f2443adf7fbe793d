/* The ground-truth cache (see cache.h for the key and the checks). */
#include "reference/cache.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "image/exr.h"
#include "scene/params.h"
#include "scene/settings.h"
#include "truth_digest.h" /* GR_TRUTH_DIGEST, generated at build time (scripts/truth_digest.cmake) */

#ifndef GR_VERSION
#define GR_VERSION "unknown"
#endif

unsigned long long gr_fnv1a64(unsigned long long h, const void *data, size_t n)
{
    /* FNV-1a: xor the byte, then multiply by the 64-bit FNV prime. */
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

static unsigned long long hash_str(unsigned long long h, const char *s)
{
    return gr_fnv1a64(h, s, strlen(s) + 1); /* the terminator separates fields */
}

const char *gr_cache_digest(void) { return GR_TRUTH_DIGEST; }

gr_status gr_cache_key(const gr_scene *s, char *key, gr_error *err)
{
    return gr_cache_key_digest(s, GR_TRUTH_DIGEST, key, err);
}

gr_status gr_cache_key_digest(const gr_scene *s, const char *digest, char *key, gr_error *err)
{
    char *json = gr_scene_to_json(s);
    if (!json) return gr_fail(err, GR_E_NOMEM, "cache key: out of memory printing the scene");
    cJSON *root = cJSON_Parse(json);
    free(json);
    if (!root) return gr_fail(err, GR_E_NOMEM, "cache key: cannot re-read the normalized scene");
    /* What the ground truth does not read: the label and the real-time settings; the
     * reference settings are hashed on their own below. */
    cJSON_DeleteItemFromObjectCaseSensitive(root, "name");
    for (int i = 0; i < gr_sections_count(); i++)
        cJSON_DeleteItemFromObjectCaseSensitive(root, gr_sections_table(i)->section);
    cJSON_DeleteItemFromObjectCaseSensitive(root, "reference");
    char *content = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!content) return gr_fail(err, GR_E_NOMEM, "cache key: out of memory printing the scene");
    const unsigned long long hs = hash_str(GR_FNV_BASIS, content);
    cJSON_free(content);

    /* the code that renders it: any edit of the ground truth's sources is another key */
    unsigned long long hr = hash_str(GR_FNV_BASIS, digest);
    hr = hash_str(hr, GR_VERSION);
    const gr_param_table *t = &gr_reference_param_table;
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        if (!strcmp(p->name, "threads")) continue; /* same bytes for any thread count */
        char num[64];
        hr = hash_str(hr, p->name);
        const int nch = p->type == GR_PT_RGB ? 3 : 1;
        for (int c = 0; c < nch; c++) {
            if (p->type == GR_PT_U64) {
                /* above 2^53 a double would merge neighbouring seeds */
                unsigned long long v = *(const unsigned long long *)((const char *)&s->reference + p->offset);
                snprintf(num, sizeof num, "%llu", v);
            } else {
                gr_format_double(gr_param_get_number(p, &s->reference, c), num, sizeof num);
            }
            hr = hash_str(hr, num);
        }
    }
    snprintf(key, GR_CACHE_KEY_LEN + 1, "%016llx-%016llx", hs, hr);
    return GR_OK;
}

/* mkdir -p; 0 on success. */
static int make_dirs(const char *dir)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char saved = *p;
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
            *p = saved;
            if (saved == '\0') break;
        }
    }
    struct stat sb;
    if (stat(dir, &sb) != 0) return -1;
    if (!S_ISDIR(sb.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    if (access(dir, W_OK | X_OK) != 0) return -1;
    return 0;
}

gr_status gr_cache_dir(char *buf, size_t n, gr_error *err)
{
    const char *env = getenv("GODRAYS_CACHE");
    if (env && env[0]) {
        if (snprintf(buf, n, "%s", env) >= (int)n)
            return gr_fail(err, GR_E_IO, "GODRAYS_CACHE=%s: path too long", env);
        if (make_dirs(buf) != 0)
            return gr_fail(err, GR_E_IO, "GODRAYS_CACHE=%s: cannot create or write: %s", env, strerror(errno));
        return GR_OK;
    }
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    char cand[3][4096];
    int nc = 0;
    /* XDG says a relative XDG_CACHE_HOME is invalid and must be ignored. */
    if (xdg && xdg[0] == '/' && snprintf(cand[nc], sizeof cand[nc], "%s/godrays", xdg) < (int)sizeof cand[nc]) nc++;
    if (home && home[0] && snprintf(cand[nc], sizeof cand[nc], "%s/.cache/godrays", home) < (int)sizeof cand[nc]) nc++;
    snprintf(cand[nc++], sizeof cand[0], ".godrays-cache");
    int last_errno = 0;
    for (int i = 0; i < nc; i++) {
        if (make_dirs(cand[i]) != 0) {
            last_errno = errno;
            continue;
        }
        if (snprintf(buf, n, "%s", cand[i]) >= (int)n) return gr_fail(err, GR_E_IO, "%s: path too long", cand[i]);
        return GR_OK;
    }
    return gr_fail(err, GR_E_IO, "no usable cache directory ($GODRAYS_CACHE unset; $HOME/.cache/godrays and "
                   "./.godrays-cache: %s)", strerror(last_errno));
}

gr_status gr_cache_path(const char *dir, const char *key, char *buf, size_t n, gr_error *err)
{
    if (snprintf(buf, n, "%s/reference-%s.exr", dir, key) >= (int)n)
        return gr_fail(err, GR_E_USAGE, "%s: cache directory name too long", dir);
    return GR_OK;
}

/* FNV-1a 64 of the pixels' bytes as 16 hex digits: stored in the entry and checked on read,
 * since a float flipped inside a chunk that OpenEXR stored raw reads back without any error. */
static void pixel_checksum(const gr_image *img, char out[17])
{
    /* channel by channel in name order (a read may order channels differently from the
     * image that was stored), each channel's name then its samples */
    const size_t np = (size_t)img->width * (size_t)img->height, nc = (size_t)img->nchannels;
    int order[GR_IMAGE_MAX_CHANNELS];
    for (int c = 0; c < img->nchannels; c++) {
        int j = c;
        while (j > 0 && strcmp(img->names[c], img->names[order[j - 1]]) < 0) {
            order[j] = order[j - 1];
            j--;
        }
        order[j] = c;
    }
    unsigned long long h = GR_FNV_BASIS;
    for (int k = 0; k < img->nchannels; k++) {
        const int c = order[k];
        h = hash_str(h, img->names[c]);
        for (size_t p = 0; p < np; p++) h = gr_fnv1a64(h, img->pixels + p * nc + (size_t)c, sizeof(float));
    }
    snprintf(out, 17, "%016llx", h);
}

/* Removes the temporary files that a process killed while storing an entry left behind
 * (reference-KEY.exr.tmp-PID[-N]): those whose process no longer runs. */
static void remove_stale_temps(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *t = strstr(e->d_name, ".exr.tmp-");
        if (strncmp(e->d_name, "reference-", 10) != 0 || !t) continue;
        char *end = NULL;
        long pid = strtol(t + 9, &end, 10);
        if (pid <= 0 || end == t + 9 || (*end != '\0' && *end != '-')) continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue; /* alive (or not ours to judge) */
        char path[4400];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) < (int)sizeof path) unlink(path);
    }
    closedir(d);
}

/* why = "PATH: what" (why may be NULL). */
static void set_why(char *why, size_t n, const char *path, const char *what)
{
    if (why && n) snprintf(why, n, "%s: %s", path, what);
}

gr_status gr_cache_load(const char *dir, const char *key, int width, int height, gr_image **img,
                        gr_metadata *meta, int *hit, char *why, size_t why_n, gr_error *err)
{
    *hit = 0;
    *img = NULL;
    char path[4200];
    gr_status st = gr_cache_path(dir, key, path, sizeof path, err);
    if (st != GR_OK) return st;
    remove_stale_temps(dir);
    struct stat psb;
    if (stat(path, &psb) == 0 && !S_ISREG(psb.st_mode)) {
        set_why(why, why_n, path, "ignored: not a regular file");
        return GR_OK;
    }
    if (access(path, F_OK) != 0) {
        set_why(why, why_n, path, "not cached yet");
        return GR_OK;
    }
    gr_error rerr = {GR_OK, ""};
    gr_image *im = NULL;
    gr_metadata m;
    gr_meta_init(&m);
    st = gr_exr_read(path, &im, &m, &rerr);
    if (st == GR_E_NOMEM) {
        gr_meta_free(&m);
        return gr_fail(err, GR_E_NOMEM, "%s", rerr.msg);
    }
    const char *bad = NULL;
    char detail[1200];
    if (st != GR_OK) {
        snprintf(detail, sizeof detail, "unreadable (%s)", rerr.msg);
        bad = detail;
    } else {
        const gr_meta_item *k = gr_meta_get(&m, GR_CACHE_META_KEY);
        const gr_meta_item *partial = gr_meta_get(&m, "godrays:partial");
        const gr_meta_item *sum = gr_meta_get(&m, GR_CACHE_META_CHECKSUM);
        char want[17];
        pixel_checksum(im, want);
        static const char *const need[6] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
        if (!k || k->type != GR_META_STRING || strcmp(k->str, key)) {
            bad = "its " GR_CACHE_META_KEY " attribute does not match the file name";
        } else if (im->width != width || im->height != height) {
            snprintf(detail, sizeof detail, "size %d x %d, expected %d x %d", im->width, im->height, width, height);
            bad = detail;
        } else if (partial && partial->type != GR_META_STRING && partial->num != 0) {
            bad = "it holds an interrupted (partial) render";
        } else if (!sum || sum->type != GR_META_STRING || strcmp(sum->str, want)) {
            bad = "its pixels do not match their " GR_CACHE_META_CHECKSUM " (a corrupted or older entry); rendering "
                  "it again";
        } else {
            for (int c = 0; c < 6 && !bad; c++)
                if (gr_image_channel(im, need[c]) < 0) {
                    snprintf(detail, sizeof detail, "channel %s is missing", need[c]);
                    bad = detail;
                }
            if (!bad && gr_image_check_finite(im, "cache", &rerr) != GR_OK) {
                snprintf(detail, sizeof detail, "%s", rerr.msg);
                bad = detail;
            }
        }
    }
    if (bad) {
        char what[1300];
        snprintf(what, sizeof what, "ignored: %s", bad);
        set_why(why, why_n, path, what);
        gr_image_destroy(im);
        gr_meta_free(&m);
        return GR_OK;
    }
    *img = im;
    *hit = 1;
    if (meta) {
        gr_meta_free(meta);
        *meta = m; /* hand the items over */
    } else {
        gr_meta_free(&m);
    }
    set_why(why, why_n, path, "cache hit");
    return GR_OK;
}

gr_status gr_cache_store(const char *dir, const char *key, const gr_image *img, const gr_metadata *meta,
                         gr_error *err)
{
    char path[4200];
    gr_status st = gr_cache_path(dir, key, path, sizeof path, err);
    if (st != GR_OK) return st;
    gr_metadata m;
    gr_meta_init(&m);
    char sum[17];
    pixel_checksum(img, sum);
    if ((meta && gr_meta_copy(&m, meta) != GR_OK) || gr_meta_set_string(&m, GR_CACHE_META_KEY, key) != GR_OK ||
        gr_meta_set_string(&m, GR_CACHE_META_CHECKSUM, sum) != GR_OK) {
        gr_meta_free(&m);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    st = gr_exr_write(path, img, &m, err);
    gr_meta_free(&m);
    return st;
}
