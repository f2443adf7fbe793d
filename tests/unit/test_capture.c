/* Capture sanity checks (compare/capture.h) on images built here: a test flipped upside down or
 * mirrored gives its warning (and the fitted errors of the three orientations are what the
 * closed form gives: 0 for the right one); an 8-bit file with more than 0.5 % of its pixels at
 * the top code warns, 0.4 % does not, nor a 16-bit file; linear values decoded as sRGB, and
 * sRGB values read as linear, give the transfer warnings, the right readings none; a scale fit
 * outside [0.1, 10] warns, per channel too; the correct capture (the truth at another
 * exposure, within the range) gives no warning at all, nor does a left-right symmetric truth
 * against its own mirror image. */
#include <string.h>

#include "check.h"
#include "compare/capture.h"

enum { W = 64, H = 36 };
static const int RGB[3] = {0, 1, 2};

/* A glow in the upper left with a coloured tint: asymmetric both ways, values in (0.004, 1]. */
static double truth_at(int x, int y, int c)
{
    const double dx = (x - 18.0) / 20.0, dy = (y - 9.0) / 14.0;
    return (0.9 - 0.2 * c) * exp(-(dx * dx + dy * dy)) + 0.004 + 0.002 * c;
}

static gr_image *make(int flip_v, int flip_h, double gain)
{
    gr_image *im = gr_image_create(W, H, 3, NULL);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                im->pixels[((size_t)y * W + (size_t)x) * 3 + (size_t)c] =
                    (float)(gain * truth_at(flip_h ? W - 1 - x : x, flip_v ? H - 1 - y : y, c));
    return im;
}

static int has(const gr_capture_report *r, const char *code)
{
    for (int k = 0; k < r->n; k++)
        if (!strcmp(r->w[k].code, code)) return 1;
    return 0;
}

static gr_capture_report run(const gr_image *ref, const gr_image *test, gr_capture_file rf, gr_capture_file tf,
                             const double *fit_rgb)
{
    gr_capture_input in = {.ref = ref, .test = test, .ref_rgb = RGB, .test_rgb = RGB, .ref_file = rf,
                           .test_file = tf, .fit_rgb = fit_rgb};
    gr_capture_report r;
    gr_error err = {0};
    CHECK_OK(gr_capture_check(&in, &r, &err), err);
    return r;
}

static const gr_capture_file FLOAT_FILE = {.bits = 32};

