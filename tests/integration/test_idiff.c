/* Cross-check against OpenImageIO's `idiff -a` (openimageio-tools), an independent
 * implementation: its "Mean error" (mean |d| over all channels), "RMS error", "Peak SNR"
 * (20 log10(max(1, max value of both images) / RMS)) and "Max error @ (x, y, channel)" must
 * equal our pooled RGB row (mae, rmse, psnr_idiff_db, max_abs_err and where). The EXR files
 * hold R, G, B only, since idiff compares every channel.
 *
 * idiff prints 6 significant digits. Cases 1 and 2 are designed so that its printed values
 * are within 2e-7 of the exact ones: there ours must agree to 1e-6 relative. Case 3 (random
 * HDR values) checks agreement to idiff's printed precision, half a unit of the 6th digit. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "compare/metrics.h"
#include "image/exr.h"

typedef struct idiff_out {
    double mean, rms, psnr, max;
    int x, y;
    char chan[16];
    int found; /* bit mask of the lines parsed */
} idiff_out;

static int find_idiff(char *buf, size_t n)
{
    const char *path = getenv("PATH");
    if (!path) return 0;
    char *copy = strdup(path);
    int ok = 0;
    for (char *save = NULL, *dir = strtok_r(copy, ":", &save); dir && !ok; dir = strtok_r(NULL, ":", &save)) {
        snprintf(buf, n, "%s/idiff", dir);
        ok = access(buf, X_OK) == 0;
    }
    free(copy);
    return ok;
}

static int run_idiff(const char *idiff, const char *a, const char *b, idiff_out *o)
{
    char cmd[4096];
    if (snprintf(cmd, sizeof cmd, "'%s' -a '%s' '%s' 2>&1", idiff, a, b) >= (int)sizeof cmd) return -1;
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    memset(o, 0, sizeof *o);
    char line[512];
    while (fgets(line, sizeof line, p)) {
        fputs(line, stdout); /* kept in the test log */
        if (sscanf(line, " Mean error = %lf", &o->mean) == 1) o->found |= 1;
        if (sscanf(line, " RMS error = %lf", &o->rms) == 1) o->found |= 2;
        if (sscanf(line, " Peak SNR = %lf", &o->psnr) == 1) o->found |= 4;
        if (sscanf(line, " Max error = %lf @ (%d, %d, %15[A-Za-z0-9.])", &o->max, &o->x, &o->y, o->chan) == 4)
            o->found |= 8;
    }
    return pclose(p);
}

static void write_pair(const char *dir, const char *name, const gr_image *a, const gr_image *b, char *pa, char *pb,
                       size_t n)
{
    gr_error err = {0};
    snprintf(pa, n, "%s/idiff_%s_ref.exr", dir, name);
    snprintf(pb, n, "%s/idiff_%s_test.exr", dir, name);
    CHECK_OK(gr_exr_write(pa, a, NULL, &err), err);
    CHECK_OK(gr_exr_write(pb, b, NULL, &err), err);
}

