#include "farm/parts.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "common/memlimit.h"
#include "common/outfile.h"
#include "reference/cache.h"
#include "reference/truth.h"

#define PART_MAGIC "GODRAYS-PART 1\n"

void gr_part_rows(int i, int n, int h, int *row0, int *row1)
{
    *row0 = (int)((long long)i * h / n);
    *row1 = (int)((long long)(i + 1) * h / n);
}

/* ---- a byte buffer ---- */
typedef struct buf { unsigned char *p; size_t n; int bad; } buf;

static int little_endian(void)
{
    const uint16_t one = 1;
    return *(const unsigned char *)&one == 1;
}

/* ---- the sums' fields through their table (reference/sums.h), both directions ---- */

/* The payload of rectangle rc of s: every array field of gr_ref_sums_fields in the table's
 * order, per pixel and batch the rows [row0, row1) x the batches [batch0, batch1), then
 * (rc->probe) per probe level each probe array's rows [probe_row0, probe_row1). Copies
 * between s and bytes (to_sums: into s; bytes NULL: only counts); returns the byte count. */
static size_t payload_walk(gr_ref_sums *s, const gr_ref_sums_rect *rc, unsigned char *bytes, int to_sums)
{
    size_t n = 0, nb = (size_t)(rc->batch1 - rc->batch0);
    for (int pass = 0; pass < 2; pass++) /* 0: the image arrays, 1: the probe's */
        for (int k = 0; k < (pass ? (rc->probe ? s->probe_levels : 0) : 1); k++)
            for (size_t i = 0; i < gr_ref_sums_nfields; i++) {
                const gr_ref_sums_field *f = &gr_ref_sums_fields[i];
                if (f->shape != (pass ? GR_SUMS_PROBE_PIXEL : GR_SUMS_PIXEL_BATCH)) continue;
                size_t e = gr_ref_sums_elem_bytes(f);
                unsigned char *a = bytes ? gr_ref_sums_array(s, f, k) : NULL;
                /* runs of elements: nb per image pixel, or whole probe rows */
                size_t run = pass ? (size_t)(rc->probe_row1 - rc->probe_row0) * s->probe_w * e : nb * e;
                size_t first = pass ? (size_t)rc->probe_row0 * s->probe_w : (size_t)rc->row0 * s->W;
                size_t runs = pass ? 1 : (size_t)(rc->row1 - rc->row0) * s->W;
                for (size_t q = 0; q < runs; q++, n += run) {
                    if (!bytes) continue;
                    size_t at = pass ? first * e : ((first + q) * s->B + rc->batch0) * e;
                    if (to_sums) memcpy(a + at, bytes + n, run);
                    else memcpy(bytes + n, a + at, run);
                }
            }
    return n;
}

/* The header keys of every scalar of s (gr_ref_sums_fields' names). */
static void header_put_sums(cJSON *h, const gr_ref_sums *s)
{
    for (size_t i = 0; i < gr_ref_sums_nfields; i++)
        if (gr_ref_sums_fields[i].shape == GR_SUMS_SCALAR)
            cJSON_AddNumberToObject(h, gr_ref_sums_fields[i].name, gr_ref_sums_get(s, &gr_ref_sums_fields[i]));
}

/* Every scalar of s from the header's keys. A size or the probe's layout must be there (*ok
 * = 0 if not); a tally missing (a part written before it existed) reads 0. */
static void header_get_sums(const cJSON *h, gr_ref_sums *s, int *ok)
{
    for (size_t i = 0; i < gr_ref_sums_nfields; i++) {
        const gr_ref_sums_field *f = &gr_ref_sums_fields[i];
        if (f->shape != GR_SUMS_SCALAR) continue;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(h, f->name);
        if (cJSON_IsNumber(v)) gr_ref_sums_set(s, f, v->valuedouble);
        else if (!gr_ref_sums_is_tally(f)) *ok = 0;
    }
}

