/* Issue 31 (docs/reliability.md, "Issue 31: readers and memory"): the part-file reader of
 * `godrays merge` against forged and damaged parts. Parts are written by gr_part_write from
 * sums made here (so their payload checksum is valid), some then have a header field edited
 * (the checksum covers the payload only) or bytes appended. Expectations are independent of
 * the reader: a render of the 4 x 2 flat scene with 2 batches, 2 sun samples and spp 3 gives
 * each pixel of each batch 1 pass x 3 samples; a merged pixel is its sums over its samples
 * (R 0.25, G 0.5, B 0.75 per sample here). Forged sums (NaN, 1e308, negative), counts (0) and
 * passes (negative, wrong), sizes that no scene allows (height 2^24, 27.9, width 1e300) or
 * that are over the memory limit, and a padded file are refused with exit-2 status naming
 * the field, and the refusals allocate nothing of the size claimed (peak RSS grows < 48 MB
 * where the old reader took 128 MB, 256 MB). A probe mismatch names the levels. */
#define _GNU_SOURCE
#include "check.h"

#include <cjson/cJSON.h>
#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "farm/parts.h"

static gr_scene scene;
static char dir[512];

static double peak_rss_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* Sums of rows [row0, row1) and batches [b0, b1) of the 4 x 2 image, 2 batches: 3 samples
 * per pixel and batch, per-sample radiance (0.25, 0.5, 0.75); probe_levels > 0 adds a 1 x 1
 * probe grid. */
static gr_ref_sums *make_sums(int probe_levels)
{
    gr_ref_sums *s = gr_ref_sums_create(4, 2, 2, probe_levels, probe_levels ? 1 : 0, probe_levels ? 1 : 0);
    if (!s) return NULL;
    for (size_t k = 0; k < 4 * 2 * 2; k++) {
        s->count[k] = 3;
        for (int c = 0; c < 3; c++) s->sum[k * 3 + c] = 0.25 * (c + 1) * 3;
    }
    s->passes = 2;
    if (probe_levels) {
        s->probe = 1;
        s->probe_stride = 5;
        s->probe_passes = 2;
        for (int k = 0; k < probe_levels; k++) {
            s->probe_count[k][0] = 3;
            for (int c = 0; c < 3; c++) s->probe_sum[k][c] = 0.5;
        }
    }
    return s;
}

static void write_part(const char *path, gr_ref_sums *s, int row0, int row1)
{
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.row0 = row0;
    o.row1 = row1;
    o.batch0 = 0;
    o.batch1 = 2;
    gr_ref_result res;
    memset(&res, 0, sizeof res);
    gr_meta_init(&res.meta);
    res.sums = s;
    gr_error err = {GR_OK, ""};
    gr_status st = gr_part_write(path, &scene, &o, &res, "test", &err);
    CHECK_OK(st, err);
    gr_meta_free(&res.meta);
}

/* Rewrites the part's header with one number changed (the payload, and its checksum, stay). */
static void edit_header(const char *path, const char *key, double v)
{
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    if (!f) return;
    char magic[64], len[64];
    size_t hn = 0;
    CHECK(fgets(magic, sizeof magic, f) && fgets(len, sizeof len, f) && sscanf(len, "%zu", &hn) == 1);
    char *h = calloc(hn + 1, 1);
    unsigned char pay[4096];
    size_t got = h ? fread(h, 1, hn, f) : 0;
    size_t pn = fread(pay, 1, sizeof pay, f);
    fclose(f);
    CHECK(got == hn && pn < sizeof pay);
    cJSON *j = cJSON_Parse(h);
    CHECK(j != NULL);
    cJSON_ReplaceItemInObjectCaseSensitive(j, key, cJSON_CreateNumber(v));
    char *t = cJSON_PrintUnformatted(j);
    f = fopen(path, "wb");
    CHECK(f && t);
    if (f && t) {
        fprintf(f, "%s%zu\n", magic, strlen(t));
        fwrite(t, 1, strlen(t), f);
        fwrite(pay, 1, pn, f);
        fclose(f);
    }
    cJSON_free(t);
    cJSON_Delete(j);
    free(h);
}

/* Merges the given parts; checks the status and that the message holds `want`. */
static void expect_refused(const char *what, const char *const *paths, int n, const char *want, double max_rss_growth_mb)
{
    gr_ref_result res;
    gr_error err = {GR_OK, ""};
    char key[80];
    const double rss0 = peak_rss_mb();
    gr_status st = gr_parts_merge(paths, n, &scene, &res, key, sizeof key, &err);
    const double grown = peak_rss_mb() - rss0;
    CHECK_MSG(st == GR_E_INPUT && strstr(err.msg, want), "%s: status %d, message '%s', expected one with '%s'", what,
              (int)st, err.msg, want);
    CHECK_MSG(max_rss_growth_mb <= 0 || grown < max_rss_growth_mb, "%s: peak RSS grew by %.0f MB", what, grown);
    if (st == GR_OK) gr_ref_result_free(&res);
}