/* Compares, with tolerance tol(v) = rel * |v| or, if printed, half a unit of the 6th digit. */
static void check_case(const char *idiff, const char *dir, const char *name, const gr_image *a, const gr_image *b,
                       int printed_precision)
{
    char pa[1024], pb[1024];
    write_pair(dir, name, a, b, pa, pb, sizeof pa);
    idiff_out o;
    int rc = run_idiff(idiff, pa, pb, &o);
    CHECK_MSG(rc != -1 && o.found == 15, "%s: idiff output not parsed (found mask %d)", name, o.found);
    gr_metrics m;
    gr_error err = {0};
    gr_metrics_options opt = {.skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(a, b, &opt, &m, &err), err);
    const gr_channel_metrics *P = &m.raw.ch[GR_MCH_RGB];
    const double ours[4] = {P->mae, P->rmse, P->psnr_idiff_db, P->max_abs_err};
    const double theirs[4] = {o.mean, o.rms, o.psnr, o.max};
    const char *what[4] = {"mean error", "RMS error", "PSNR", "max error"};
    for (int k = 0; k < 4; k++) {
        double tol = 1e-6 * fabs(theirs[k]);
        if (printed_precision && theirs[k] != 0.0)
            tol = 0.5 * pow(10.0, floor(log10(fabs(theirs[k]))) - 5.0) * (1.0 + 1e-9);
        CHECK_MSG(fabs(ours[k] - theirs[k]) <= tol, "%s %s: ours %.9g, idiff %.9g (tol %.3g)", name, what[k], ours[k],
                  theirs[k], tol);
    }
    CHECK_MSG(P->max_x == o.x && P->max_y == o.y, "%s: max at (%d, %d), idiff (%d, %d)", name, P->max_x, P->max_y, o.x,
              o.y);
    CHECK_MSG(P->max_c >= 0 && o.chan[0] == "RGB"[P->max_c] && o.chan[1] == '\0', "%s: max channel %d, idiff %s", name,
              P->max_c, o.chan);
}

int main(void)
{
    char idiff[1024];
    if (!find_idiff(idiff, sizeof idiff)) {
        fprintf(stderr, "idiff not found on PATH (Debian package openimageio-tools)\n");
        return 1;
    }
    const char *dir = getenv("GODRAYS_TEST_OUT");
    if (!dir || !dir[0]) dir = "/tmp";

    /* Case 1 (LDR, peak 1): 2 x 2 RGB at 0.5; the test is 0.7 in three samples, R of (1, 0),
     * G of (0, 1) and B of (1, 1), where |d| = 0.2 (max, first at (1, 0, R)).
     *   mean = 3 * 0.2 / 12 = 0.05, RMS = sqrt(3 * 0.04 / 12) = 0.1, PSNR = 20 log10(1/0.1) = 20. */
    gr_image *a = gr_image_create(2, 2, 3, NULL), *b = gr_image_create(2, 2, 3, NULL);
    for (int i = 0; i < 12; i++) a->pixels[i] = b->pixels[i] = 0.5f;
    b->pixels[3 * 1 + 0] = 0.7f;
    b->pixels[3 * 2 + 1] = 0.7f;
    b->pixels[3 * 3 + 2] = 0.7f;
    check_case(idiff, dir, "ldr", a, b, 0);

    /* Case 2 (HDR): the same differences on top of 3.5, and one sample of the reference at 4:
     * peak = max(1, 4, 3.7) = 4; PSNR = 20 log10(4 / 0.1) = 32.0411998 (idiff: 32.0412). */
    for (int i = 0; i < 12; i++) a->pixels[i] = b->pixels[i] = 3.5f;
    b->pixels[3 * 1 + 0] = 3.7f;
    b->pixels[3 * 2 + 1] = 3.7f;
    b->pixels[3 * 3 + 2] = 3.7f;
    a->pixels[1] = 4.0f, b->pixels[1] = 4.0f;
    check_case(idiff, dir, "hdr", a, b, 0);
    gr_image_destroy(a);
    gr_image_destroy(b);

    /* Case 3: 37 x 23 random HDR values in [0, 3), the test a noisy, biased copy. */
    a = gr_image_create(37, 23, 3, NULL);
    b = gr_image_create(37, 23, 3, NULL);
    unsigned s = 2024u;
    for (int i = 0; i < 37 * 23 * 3; i++) {
        s = s * 1664525u + 1013904223u;
        a->pixels[i] = (float)(s >> 8) / 16777216.0f * 3.0f;
        s = s * 1664525u + 1013904223u;
        b->pixels[i] = a->pixels[i] * 0.9f + ((float)(s >> 8) / 16777216.0f - 0.5f) * 0.4f;
    }
    check_case(idiff, dir, "random", a, b, 1);
    gr_image_destroy(a);
    gr_image_destroy(b);
    CHECK_DONE();
}