gr_status gr_part_write(const char *path, const gr_scene *scene, const gr_ref_options *o, const gr_ref_result *res,
                        const char *command, gr_error *err)
{
    const gr_ref_sums *s = res->sums;
    if (!s) return gr_fail(err, GR_E_USAGE, "%s: the render kept no sums (gr_ref_options.keep_sums)", path);
    if (!little_endian()) return gr_fail(err, GR_E_RUNTIME, "%s: part files are little-endian; this machine is not", path);
    gr_ref_sums_rect rc = {o->row0, o->row1 ? o->row1 : s->H, o->batch0, o->batch1 ? o->batch1 : s->B, s->probe, 0, 0};
    if (s->probe) {
        rc.probe_row0 = gr_ref_probe_row(rc.row0, s->probe_stride, s->probe_off, s->probe_h);
        rc.probe_row1 = gr_ref_probe_row(rc.row1, s->probe_stride, s->probe_off, s->probe_h);
    }
    buf pay = {0};
    size_t pn = payload_walk((gr_ref_sums *)s, &rc, NULL, 0);
    pay.p = malloc(pn + 1);
    if (pay.p) pay.n = payload_walk((gr_ref_sums *)s, &rc, pay.p, 0);
    else pay.bad = 1;
    char key[GR_CACHE_KEY_LEN + 1];
    gr_status st = pay.bad ? gr_fail(err, GR_E_NOMEM, "%s: out of memory", path) : gr_cache_key(scene, key, err);
    char *scene_json = st == GR_OK ? gr_scene_to_json(scene) : NULL;
    if (st == GR_OK && !scene_json) st = gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    cJSON *h = st == GR_OK ? cJSON_CreateObject() : NULL;
    char *htxt = NULL;
    if (h) {
        char host[128] = "", date[64] = "", fnv[20];
        gethostname(host, sizeof host - 1);
        time_t now = time(NULL);
        struct tm tm;
        gmtime_r(&now, &tm);
        strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
        snprintf(fnv, sizeof fnv, "%016llx", gr_fnv1a64(GR_FNV_BASIS, pay.p, pay.n));
        cJSON_AddStringToObject(h, "format", GR_PART_FORMAT);
        cJSON_AddStringToObject(h, "cache_key", key);
        cJSON_AddStringToObject(h, "scene_path", scene->source_path);
        cJSON_AddStringToObject(h, "scene", scene_json);
        header_put_sums(h, s);
        cJSON_AddNumberToObject(h, "row0", rc.row0);
        cJSON_AddNumberToObject(h, "row1", rc.row1);
        cJSON_AddNumberToObject(h, "batch0", rc.batch0);
        cJSON_AddNumberToObject(h, "batch1", rc.batch1);
        cJSON_AddNumberToObject(h, "probe_row0", rc.probe_row0);
        cJSON_AddNumberToObject(h, "probe_row1", rc.probe_row1);
        cJSON *pv = cJSON_AddObjectToObject(h, "provenance");
        if (pv) {
            cJSON_AddStringToObject(pv, "host", host);
            cJSON_AddNumberToObject(pv, "pid", (double)getpid());
            cJSON_AddStringToObject(pv, "date", date);
            cJSON_AddNumberToObject(pv, "wall_s", res->wall_s);
            const gr_meta_item *th = gr_meta_get(&res->meta, "godrays:threads");
            cJSON_AddNumberToObject(pv, "threads", th ? th->num : scene->reference.threads);
            cJSON_AddStringToObject(pv, "version", GR_VERSION);
            cJSON_AddStringToObject(pv, "command", command ? command : "");
        }
        cJSON_AddNumberToObject(h, "payload_bytes", (double)pay.n);
        cJSON_AddStringToObject(h, "payload_fnv1a64", fnv);
        htxt = cJSON_PrintUnformatted(h);
        cJSON_Delete(h);
        if (!htxt) st = gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    } else if (st == GR_OK) {
        st = gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    free(scene_json);
    if (st == GR_OK) {
        size_t tl = strlen(path) + 32;
        char *tmp = malloc(tl);
        FILE *f = NULL;
        if (tmp) {
            snprintf(tmp, tl, "%s.tmp-%ld", path, (long)getpid());
            f = fopen(tmp, "wb");
        }
        if (!f) {
            st = gr_fail(err, GR_E_IO, "%s: cannot write: %s", path, tmp ? strerror(errno) : "out of memory");
        } else {
            int ok = fprintf(f, "%s%zu\n", PART_MAGIC, strlen(htxt)) > 0;
            ok = ok && fwrite(htxt, 1, strlen(htxt), f) == strlen(htxt);
            ok = ok && (pay.n == 0 || fwrite(pay.p, 1, pay.n, f) == pay.n);
            ok = ok && fflush(f) == 0 && fsync(fileno(f)) == 0;
            ok = (fclose(f) == 0) && ok;
            if (!ok) st = gr_fail(err, GR_E_IO, "%s: write failed: %s", tmp, strerror(errno));
            else if (rename(tmp, path) != 0) st = gr_fail(err, GR_E_IO, "%s: cannot rename into place: %s", path, strerror(errno));
            if (st != GR_OK) remove(tmp);
        }
        free(tmp);
    }
    cJSON_free(htxt);
    free(pay.p);
    return st;
}

/* ---- reading ---- */

typedef struct part {
    const char *path;
    cJSON *h;
    unsigned char *data; /* the whole file */
    const unsigned char *pay;
    size_t pay_n;
    gr_ref_sums s;          /* the header's scalars (no arrays) */
    gr_ref_sums_rect rc;    /* its rectangle */
} part;

static double num(const cJSON *h, const char *k, int *ok)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(h, k);
    if (!cJSON_IsNumber(v)) { *ok = 0; return 0.0; }
    return v->valuedouble;
}

