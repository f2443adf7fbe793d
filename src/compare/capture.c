/* Capture sanity checks (capture.h; rules and thresholds in docs/metrics.md, "Capture warnings"). */
#include "compare/capture.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "compare/channels.h"
#include "compare/fit.h"

static double lum(const gr_image *im, size_t p, const int rgb[3])
{
    const float *px = im->pixels + p * (size_t)im->nchannels;
    return GR_LUM_R * (double)px[rgb[0]] + GR_LUM_G * (double)px[rgb[1]] + GR_LUM_B * (double)px[rgb[2]];
}

static void warn(gr_capture_report *out, const char *code, const char *fmt, ...)
{
    if (out->n >= GR_CAPTURE_MAX_WARNINGS) return;
    gr_capture_warning *w = &out->w[out->n++];
    w->code = code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->message, sizeof w->message, fmt, ap);
    va_end(ap);
}

/* Sums of one least-squares fit t ~ a r with a >= 0. */
typedef struct fitsum {
    double rr, tr, tt;
} fitsum;

static void fs_add(fitsum *f, double r, double t)
{
    f->rr += r * r, f->tr += r * t, f->tt += t * t;
}

/* RMSE after the best scale a >= 0, over n samples, relative to mean_r (the residual of
 * min_a ||a t - r||^2 = <r, r> - <t, r>^2 / <t, t>). */
static double fs_rel_err(const fitsum *f, double n, double mean_r)
{
    const double tr = f->tr > 0.0 ? f->tr : 0.0;
    double e = f->tt > 0.0 ? f->rr - tr * tr / f->tt : f->rr;
    if (e < 0.0) e = 0.0; /* rounding */
    const double rmse = n > 0.0 ? sqrt(e / n) : 0.0;
    return mean_r > 0.0 ? rmse / mean_r : rmse;
}

/* The fitted error of Y as given, upside down and mirrored: a capture read with the wrong row
 * order (OpenGL's bottom-up read-back saved top-down) or a mirrored camera matches the truth
 * better turned over. */
static void check_flips(const gr_capture_input *in, gr_capture_report *out)
{
    const gr_image *ref = in->ref, *test = in->test;
    const int W = ref->width, H = ref->height;
    fitsum f[3];
    memset(f, 0, sizeof f);
    double sr = 0.0, n = 0.0;
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            const size_t p = (size_t)y * (size_t)W + (size_t)x;
            if (in->scored && !in->scored[p]) continue;
            const double r = lum(ref, p, in->ref_rgb);
            const size_t q[3] = {p, (size_t)(H - 1 - y) * (size_t)W + (size_t)x, (size_t)y * (size_t)W + (size_t)(W - 1 - x)};
            for (int k = 0; k < 3; k++) fs_add(&f[k], r, lum(test, q[k], in->test_rgb));
            sr += r;
            n += 1.0;
        }
    }
    const double mean_r = n > 0.0 ? fabs(sr / n) : 0.0;
    out->err_given = fs_rel_err(&f[0], n, mean_r);
    out->err_vflip = fs_rel_err(&f[1], n, mean_r);
    out->err_hflip = fs_rel_err(&f[2], n, mean_r);
    static const char *const codes[2] = {"flipped_vertically", "flipped_horizontally"};
    static const char *const how[2] = {"upside down (rows in the other order)", "mirrored left-right"};
    const double e[2] = {out->err_vflip, out->err_hflip};
    for (int k = 0; k < 2; k++)
        if (out->err_given > 0.0 && e[k] < GR_CAPTURE_FLIP_MARGIN * out->err_given)
            warn(out, codes[k],
                 "matches the reference better %s: relative RMSE of Y after a scale fit %.4g, as given %.4g "
                 "(%.0f %% lower); a capture saved with the wrong row order or a mirrored camera?",
                 how[k], e[k], out->err_given, 100.0 * (1.0 - e[k] / out->err_given));
}

static void check_clipping(const gr_capture_input *in, gr_capture_report *out)
{
    const gr_capture_file *f[2] = {&in->ref_file, &in->test_file};
    static const char *const codes[2] = {"clipped_reference", "clipped_test"};
    const double npx = (double)in->ref->width * (double)in->ref->height;
    for (int k = 0; k < 2; k++) {
        out->top_fraction[k] = NAN;
        if (!(f[k]->integer && f[k]->bits == 8)) continue;
        out->top_fraction[k] = (double)f[k]->n_top_code / npx;
        if (out->top_fraction[k] > GR_CAPTURE_CLIP_FRACTION)
            warn(out, codes[k],
                 "%.2f %% of the pixels (%lld) are at the top code 255 of an 8-bit file: clipped highlights "
                 "(more than %.1f %%); capture in a float format (EXR) or at a lower exposure",
                 100.0 * out->top_fraction[k], f[k]->n_top_code, 100.0 * GR_CAPTURE_CLIP_FRACTION);
    }
}

