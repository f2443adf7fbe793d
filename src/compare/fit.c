/* Scale fits of a test image (fit.h; derivation in docs/metrics.md, "Scale fits"). */
#include "compare/fit.h"

#include <string.h>

#include "compare/channels.h"

static const char *const names[] = {"none", "scale", "rgb"};

const char *gr_fit_mode_name(gr_fit_mode m)
{
    return (int)m >= 0 && (int)m < 3 ? names[m] : NULL;
}

static int is_word(const char *s)
{
    for (int k = 0; s && k < 3; k++)
        if (!strcmp(s, names[k])) return 1;
    return 0;
}

gr_status gr_fit_mode_parse(const char *flag, const char *s, gr_fit_mode *m, gr_error *err)
{
    for (int k = 0; s && k < 3; k++) {
        if (strcmp(s, names[k])) continue;
        *m = (gr_fit_mode)k;
        return GR_OK;
    }
    return gr_fail(err, GR_E_USAGE, "%s '%s': use scale (one factor for R, G, B), rgb (one per channel) or none",
                   flag, s ? s : "");
}

int gr_fit_mode_option(int argc, char *const *argv, int *i, gr_fit_mode *m, gr_error *err)
{
    const char *a = argv[*i];
    if (!strcmp(a, "--fit-scale")) *m = GR_FIT_SCALE;
    else if (!strcmp(a, "--no-fit")) *m = GR_FIT_NONE;
    else if (!strncmp(a, "--fit=", 6)) return gr_fit_mode_parse("--fit", a + 6, m, err) == GR_OK ? 1 : -1;
    else if (strcmp(a, "--fit")) return 0;
    else if (*i + 1 < argc && is_word(argv[*i + 1])) return gr_fit_mode_parse("--fit", argv[++*i], m, err) == GR_OK ? 1 : -1;
    else *m = GR_FIT_SCALE;
    return 1;
}

int gr_fit_scales(const gr_image *ref, const gr_image *test, const unsigned char *scored, const int rr[3],
                  const int tr[3], gr_fit_mode mode, double a[3])
{
    a[0] = a[1] = a[2] = 1.0;
    if (mode == GR_FIT_NONE) return 0;
    if (!ref || !test || !ref->pixels || !test->pixels || ref->width != test->width || ref->height != test->height)
        return 0;
    /* Least squares: d/da_c sum (a_c t_c - r_c)^2 = 0 gives a_c = <t_c, r_c> / <t_c, t_c> per
     * channel; one shared a sums both products over the three channels (docs/metrics.md). */
    double tr_dot[3] = {0}, tt_dot[3] = {0}, num = 0.0, den = 0.0; /* per channel; pooled */
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    for (size_t p = 0; p < n; p++) {
        if (scored && !scored[p]) continue;
        const float *rp = ref->pixels + p * (size_t)ref->nchannels;
        const float *tp = test->pixels + p * (size_t)test->nchannels;
        for (int c = 0; c < 3; c++) {
            const double t = (double)tp[tr[c]], r = (double)rp[rr[c]];
            tr_dot[c] += t * r;
            tt_dot[c] += t * t;
            num += t * r;
            den += t * t;
        }
    }
    if (mode == GR_FIT_SCALE) {
        if (!(den > 0.0)) return 0;
        a[0] = a[1] = a[2] = num / den;
        return 3;
    }
    int defined = 0;
    for (int c = 0; c < 3; c++) {
        if (!(tt_dot[c] > 0.0)) continue;
        a[c] = tr_dot[c] / tt_dot[c];
        defined++;
    }
    return defined;
}

double gr_fit_luminance_scale(const double a[3], const double mean_t[3])
{
    static const double w[3] = {GR_LUM_R, GR_LUM_G, GR_LUM_B};
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; c++) {
        num += w[c] * a[c] * mean_t[c];
        den += w[c] * mean_t[c];
    }
    return den != 0.0 ? num / den : (a[0] + a[1] + a[2]) / 3.0;
}