static const char *str(const cJSON *h, const char *k)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(h, k);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

static void part_free(part *p)
{
    cJSON_Delete(p->h);
    free(p->data);
    memset(p, 0, sizeof *p);
}

/* ---- checks of a part's header, size and sums (docs/reliability.md, "Issue 31") ---- */

/* The largest image side and batch count a scene allows (scene/scene.c camera.width/height,
 * scene/settings.c reference.batches): a header over them describes no render. */
#define PART_MAX_SIDE 16384
#define PART_MAX_BATCHES 1024
/* A batch sum over its sample count: no radiance comes near 1e30, and the squares of batch
 * means (the error bars) then stay finite; NaN, Inf or 1e308 merged into zero pixels. */
#define PART_MAX_MEAN 1e30

/* Every number of the header: present where required, finite, integral where an integer, and
 * within the range its use needs, so that the (int) and (long long) conversions below are
 * defined (a double out of an integer type's range converts with undefined behaviour) and a
 * forged size is refused before anything is allocated for it. */
static gr_status part_check_fields(const cJSON *h, const char *path, gr_error *err)
{
    static const struct { const char *key; double lo, hi; int integer; } f[] = {
        {"width", 1, PART_MAX_SIDE, 1}, {"height", 1, PART_MAX_SIDE, 1}, {"batches", 2, PART_MAX_BATCHES, 1},
        {"row0", 0, PART_MAX_SIDE, 1}, {"row1", 1, PART_MAX_SIDE, 1}, {"batch0", 0, PART_MAX_BATCHES, 1},
        {"batch1", 1, PART_MAX_BATCHES, 1}, {"passes", 1, INT_MAX, 1}, {"probe", 0, 1, 1},
        {"probe_levels", 0, GR_REF_PROBE_MAX_LEVELS, 1}, {"probe_w", 0, PART_MAX_SIDE, 1},
        {"probe_h", 0, PART_MAX_SIDE, 1}, {"probe_stride", 0, PART_MAX_SIDE, 1}, {"probe_off", 0, PART_MAX_SIDE, 1},
        {"probe_passes", 0, INT_MAX, 1}, {"probe_row0", 0, PART_MAX_SIDE, 1}, {"probe_row1", 0, PART_MAX_SIDE, 1},
        {"probe_s", 0, 1e300, 0}, {"beam_cell_m", 0, 1e300, 0}, {"beam_prims", 0, 9007199254740992.0, 1},
        {"beam_refine_factor", 0, INT_MAX, 1}, {"beam_refine_radius_m", -1, 1e300, 0}, /* -1: no cone (beams.h) */
        {"beam_refined_cells", 0, 9007199254740992.0, 1}, {"beam_transition_cells", 0, 9007199254740992.0, 1},
        {"beam_triangles", 0, 9007199254740992.0, 1}, {"beam_near_factor", 0, INT_MAX, 1},
        {"beam_near_radius_m", 0, 1e300, 0}, {"beam_near_cells", 0, 9007199254740992.0, 1},
        {"beam_near_transition_cells", 0, 9007199254740992.0, 1}, {"beam_near_triangles", 0, 9007199254740992.0, 1},
        {"beam_build_s", 0, 1e300, 0}, {"march_s", 0, 1e300, 0},
        {"queries", 0, 9007199254740992.0, 1}, {"shadows", 0, 9007199254740992.0, 1},
        {"overflows", 0, 9007199254740992.0, 1}, {"steps_sum", 0, 1e300, 0}, {"steps_pixels", 0, 1e300, 0},
        {"steps_capped", 0, 1e300, 0}, {"steps_wanted_sum", 0, 1e300, 0},
        {"steps_min", 0, INT_MAX, 1}, {"steps_max", 0, INT_MAX, 1}, {"pilot_steps", 0, INT_MAX, 1},
        {"pilot_s", 0, 1e300, 0}, {"payload_bytes", 0, 9007199254740992.0, 1}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(h, f[i].key);
        if (!cJSON_IsNumber(v)) return gr_fail(err, GR_E_INPUT, "%s: header field %s missing or not a number", path, f[i].key);
        const double d = v->valuedouble;
        if (!isfinite(d) || d < f[i].lo || d > f[i].hi || (f[i].integer && d != floor(d)))
            return gr_fail(err, GR_E_INPUT, "%s: header field %s is %.17g, expected %s in [%.17g, %.17g]", path, f[i].key,
                           d, f[i].integer ? "an integer" : "a number", f[i].lo, f[i].hi);
    }
    const cJSON *pv = cJSON_GetObjectItemCaseSensitive(h, "provenance");
    const cJSON *w = pv ? cJSON_GetObjectItemCaseSensitive(pv, "wall_s") : NULL;
    if (w && (!cJSON_IsNumber(w) || !isfinite(w->valuedouble) || w->valuedouble < 0.0))
        return gr_fail(err, GR_E_INPUT, "%s: header field provenance.wall_s is not a finite number >= 0", path);
    return GR_OK;
}