static void forged_sum(const char *path, const char *what, double v, uint32_t count, int passes, const char *want)
{
    gr_ref_sums *s = make_sums(0);
    s->sum[(6 * 2 + 1) * 3 + 1] = v; /* pixel (2, 1), batch 1, G */
    s->count[6 * 2 + 1] = count;
    s->passes = passes;
    write_part(path, s, 0, 2);
    gr_ref_sums_destroy(s);
    expect_refused(what, &path, 1, want, 0);
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR"), *out = getenv("GODRAYS_TEST_OUT");
    char sp[1024];
    snprintf(sp, sizeof sp, "%s/data/scenes/flat.json", src ? src : ".");
    snprintf(dir, sizeof dir, "%s/rel_parts", out ? out : "/tmp");
    char cmd[600];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    CHECK(system(cmd) == 0);
    const char *sets[] = {"camera.width=4", "camera.height=2", "reference.batches=2", "reference.sun_samples=2",
                          "reference.spp=3"};
    gr_error err = {GR_OK, ""};
    gr_status st = gr_scene_load_file(sp, sets, 5, &scene, &err);
    CHECK_OK(st, err);
    if (st != GR_OK) CHECK_DONE();
    char p[600], q[600];
    snprintf(p, sizeof p, "%s/part.grpart", dir);
    snprintf(q, sizeof q, "%s/part2.grpart", dir);
    const char *pp = p, *two[2] = {p, q};

    /* the valid part: the expected pixels */
    gr_ref_sums *s = make_sums(0);
    write_part(p, s, 0, 2);
    gr_ref_sums_destroy(s);
    gr_ref_result res;
    char key[80];
    st = gr_parts_merge(&pp, 1, &scene, &res, key, sizeof key, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) {
        const float *px = gr_image_pixel(res.image, 3, 1);
        CHECK_NEAR(px[0], 0.25, 1e-7);
        CHECK_NEAR(px[1], 0.5, 1e-7);
        CHECK_NEAR(px[2], 0.75, 1e-7);
        CHECK(res.spp == 6 && res.passes == 2);
        gr_ref_result_free(&res);
    }

    /* beam_refine_radius_m -1: a render whose camera sees no refinement cone (a horizontal
     * view, reference/beams.h) writes it; such parts merge (the farm refused them once) */
    s = make_sums(0);
    write_part(p, s, 0, 2);
    gr_ref_sums_destroy(s);
    edit_header(p, "beam_refine_radius_m", -1.0);
    st = gr_parts_merge(&pp, 1, &scene, &res, key, sizeof key, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) gr_ref_result_free(&res);
    edit_header(p, "beam_refine_radius_m", -2.0);
    expect_refused("refine radius -2", &pp, 1, "header field beam_refine_radius_m is -2", 0);

    /* forged sums, counts and passes with a valid checksum (they merged with exit 0) */
    forged_sum(p, "NaN sum", NAN, 3, 2, "not a finite radiance sum");
    forged_sum(p, "1e308 sum", 1e308, 3, 2, "not a finite radiance sum");
    forged_sum(p, "negative sum", -1.0, 3, 2, "not a finite radiance sum");
    forged_sum(p, "zero count", 1.5, 0, 2, "has 0 samples; its scene gives 3");
    forged_sum(p, "4 samples", 1.5, 4, 2, "has 4 samples; its scene gives 3");
    forged_sum(p, "negative passes", 1.5, 3, -3, "header field passes is -3");
    forged_sum(p, "wrong passes", 1.5, 3, 5, "5 passes for 2 batches");

    /* forged sizes: refused from the header, before anything of their size is allocated */
    s = make_sums(0);
    write_part(p, s, 0, 2);
    edit_header(p, "height", 16777216.0);
    expect_refused("height 2^24", &pp, 1, "header field height is 16777216", 48);
    write_part(p, s, 0, 2);
    edit_header(p, "height", 27.9);
    expect_refused("height 27.9", &pp, 1, "header field height is 27.899999999999999, expected an integer", 0);
    write_part(p, s, 0, 2);
    edit_header(p, "width", 1e300);
    expect_refused("width 1e300", &pp, 1, "header field width is 1.0000000000000001e+300", 0);
    /* 4 x 16384 pixels x 1024 batches: 1.9 GB of sums, over a 1 GiB limit (within every range) */
    write_part(p, s, 0, 2);
    edit_header(p, "height", 16384);
    edit_header(p, "batches", 1024);
    setenv("GODRAYS_MAX_MEMORY", "1G", 1);
    expect_refused("over the memory limit", &pp, 1, "over the memory limit of 1.00 GiB (GODRAYS_MAX_MEMORY)", 48);
    unsetenv("GODRAYS_MAX_MEMORY");
    /* a valid part padded with 256 MB (a sparse file): refused before it is read */
    write_part(p, s, 0, 2);
    FILE *f = fopen(p, "ab");
    CHECK(f && ftruncate(fileno(f), 256 << 20) == 0);
    if (f) fclose(f);
    expect_refused("padded", &pp, 1, "truncated or damaged, or padded", 48);
    gr_ref_sums_destroy(s);

    /* the probe: levels 3 and 2 (both grids 1 x 1) are named as what differs */
    s = make_sums(3);
    write_part(p, s, 0, 1);
    gr_ref_sums_destroy(s);
    s = make_sums(2);
    write_part(q, s, 1, 2);
    gr_ref_sums_destroy(s);
    expect_refused("probe levels", two, 2, "probe of 1x1 pixels with 2 levels, other parts 1x1 with 3", 0);
    remove(p);
    remove(q);
    CHECK_DONE();
}
