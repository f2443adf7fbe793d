/* `godrays merge` of a render split into 4 row tiles x 8 single-batch parts equals one
 * `godrays reference` run of the same scene byte for byte: every float of R, G, B and the
 * three stderr channels, and the statistics computed from the batch sums (image mean,
 * relative standard errors of the mean and of the p95 pixel, fraction within 1 %, the
 * surface-bias probe's estimate, spp, passes). Two scenes: the default (waves, occluders,
 * seabed, bias probe) and flat water (closed form, no occluders). The parts are rendered
 * with 1 thread and the single run with 2 (the same bytes for any thread count). A missing,
 * a duplicated, a mismatched, a damaged and a truncated part each exit 2 naming the file. The oracle is
 * the independent single run. Runs the built binary (GODRAYS_BINARY). */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include <stdarg.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/exr.h"

static const char *bin;

/* Runs bin with the NULL-terminated arguments; stderr to a log; returns the exit code. */
static int run(const char *log, ...)
{
    char *argv[64];
    int n = 0;
    argv[n++] = (char *)bin;
    va_list ap;
    va_start(ap, log);
    for (const char *a; n < 63 && (a = va_arg(ap, const char *)) != NULL;) argv[n++] = (char *)a;
    va_end(ap);
    argv[n] = NULL;
    pid_t pid = fork();
    if (pid == 0) {
        FILE *f = freopen(log, "w", stderr);
        (void)f;
        execv(bin, argv);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static int log_has(const char *log, const char *text)
{
    FILE *f = fopen(log, "r");
    if (!f) return 0;
    char buf[8192];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return strstr(buf, text) != NULL;
}

static double meta_num(const gr_metadata *m, const char *key)
{
    const gr_meta_item *it = gr_meta_get(m, key);
    CHECK_MSG(it != NULL, "metadata %s missing", key);
    return it ? it->num : -12345.0;
}

static void same_image(const char *a, const char *b, int expect_probe)
{
    gr_image *ia = NULL, *ib = NULL;
    gr_metadata ma, mb;
    gr_meta_init(&ma);
    gr_meta_init(&mb);
    gr_error err = {GR_OK, ""};
    gr_status st = gr_exr_read(a, &ia, &ma, &err);
    CHECK_OK(st, err);
    st = gr_exr_read(b, &ib, &mb, &err);
    CHECK_OK(st, err);
    if (ia && ib) {
        CHECK(ia->width == ib->width && ia->height == ib->height && ia->nchannels == ib->nchannels);
        /* RGB and the error bars always; the bias channels where the probe ran (not on flat water) */
        CHECK(gr_image_channel(ia, "R") >= 0 && gr_image_channel(ia, "stderr.B") >= 0);
        CHECK(ia->nchannels == 6 || (ia->nchannels == 9 && gr_image_channel(ia, "bias.R") >= 0));
        if (ia->width == ib->width && ia->height == ib->height && ia->nchannels == ib->nchannels) {
            size_t n = (size_t)ia->width * ia->height * ia->nchannels, diff = 0, nonzero = 0;
            for (size_t i = 0; i < n; i++) {
                uint32_t x, y;
                memcpy(&x, ia->pixels + i, 4);
                memcpy(&y, ib->pixels + i, 4);
                diff += x != y;
                nonzero += x != 0;
            }
            CHECK_MSG(diff == 0, "%s vs %s: %zu of %zu floats differ", a, b, diff, n);
            CHECK_MSG(nonzero > n / 4, "%s: only %zu of %zu floats nonzero (an empty render proves nothing)", a, nonzero, n);
        }
        static const char *const keys[] = {"godrays:image_mean", "godrays:image_p95", "godrays:rel_stderr_mean",
                                           "godrays:rel_stderr_p95", "godrays:frac_pixels_stderr_le_1pct",
                                           "godrays:bias_surface_rel_est", "godrays:spp", "godrays:passes",
                                           "godrays:preview_exposure", "godrays:steps_mean", "godrays:steps_min",
                                           "godrays:steps_max", "godrays:steps_capped_frac",
                                           "godrays:steps_wanted_mean_capped"};
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
            double va = meta_num(&ma, keys[k]), vb = meta_num(&mb, keys[k]);
            CHECK_MSG(memcmp(&va, &vb, sizeof va) == 0, "%s: %.17g (single) vs %.17g (merged)", keys[k], va, vb);
        }
        /* adaptive steps (the default): the parts' pilots must agree; under waves the steps vary,
         * flat water takes the fewest everywhere (docs/reference.md 2.5) */
        if (expect_probe) CHECK(meta_num(&ma, "godrays:steps_min") < meta_num(&ma, "godrays:steps_max"));
        else CHECK(meta_num(&ma, "godrays:steps_max") == meta_num(&ma, "godrays:reference.min_steps"));
        /* the local refinements' summaries (under waves, on by default) travel with the parts: the
         * camera cone's set, or the set near the camera where that covers the cone (the
         * surface_res here leaves the grid under 6.4 cells per wave: docs/reference.md 2.2) */
        int have = 0;
        for (int q = 0; q < 2; q++) {
            const char *key = q ? "godrays:surface_refine_near" : "godrays:surface_refine";
            const gr_meta_item *ra = gr_meta_get(&ma, key), *rb = gr_meta_get(&mb, key);
            CHECK_MSG((ra != NULL) == (rb != NULL), "%s: single %s, merged %s", key, ra ? "set" : "unset", rb ? "set" : "unset");
            if (ra && rb) CHECK_MSG(!strcmp(ra->str, rb->str), "%s: %s vs %s", key, ra->str, rb->str);
            have |= ra != NULL;
        }
        if (expect_probe) CHECK_MSG(have, "no refinement stated on %s (the view looks at the sun)", a);
        /* the probe's fourth level (the near cells 2x finer) ran and came through the parts */
        if (expect_probe)
            CHECK_MSG(meta_num(&ma, "godrays:bias_probe_near_held") == 1.0 && meta_num(&mb, "godrays:bias_probe_near_held") == 1.0,
                      "%s: the probe held the near cells (single %g, merged %g)", a, meta_num(&ma, "godrays:bias_probe_near_held"),
                      meta_num(&mb, "godrays:bias_probe_near_held"));
        double bias = meta_num(&ma, "godrays:bias_surface_rel_est");
        CHECK_MSG(expect_probe ? bias > 0.0 : bias == 0.0, "%s: bias estimate %g (probe expected: %d)", a, bias, expect_probe);
        CHECK(meta_num(&mb, "godrays:merged_parts") == 32.0);
        CHECK(gr_meta_get(&mb, "godrays:part.31") != NULL);
    }
    gr_image_destroy(ia);
    gr_image_destroy(ib);
    gr_meta_free(&ma);
    gr_meta_free(&mb);
}

int main(void)
{
    bin = getenv("GODRAYS_BINARY");
    const char *src = getenv("GODRAYS_SOURCE_DIR"), *out = getenv("GODRAYS_TEST_OUT");
    if (!bin || !src) {
        fprintf(stderr, "GODRAYS_BINARY and GODRAYS_SOURCE_DIR must be set (ctest does)\n");
        return 1;
    }
    char dir[4096], log[4200];
    snprintf(dir, sizeof dir, "%s/merge", out ? out : "/tmp");
    mkdir(dir, 0755);
    snprintf(log, sizeof log, "%s/log.txt", dir);
    static const struct { const char *scene; int probe; } scenes[] = {{"default.json", 1}, {"flat.json", 0}};
    /* small and fast: 96x54, 8 batches of one pass each; the default scene's 64 cells leave
     * 2 per wave, so a set near the camera is built (docs/reference.md 2.2): a disc of 6 plain
     * cells keeps it in the parts at a quarter of the default disc's cost; a target of 5.5
     * cells per wave, which factor 3 reaches, makes the bias probe hold the near cells and
     * render its fourth level (docs/reference.md 4), so the parts carry four probe levels */
    static const char *const q[] = {"--size", "96x54", "--surface-res", "64", "--steps", "32", "--quiet",
                                    "--set", "reference.near_radius_cells=6", "--set",
                                    "reference.near_cells_per_wavelength=5.5"};
#define Q q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], q[9], q[10]
    char parts[32][4300];
    for (int s = 0; s < 2; s++) {
        char scene[4200], full[4300], merged[4300];
        snprintf(scene, sizeof scene, "%s/data/scenes/%s", src, scenes[s].scene);
        snprintf(full, sizeof full, "%s/full%d.exr", dir, s);
        snprintf(merged, sizeof merged, "%s/merged%d.exr", dir, s);
        int rc = run(log, "reference", scene, Q, "--threads", "2", "--no-preview", "-o", full, (char *)NULL);
        CHECK_MSG(rc == 0, "single render of %s: exit %d", scene, rc);
        for (int t = 0; t < 4; t++)
            for (int b = 0; b < 8; b++) {
                char tile[16], bp[16];
                snprintf(tile, sizeof tile, "%d/4", t);
                snprintf(bp, sizeof bp, "%d/8", b);
                snprintf(parts[t * 8 + b], sizeof parts[0], "%s/s%d_t%d_b%d.part", dir, s, t, b);
                rc = run(log, "reference", scene, Q, "--threads", "1", "--tile", tile, "--batch-part", bp, "-o",
                         parts[t * 8 + b], (char *)NULL);
                CHECK_MSG(rc == 0, "part %s of %s: exit %d", parts[t * 8 + b], scene, rc);
            }
        const char *a[40];
        int n = 0;
        a[n++] = "merge";
        /* any order: reversed */
        for (int i = 31; i >= 0; i--) a[n++] = parts[i];
        a[n++] = "--no-preview";
        a[n++] = "-o";
        a[n++] = merged;
        a[n] = NULL;
#define A32 a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], a[9], a[10], a[11], a[12], a[13], a[14], a[15], \
            a[16], a[17], a[18], a[19], a[20], a[21], a[22], a[23], a[24], a[25], a[26], a[27], a[28], a[29], a[30], \
            a[31], a[32]
        rc = run(log, A32, a[33], a[34], a[35], (char *)NULL);
        CHECK_MSG(rc == 0, "merge of %s: exit %d", scene, rc);
        same_image(full, merged, scenes[s].probe);
    }
    /* errors, on the flat scene's parts (a[] still lists them, reversed) */
    char bad[4300];
    snprintf(bad, sizeof bad, "%s/bad.exr", dir);
    int rc = run(log, "merge", parts[0], parts[1], "-o", bad, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "missing part"), "2 of 32 parts: exit %d", rc);
    rc = run(log, "merge", parts[0], parts[0], "-o", bad, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "duplicated"), "a part twice: exit %d", rc);
    /* a part of another seed (other settings) */
    char other[4300], scene[4200];
    snprintf(scene, sizeof scene, "%s/data/scenes/flat.json", src);
    snprintf(other, sizeof other, "%s/other.part", dir);
    rc = run(log, "reference", scene, Q, "--seed", "7", "--tile", "0/4", "--batch-part", "0/8", "-o", other, (char *)NULL);
    CHECK(rc == 0);
    rc = run(log, "merge", parts[1], other, "-o", bad, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "another scene or settings"), "a part of another seed: exit %d", rc);
    /* a part with one flipped payload byte */
    char flipped[4300];
    snprintf(flipped, sizeof flipped, "%s/flipped.part", dir);
    FILE *in = fopen(parts[5], "rb"), *fo = fopen(flipped, "wb");
    if (in && fo) {
        int ch;
        long pos = 0, len;
        fseek(in, 0, SEEK_END);
        len = ftell(in);
        fseek(in, 0, SEEK_SET);
        while ((ch = fgetc(in)) != EOF) fputc(pos++ == len - 7 ? ch ^ 0x10 : ch, fo);
    }
    if (in) fclose(in);
    if (fo) fclose(fo);
    rc = run(log, "merge", flipped, "-o", bad, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "checksum"), "a damaged part: exit %d", rc);
    /* a truncated part */
    FILE *f = fopen(other, "r+b");
    if (f) {
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        fclose(f);
        CHECK(truncate(other, len - 100) == 0);
    }
    rc = run(log, "merge", other, "-o", bad, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "truncated or damaged"), "a truncated part: exit %d", rc);
    struct stat sb;
    CHECK_MSG(stat(bad, &sb) != 0, "%s written by a failed merge", bad);
    /* parts refuse what they cannot merge exactly */
    rc = run(log, "reference", scene, Q, "--tile", "0/4", "--target-error", "0.05", "-o", other, (char *)NULL);
    CHECK_MSG(rc == 2 && log_has(log, "target_error"), "--target-error with --tile: exit %d", rc);
    rc = run(log, "reference", scene, Q, "--tile", "4/4", "-o", other, (char *)NULL);
    CHECK_MSG(rc == 2, "--tile 4/4: exit %d", rc);
    CHECK_DONE();
}