/* What the merge of the render that a part describes needs, from its header alone, against
 * the memory limit (common/memlimit), before its payload is read: the merged sums (3 doubles
 * and a count per pixel and batch), the coverage map (an int per row and batch), the probe's
 * accumulators, the assembled image and its statistics (at most 11 float channels and 4
 * doubles per pixel) and this part's payload. */
static gr_status part_check_memory(const char *path, int W, int H, int B, int plevels, int pw, int ph, size_t payload,
                                   gr_error *err)
{
    const double px = (double)W * H;
    const double need = px * (28.0 * B + 11.0 * 4 + 4.0 * 8) + 4.0 * H * B + 28.0 * plevels * pw * (double)ph + (double)payload;
    char what[300], detail[160];
    snprintf(what, sizeof what, "merging %s", path);
    snprintf(detail, sizeof detail, "a %dx%d render with %d batches, as its header says", W, H, B);
    return gr_memlimit_check(what, need, detail, err);
}

/* The file's bytes after the header against the payload its header describes, before any of
 * them is read: a part padded to 12 GB was read whole before its length was compared. */
static gr_status part_check_size(const char *path, size_t have, size_t expect, double declared, gr_error *err)
{
    if ((double)expect == declared && have == expect) return GR_OK;
    return gr_fail(err, GR_E_INPUT, "%s: payload is %zu bytes, the header says %.0f (expected %zu): truncated or damaged, or padded",
                   path, have, declared, expect);
}

/* The merged sums before they are assembled: a render gives every pixel of every batch
 * exactly passes-per-batch x samples-per-pass samples, and sums that are finite, >= 0 (the
 * in-scattered radiance is) and at most PART_MAX_MEAN per sample. Forged parts with a valid
 * checksum and NaN, 1e308, negative sums or zero counts merged into zero pixels or "0 spp"
 * (and, with --cache, into the cache). owner: the part of each (row, batch). */