static void test_flips(void)
{
    gr_image *ref = make(0, 0, 1.0), *good = make(0, 0, 0.5), *v = make(1, 0, 0.5), *h = make(0, 1, 0.5);
    gr_capture_report r = run(ref, good, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK_MSG(r.n == 0, "%d warning(s), first %s", r.n, r.n ? r.w[0].message : "");
    CHECK_NEAR(r.err_given, 0.0, 1e-6);
    CHECK(r.err_vflip > 0.3 && r.err_hflip > 0.3);
    CHECK_REL(r.scale, 2.0, 1e-6);
    r = run(ref, v, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK(has(&r, "flipped_vertically") && !has(&r, "flipped_horizontally") && r.n == 1);
    CHECK_NEAR(r.err_vflip, 0.0, 1e-6);
    r = run(ref, h, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK(has(&r, "flipped_horizontally") && !has(&r, "flipped_vertically") && r.n == 1);
    CHECK_NEAR(r.err_hflip, 0.0, 1e-6);
    /* a truth symmetric left-right: its mirror image is the same picture, no warning */
    gr_image *sym = gr_image_create(W, H, 3, NULL), *noisy = gr_image_create(W, H, 3, NULL);
    unsigned s = 99u;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                const size_t i = ((size_t)y * W + (size_t)x) * 3 + (size_t)c;
                sym->pixels[i] = (float)(1.0 / (1.0 + 0.01 * (x - 31.5) * (x - 31.5) + 0.05 * y));
                s = s * 1664525u + 1013904223u;
                noisy->pixels[i] = sym->pixels[i] * (float)(1.0 + 0.2 * ((double)(s >> 8) / 16777216.0 - 0.5));
            }
    r = run(sym, noisy, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK_MSG(r.n == 0, "%d warning(s), first %s", r.n, r.n ? r.w[0].message : "");
    gr_image_destroy(sym);
    gr_image_destroy(noisy);
    gr_image_destroy(ref);
    gr_image_destroy(good);
    gr_image_destroy(v);
    gr_image_destroy(h);
}

static void test_clipping(void)
{
    gr_image *ref = make(0, 0, 1.0), *t = make(0, 0, 1.0);
    const long long npx = W * H; /* 2304: 0.5 % is 11.52 pixels */
    gr_capture_file f8 = {.bits = 8, .integer = 1, .decoded = 1, .n_top_code = 12};
    gr_capture_report r = run(ref, t, FLOAT_FILE, f8, NULL);
    CHECK(has(&r, "clipped_test") && !has(&r, "clipped_reference"));
    CHECK_NEAR(r.top_fraction[1], 12.0 / (double)npx, 1e-15);
    f8.n_top_code = 11;
    r = run(ref, t, f8, f8, NULL);
    CHECK(!has(&r, "clipped_test") && !has(&r, "clipped_reference"));
    f8.n_top_code = 500;
    r = run(ref, t, f8, FLOAT_FILE, NULL);
    CHECK(has(&r, "clipped_reference") && !has(&r, "clipped_test"));
    gr_capture_file f16 = {.bits = 16, .integer = 1, .decoded = 1, .n_top_code = 500};
    r = run(ref, t, FLOAT_FILE, f16, NULL);
    CHECK(!has(&r, "clipped_test"));
    gr_image_destroy(ref);
    gr_image_destroy(t);
}

static double enc(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055; }
static double dec(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/* What the reader gives for a file of 8-bit codes: code / 255, sRGB-decoded or not. */
static gr_image *as_read(const gr_image *lin, int store_srgb, int decode)
{
    gr_image *im = gr_image_create(W, H, 3, NULL);
    for (size_t i = 0; i < (size_t)W * H * 3; i++) {
        double v = lin->pixels[i];
        const double code = round(255.0 * (store_srgb ? enc(v) : v)) / 255.0;
        im->pixels[i] = (float)(decode ? dec(code) : code);
    }
    return im;
}

static void test_transfer(void)
{
    gr_image *ref = make(0, 0, 1.0);
    const gr_capture_file dec8 = {.bits = 8, .integer = 1, .decoded = 1}, lin8 = {.bits = 8, .integer = 1};
    gr_image *right = as_read(ref, 1, 1);   /* sRGB codes, decoded: right */
    gr_image *lin_dec = as_read(ref, 0, 1); /* linear codes decoded as sRGB */
    gr_image *srgb_lin = as_read(ref, 1, 0);/* sRGB codes read as linear */
    gr_image *lin_lin = as_read(ref, 0, 0); /* linear codes read as linear: right */
    gr_capture_report r = run(ref, right, FLOAT_FILE, dec8, NULL);
    CHECK_MSG(r.n == 0, "%d warning(s), first %s", r.n, r.n ? r.w[0].message : "");
    CHECK_NEAR(r.slope_given, 1.0, 0.05);
    r = run(ref, lin_lin, FLOAT_FILE, lin8, NULL);
    CHECK_MSG(r.n == 0, "%d warning(s), first %s", r.n, r.n ? r.w[0].message : "");
    r = run(ref, lin_dec, FLOAT_FILE, dec8, NULL);
    CHECK_MSG(has(&r, "srgb_looks_linear"), "slope %g, other %g, errors %g %g", r.slope_given, r.slope_other,
              r.err_as_read, r.err_other);
    CHECK(r.slope_given > 1.6 && fabs(r.slope_other - 1.0) < 0.05);
    r = run(ref, srgb_lin, FLOAT_FILE, lin8, NULL);
    CHECK_MSG(has(&r, "linear_looks_srgb"), "slope %g, other %g, errors %g %g", r.slope_given, r.slope_other,
              r.err_as_read, r.err_other);
    CHECK(r.slope_given < 0.625);
    /* float files are not checked */
    r = run(ref, srgb_lin, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK(!has(&r, "linear_looks_srgb") && isnan(r.slope_given));
    gr_image_destroy(right);
    gr_image_destroy(lin_dec);
    gr_image_destroy(srgb_lin);
    gr_image_destroy(lin_lin);
    gr_image_destroy(ref);
}

static void test_scale(void)
{
    gr_image *ref = make(0, 0, 1.0), *dim = make(0, 0, 0.05), *ok = make(0, 0, 0.2);
    gr_capture_report r = run(ref, dim, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK(has(&r, "scale_out_of_range") && r.n == 1);
    CHECK_REL(r.scale, 20.0, 1e-6);
    r = run(ref, ok, FLOAT_FILE, FLOAT_FILE, NULL);
    CHECK(r.n == 0);
    const double fit_rgb[3] = {5.0, 5.0, 12.0};
    r = run(ref, ok, FLOAT_FILE, FLOAT_FILE, fit_rgb);
    CHECK(has(&r, "scale_out_of_range") && r.n == 1 && strstr(r.w[0].message, "B factor"));
    gr_image_destroy(ref);
    gr_image_destroy(dim);
    gr_image_destroy(ok);
}

static void test_bad_input(void)
{
    gr_image *a = gr_image_create(4, 4, 3, NULL), *b = gr_image_create(4, 5, 3, NULL);
    gr_capture_input in = {.ref = a, .test = b, .ref_rgb = RGB, .test_rgb = RGB};
    gr_capture_report r;
    gr_error err = {0};
    CHECK(gr_capture_check(&in, &r, &err) == GR_E_INPUT && strstr(err.msg, "4 x 5"));
    in.test = NULL;
    CHECK(gr_capture_check(&in, &r, &err) == GR_E_INPUT);
    gr_image_destroy(a);
    gr_image_destroy(b);
}

int main(void)
{
    test_flips();
    test_clipping();
    test_transfer();
    test_scale();
    test_bad_input();
    CHECK_DONE();
}