static double srgb_encode(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* Ordinary least-squares slope of y over x from the sums. */
static double ols_slope(double n, double sx, double sy, double sxx, double sxy)
{
    const double vx = sxx - sx * sx / n;
    return vx > 0.0 ? (sxy - sx * sy / n) / vx : NAN;
}

/* The transfer check of an integer test file: its Y against the reference's on a log-log scale
 * rises with slope 1 when the codes were read the right way; codes decoded as sRGB although
 * they hold linear values give about 2.2 (the decoding's power), linear codes read as linear
 * although they hold sRGB values about 1 / 2.2. Both readings are scored over the same pixels
 * (codes 4..251 of each colour channel: not black, not clipped, above the quantization). */
static void check_transfer(const gr_capture_input *in, gr_capture_report *out)
{
    out->slope_given = out->slope_other = out->err_other = out->err_as_read = NAN;
    const gr_capture_file *tf = &in->test_file;
    if (!tf->integer) return;
    const gr_image *ref = in->ref, *test = in->test;
    const size_t np = (size_t)ref->width * (size_t)ref->height;
    const double lo = 4.0 / 255.0, hi = 251.0 / 255.0;
    double n = 0.0, sx = 0.0, sxx = 0.0, sy[2] = {0}, sxy[2] = {0}, sr = 0.0;
    fitsum f[2];
    memset(f, 0, sizeof f);
    static const double w[3] = {GR_LUM_R, GR_LUM_G, GR_LUM_B};
    for (size_t p = 0; p < np; p++) {
        if (in->scored && !in->scored[p]) continue;
        const double r = lum(ref, p, in->ref_rgb);
        if (!(r > 0.0)) continue;
        const float *tp = test->pixels + p * (size_t)test->nchannels;
        double y[2] = {0.0, 0.0};
        int ok = 1;
        for (int c = 0; c < 3 && ok; c++) {
            const double v = (double)tp[in->test_rgb[c]];
            const double code = tf->decoded ? srgb_encode(v) : v;
            ok = code >= lo && code <= hi;
            y[0] += w[c] * v;                                   /* as read */
            y[1] += w[c] * (tf->decoded ? code : srgb_decode(v)); /* read the other way */
        }
        if (!ok) continue;
        const double x = log(r);
        n += 1.0, sx += x, sxx += x * x, sr += r;
        for (int k = 0; k < 2; k++) {
            const double ly = log(y[k]);
            sy[k] += ly, sxy[k] += x * ly;
            fs_add(&f[k], r, y[k]);
        }
    }
    /* enough samples over enough of a range for a slope: 64, and a standard deviation of ln Y
     * of the reference of 0.3 (a factor 1.35) */
    if (n < 64.0 || (sxx - sx * sx / n) / n < 0.09) return;
    out->slope_given = ols_slope(n, sx, sy[0], sxx, sxy[0]);
    out->slope_other = ols_slope(n, sx, sy[1], sxx, sxy[1]);
    out->err_as_read = fs_rel_err(&f[0], n, sr / n);
    out->err_other = fs_rel_err(&f[1], n, sr / n);
    const double g = out->slope_given, g2 = out->slope_other;
    const int off = tf->decoded ? g > GR_CAPTURE_SLOPE : g < 1.0 / GR_CAPTURE_SLOPE;
    if (!off || !(fabs(log(g2)) < fabs(log(g))) || !(out->err_other < GR_CAPTURE_TRANSFER_MARGIN * out->err_as_read))
        return;
    if (tf->decoded)
        warn(out, "srgb_looks_linear",
             "decoded from sRGB, but its values look linear: ln Y(test) over ln Y(ref) has slope %.2f (1 expected), "
             "%.2f read as code / %d, where the error after a scale fit is %.0f %% lower; compare with "
             "--no-linearize, or capture with an sRGB encoding",
             g, g2, (1 << tf->bits) - 1, 100.0 * (1.0 - out->err_other / out->err_as_read));
    else
        warn(out, "linear_looks_srgb",
             "read as linear codes, but its values look sRGB-encoded: ln Y(test) over ln Y(ref) has slope %.2f "
             "(1 expected), %.2f sRGB-decoded, where the error after a scale fit is %.0f %% lower; compare "
             "without --no-linearize (or tag the file sRGB)",
             g, g2, 100.0 * (1.0 - out->err_other / out->err_as_read));
}

static void check_scale(const gr_capture_input *in, gr_capture_report *out)
{
    double a[3];
    out->scale = NAN;
    if (gr_fit_scales(in->ref, in->test, in->scored, in->ref_rgb, in->test_rgb, GR_FIT_SCALE, a) > 0) {
        out->scale = a[0];
        if (!(a[0] >= GR_CAPTURE_SCALE_LO && a[0] <= GR_CAPTURE_SCALE_HI))
            warn(out, "scale_out_of_range",
                 "the best scale fit is test x %.4g, outside [%g, %g]: a capture at another exposure or in other "
                 "units? (the errors after the fit hide it)", a[0], GR_CAPTURE_SCALE_LO, GR_CAPTURE_SCALE_HI);
    }
    for (int c = 0; in->fit_rgb && c < 3; c++)
        if (!(in->fit_rgb[c] >= GR_CAPTURE_SCALE_LO && in->fit_rgb[c] <= GR_CAPTURE_SCALE_HI))
            warn(out, "scale_out_of_range", "the per-channel fit's %c factor is x %.4g, outside [%g, %g]", "RGB"[c],
                 in->fit_rgb[c], GR_CAPTURE_SCALE_LO, GR_CAPTURE_SCALE_HI);
}

gr_status gr_capture_check(const gr_capture_input *in, gr_capture_report *out, gr_error *err)
{
    if (!out) return gr_fail(err, GR_E_INPUT, "capture check: no output");
    memset(out, 0, sizeof *out);
    if (!in || !in->ref || !in->test || !in->ref->pixels || !in->test->pixels || !in->ref_rgb || !in->test_rgb)
        return gr_fail(err, GR_E_INPUT, "capture check: no images");
    if (in->ref->width != in->test->width || in->ref->height != in->test->height)
        return gr_fail(err, GR_E_INPUT, "capture check: reference is %d x %d, test is %d x %d", in->ref->width,
                       in->ref->height, in->test->width, in->test->height);
    check_flips(in, out);
    check_clipping(in, out);
    check_transfer(in, out);
    check_scale(in, out);
    return GR_OK;
}