static gr_status parts_check_sums(const gr_ref_sums *s, const int *owner, const part *ps, int n,
                                  const gr_ref_info *info, gr_error *err)
{
    const int B = s->B, per_batch = info->passes_per_round / B;
    const uint32_t want = (uint32_t)per_batch * (uint32_t)info->spp_per_pass;
    for (int i = 0; i < n; i++)
        if (ps[i].s.passes != (ps[i].rc.batch1 - ps[i].rc.batch0) * per_batch)
            return gr_fail(err, GR_E_INPUT, "%s: %d passes for %d batches; its scene gives every batch %d passes", ps[i].path,
                           ps[i].s.passes, ps[i].rc.batch1 - ps[i].rc.batch0, per_batch);
    for (int y = 0; y < s->H; y++)
        for (int x = 0; x < s->W; x++)
            for (int b = 0; b < B; b++) {
                const size_t k = ((size_t)y * s->W + x) * B + b;
                const uint32_t c = s->count[k];
                const double *v = s->sum + k * 3;
                const char *path = ps[owner[(size_t)y * B + b]].path;
                if (c != want)
                    return gr_fail(err, GR_E_INPUT, "%s: pixel (%d, %d) of batch %d has %u samples; its scene gives %u "
                                   "(%d passes x %d samples): damaged or forged", path, x, y, b, c, want, per_batch,
                                   info->spp_per_pass);
                for (int ch = 0; ch < 3; ch++)
                    if (!(v[ch] >= 0.0 && v[ch] <= PART_MAX_MEAN * c)) /* also NaN */
                        return gr_fail(err, GR_E_INPUT, "%s: pixel (%d, %d) of batch %d: sum %.17g is not a finite radiance "
                                       "sum in [0, %g x %u samples]: damaged or forged", path, x, y, b, v[ch], PART_MAX_MEAN, c);
            }
    for (int k = 0; s->probe && k < s->probe_levels; k++)
        for (size_t q = 0; q < (size_t)s->probe_w * s->probe_h * 3; q++) {
            const double v = s->probe_sum[k][q];
            const double c = s->probe_count[k][q / 3];
            if (!(v >= 0.0 && v <= PART_MAX_MEAN * (c > 1.0 ? c : 1.0)))
                return gr_fail(err, GR_E_INPUT, "merge: surface-bias probe level %d, probe pixel %zu: sum %.17g is not a "
                               "finite radiance sum: a part is damaged or forged", k, q / 3, v);
        }
    return GR_OK;
}

/* parts_check_sums through gr_truth_assemble's check (reference/truth.h): the renderer that
 * assembles the sums says what a render of the scene gives. */
typedef struct parts_checked {
    const gr_ref_sums *sums;
    const int *owner;
    const part *ps;
    int n;
} parts_checked;

static gr_status parts_check_hook(void *user, const gr_ref_info *info, gr_error *err)
{
    const parts_checked *c = user;
    return parts_check_sums(c->sums, c->owner, c->ps, c->n, info, err);
}

/* Reads and checks one part file (header fields, payload length and checksum). */
static gr_status part_read(const char *path, part *p, gr_error *err)
{
    memset(p, 0, sizeof *p);
    p->path = path;
    gr_status reg = gr_check_regular_input(path, err); /* a FIFO would block the open (issue 31) */
    if (reg != GR_OK) return reg;
    FILE *f = fopen(path, "rb");
    if (!f) return gr_fail(err, GR_E_INPUT, "%s: cannot open: %s", path, strerror(errno));
    char line[64];
    size_t hn = 0;
    if (!fgets(line, sizeof line, f) || strcmp(line, PART_MAGIC) != 0) {
        fclose(f);
        return gr_fail(err, GR_E_INPUT, "%s: not a godrays part file (no \"GODRAYS-PART 1\" line)", path);
    }
    if (!fgets(line, sizeof line, f) || sscanf(line, "%zu", &hn) != 1 || hn == 0 || hn > ((size_t)1 << 30)) {
        fclose(f);
        return gr_fail(err, GR_E_INPUT, "%s: bad header length", path);
    }
    long start = ftell(f);
    fseek(f, 0, SEEK_END);
    long end = ftell(f);
    fseek(f, start, SEEK_SET);
    size_t total = end > start ? (size_t)(end - start) : 0;
    if (total < hn) {
        fclose(f);
        return gr_fail(err, GR_E_INPUT, "%s: truncated header", path);
    }
    /* the header first; the payload only once its size matches the file and the memory limit */
    p->data = malloc(hn + 1);
    if (!p->data) {
        fclose(f);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    if (fread(p->data, 1, hn, f) != hn) {
        fclose(f);
        part_free(p);
        return gr_fail(err, GR_E_INPUT, "%s: short read", path);
    }
    p->data[hn] = '\0';
    p->h = cJSON_Parse((const char *)p->data);
    if (!p->h) {
        fclose(f);
        part_free(p);
        return gr_fail(err, GR_E_INPUT, "%s: header is not JSON", path);
    }
    const char *fmt = str(p->h, "format");
    gr_status fst = !fmt || strcmp(fmt, GR_PART_FORMAT) != 0
                        ? gr_fail(err, GR_E_INPUT, "%s: format is not %s", path, GR_PART_FORMAT)
                        : part_check_fields(p->h, path, err);
    if (fst != GR_OK) {
        fclose(f);
        part_free(p);
        return fst;
    }
    int ok = 1;
    const gr_ref_sums *hs = &p->s;
    gr_ref_sums_rect *rc = &p->rc;
    header_get_sums(p->h, &p->s, &ok);
    rc->row0 = (int)num(p->h, "row0", &ok);
    rc->row1 = (int)num(p->h, "row1", &ok);
    rc->batch0 = (int)num(p->h, "batch0", &ok);
    rc->batch1 = (int)num(p->h, "batch1", &ok);
    rc->probe = hs->probe;
    rc->probe_row0 = (int)num(p->h, "probe_row0", &ok);
    rc->probe_row1 = (int)num(p->h, "probe_row1", &ok);
    double pn = num(p->h, "payload_bytes", &ok);
    const char *fnv = str(p->h, "payload_fnv1a64");
    if (!ok || !fnv || !str(p->h, "cache_key") || !str(p->h, "scene") || hs->W < 1 || hs->H < 1 || hs->B < 2 ||
        rc->row0 < 0 || rc->row1 > hs->H || rc->row0 >= rc->row1 || rc->batch0 < 0 || rc->batch1 > hs->B ||
        rc->batch0 >= rc->batch1 ||
        (hs->probe && (hs->probe_levels < 1 || hs->probe_levels > GR_REF_PROBE_MAX_LEVELS || hs->probe_w < 1 ||
                       hs->probe_h < 1 || rc->probe_row0 < 0 || rc->probe_row1 > hs->probe_h ||
                       rc->probe_row0 > rc->probe_row1))) {
        fclose(f);
        part_free(p);
        return gr_fail(err, GR_E_INPUT, "%s: header fields missing or out of range", path);
    }
    size_t expect = payload_walk(&p->s, rc, NULL, 0);
    gr_status sst = part_check_size(path, total - hn, expect, pn, err);
    if (sst == GR_OK)
        sst = part_check_memory(path, hs->W, hs->H, hs->B, hs->probe ? hs->probe_levels : 0, hs->probe_w, hs->probe_h,
                                expect, err);
    unsigned char *whole = sst == GR_OK ? realloc(p->data, hn + expect + 1) : NULL;
    if (sst == GR_OK && !whole) sst = gr_fail(err, GR_E_NOMEM, "%s: out of memory for its %zu-byte payload", path, expect);
    if (whole) p->data = whole;
    if (sst == GR_OK && fread(p->data + hn, 1, expect, f) != expect)
        sst = gr_fail(err, GR_E_INPUT, "%s: short read", path);
    fclose(f);
    if (sst != GR_OK) {
        part_free(p);
        return sst;
    }
    p->pay_n = expect;
    p->pay = p->data + hn;
    char h[20];
    snprintf(h, sizeof h, "%016llx", gr_fnv1a64(GR_FNV_BASIS, p->pay, p->pay_n));
    if (strcmp(h, fnv) != 0) {
        gr_fail(err, GR_E_INPUT, "%s: payload checksum %s, the header says %s: damaged", path, h, fnv);
        part_free(p); /* fnv lives in the header */
        return GR_E_INPUT;
    }
    return GR_OK;
}

gr_status gr_parts_merge(const char *const *paths, int n, gr_scene *scene, gr_ref_result *out, char *key,
                         size_t key_n, gr_error *err)
{
    memset(out, 0, sizeof *out);
    if (n < 1) return gr_fail(err, GR_E_USAGE, "merge: no parts given");
    part *ps = calloc((size_t)n, sizeof *ps);
    if (!ps) return gr_fail(err, GR_E_NOMEM, "merge: out of memory");
    gr_status st = GR_OK;
    int *owner = NULL;
    gr_ref_sums *sums = NULL;
    for (int i = 0; i < n && st == GR_OK; i++) st = part_read(paths[i], &ps[i], err);
    /* one scene, one set of settings, one image size (the cache key covers the scene's
     * content and every reference setting but threads) */
    const part *p0 = &ps[0];
    for (int i = 1; i < n && st == GR_OK; i++) {
        const part *p = &ps[i];
        if (strcmp(str(p->h, "cache_key"), str(p0->h, "cache_key")) != 0)
            st = gr_fail(err, GR_E_INPUT, "%s: another scene or settings than %s (cache key %s, not %s)", p->path,
                         p0->path, str(p->h, "cache_key"), str(p0->h, "cache_key"));
        else if (p->s.W != p0->s.W || p->s.H != p0->s.H || p->s.B != p0->s.B)
            st = gr_fail(err, GR_E_INPUT, "%s: %dx%d with %d batches, %s is %dx%d with %d", p->path, p->s.W, p->s.H,
                         p->s.B, p0->path, p0->s.W, p0->s.H, p0->s.B);
    }
    int W = p0->s.W, H = p0->s.H, B = p0->s.B;
    /* coverage: every (row, batch) once */
    if (st == GR_OK && !(owner = malloc((size_t)H * B * sizeof *owner))) st = gr_fail(err, GR_E_NOMEM, "merge: out of memory");
    if (st == GR_OK) {
        for (size_t k = 0; k < (size_t)H * B; k++) owner[k] = -1;
        for (int i = 0; i < n && st == GR_OK; i++)
            for (int y = ps[i].rc.row0; y < ps[i].rc.row1 && st == GR_OK; y++)
                for (int b = ps[i].rc.batch0; b < ps[i].rc.batch1; b++) {
                    int o = owner[(size_t)y * B + b];
                    if (o >= 0) {
                        st = gr_fail(err, GR_E_INPUT,
                                     "%s: row %d, batch %d is also in %s (a duplicated or overlapping part)",
                                     ps[i].path, y, b, ps[o].path);
                        break;
                    }
                    owner[(size_t)y * B + b] = i;
                }
        for (int y = 0; y < H && st == GR_OK; y++)
            for (int b = 0; b < B; b++)
                if (owner[(size_t)y * B + b] < 0) {
                    int y1 = y;
                    while (y1 + 1 < H && owner[(size_t)(y1 + 1) * B + b] < 0) y1++;
                    st = gr_fail(err, GR_E_INPUT, "merge: missing part: rows %d-%d of batch %d (of %dx%d, %d batches)", y,
                                 y1, b, W, H, B);
                    break;
                }
    }
    /* the probe: the parts that hold batch 0 carry it, for their rows */
    int probe = 0, pw = 0, ph = 0, plevels = 0;
    for (int i = 0; i < n && st == GR_OK; i++)
        if (ps[i].s.probe) {
            const gr_ref_sums *q = &ps[i].s;
            if (!probe) {
                probe = 1;
                pw = q->probe_w;
                ph = q->probe_h;
                plevels = q->probe_levels;
            } else if (q->probe_w != pw || q->probe_h != ph || q->probe_levels != plevels) {
                st = gr_fail(err, GR_E_INPUT, "%s: surface-bias probe of %dx%d pixels with %d levels, other parts %dx%d with %d",
                             ps[i].path, q->probe_w, q->probe_h, q->probe_levels, pw, ph, plevels);
            }
        }
    for (int i = 0; i < n && st == GR_OK && probe; i++)
        if (ps[i].rc.batch0 == 0 && !ps[i].s.probe)
            st = gr_fail(err, GR_E_INPUT, "%s: holds batch 0 but no surface-bias probe, other parts do", ps[i].path);
    if (st == GR_OK && !(sums = gr_ref_sums_create(W, H, B, probe ? plevels : 0, probe ? pw : 0, probe ? ph : 0)))
        st = gr_fail(err, GR_E_NOMEM, "merge: out of memory for %dx%d pixels x %d batches", W, H, B);
    double wall = 0.0;
    if (st == GR_OK) {
        int ok = 1, batch0_parts = 0;
        for (int i = 0; i < n; i++) {
            /* each part's sums where a single render accumulates them; its scalars by the
             * table's rules (reference/sums.h), in the parts' order */
            payload_walk(sums, &ps[i].rc, (unsigned char *)ps[i].pay, 1);
            gr_ref_sums_merge_scalars(sums, &ps[i].s, &ps[i].rc, &batch0_parts);
            const cJSON *pv = cJSON_GetObjectItemCaseSensitive(ps[i].h, "provenance");
            if (pv) wall += num(pv, "wall_s", &ok);
        }
        (void)ok;
        /* the probe pixels: every probe row must have come with some part */
        if (probe) {
            for (int y = 0; y < ph && st == GR_OK; y++) {
                int have = 0;
                for (int i = 0; i < n && !have; i++)
                    have = ps[i].s.probe && y >= ps[i].rc.probe_row0 && y < ps[i].rc.probe_row1;
                if (!have) st = gr_fail(err, GR_E_INPUT, "merge: surface-bias probe row %d is in no part", y);
            }
        }
    }
    /* the scene, as the parts rendered it; its key must be theirs */
    if (st == GR_OK) {
        st = gr_scene_load_string(str(p0->h, "scene"), p0->path, NULL, 0, scene, err);
        if (st == GR_OK) {
            const char *sp = str(p0->h, "scene_path");
            snprintf(scene->source_path, sizeof scene->source_path, "%s", sp ? sp : "");
        }
    }
    char k[GR_CACHE_KEY_LEN + 1] = "";
    if (st == GR_OK) st = gr_cache_key(scene, k, err);
    if (st == GR_OK && strcmp(k, str(p0->h, "cache_key")) != 0)
        st = gr_fail(err, GR_E_INPUT, "%s: its scene reloads with cache key %s, not %s (another godrays version?)", p0->path,
                     k, str(p0->h, "cache_key"));
    parts_checked pc = {sums, owner, ps, n};
    if (st == GR_OK) st = gr_truth_assemble(scene, sums, wall, parts_check_hook, &pc, out, err);
    if (st == GR_OK) {
        gr_meta_set_int(&out->meta, "godrays:merged_parts", n);
        gr_meta_set_string(&out->meta, "godrays:wall_s_note", "wall_s: the parts' wall times added up");
        for (int i = 0; i < n && st == GR_OK; i++) {
            const cJSON *pv = cJSON_GetObjectItemCaseSensitive(ps[i].h, "provenance");
            int ok = 1;
            const char *host = pv ? str(pv, "host") : NULL, *date = pv ? str(pv, "date") : NULL;
            char mk[48], line[1024];
            snprintf(mk, sizeof mk, "godrays:part.%d", i);
            snprintf(line, sizeof line, "%s: rows [%d, %d) batches [%d, %d) host %s pid %.15g date %s wall_s %.6g threads %.15g",
                     ps[i].path, ps[i].rc.row0, ps[i].rc.row1, ps[i].rc.batch0, ps[i].rc.batch1, host ? host : "?",
                     pv ? num(pv, "pid", &ok) : 0.0, date ? date : "?", pv ? num(pv, "wall_s", &ok) : 0.0,
                     pv ? num(pv, "threads", &ok) : 0.0);
            if (gr_meta_set_string(&out->meta, mk, line) != GR_OK) st = gr_fail(err, GR_E_NOMEM, "merge: out of memory");
        }
        if (st != GR_OK) gr_ref_result_free(out);
        else if (key) snprintf(key, key_n, "%s", k);
    }
    gr_ref_sums_destroy(sums);
    free(owner);
    for (int i = 0; i < n; i++) part_free(&ps[i]);
    free(ps);
    return st;
}
