/* Sequence metrics (see temporal.h; docs/metrics.md "Time"). */
#include "compare/temporal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/channels.h"

double gr_temporal_profile_drift(const double *f0, const unsigned char *v0, const double *f1, const unsigned char *v1,
                                 int n_theta, double max_deg)
{
    if (!f0 || !f1 || !v0 || !v1 || n_theta < 3) return 0.0;
    int smax = (int)ceil(max_deg / 360.0 * n_theta);
    if (smax > n_theta / 2 - 1) smax = n_theta / 2 - 1;
    if (smax < 1) smax = 1;
    /* c(s) = normalized correlation of f0(theta) with f1(theta + s): the pattern of frame 0
     * found s bins further in frame 1 */
    double best = -INFINITY, cm = 0, cp = 0;
    int bs = 0;
    double *c = malloc((size_t)(2 * smax + 1) * sizeof(double));
    if (!c) return 0.0;
    for (int s = -smax; s <= smax; s++) {
        double sab = 0, saa = 0, sbb = 0, sa = 0, sb = 0;
        int k = 0;
        for (int j = 0; j < n_theta; j++) {
            const int jj = ((j + s) % n_theta + n_theta) % n_theta;
            if (!v0[j] || !v1[jj]) continue;
            sa += f0[j], sb += f1[jj], sab += f0[j] * f1[jj], saa += f0[j] * f0[j], sbb += f1[jj] * f1[jj];
            k++;
        }
        double r = 0.0;
        if (k > 1) {
            const double va = saa - sa * sa / k, vb = sbb - sb * sb / k;
            r = va > 0 && vb > 0 ? (sab - sa * sb / k) / sqrt(va * vb) : 0.0;
        }
        c[s + smax] = r;
        if (r > best) best = r, bs = s;
    }
    double off = 0.0;
    if (bs > -smax && bs < smax) {
        cm = c[bs - 1 + smax], cp = c[bs + 1 + smax];
        const double den = cm - 2.0 * best + cp;
        if (den < 0.0) off = 0.5 * (cm - cp) / den; /* vertex of the parabola through 3 points */
    }
    free(c);
    return (bs + off) * 360.0 / n_theta;
}

/* luminance of a T and R, and R's luminance standard error (linear sum: any correlation) */
static void lum3(const gr_image *img, const int rgb[3], size_t p, double a, double *y)
{
    const float *px = img->pixels + p * (size_t)img->nchannels;
    *y = a * (GR_LUM_R * px[rgb[0]] + GR_LUM_G * px[rgb[1]] + GR_LUM_B * px[rgb[2]]);
}

static int stderr_channels(const gr_image *img, int s[3])
{
    s[0] = gr_image_channel(img, "stderr.R"), s[1] = gr_image_channel(img, "stderr.G");
    s[2] = gr_image_channel(img, "stderr.B");
    return s[0] >= 0 && s[1] >= 0 && s[2] >= 0;
}

static double stderr_y(const gr_image *img, const int s[3], size_t p)
{
    const float *px = img->pixels + p * (size_t)img->nchannels;
    return GR_LUM_R * fabs(px[s[0]]) + GR_LUM_G * fabs(px[s[1]]) + GR_LUM_B * fabs(px[s[2]]);
}

gr_status gr_temporal_compute(const gr_image *const *ref, const gr_image *const *test, int n,
                              const gr_temporal_options *opt, gr_temporal_frame *frames, gr_temporal_pair *pairs,
                              gr_temporal_summary *sum, gr_error *err)
{
    const gr_temporal_options zero = {0};
    if (!opt) opt = &zero;
    if (!ref || !test || !sum) return gr_fail(err, GR_E_INPUT, "temporal: NULL argument");
    if (n < 2) return gr_fail(err, GR_E_INPUT, "temporal: need at least 2 frames (got %d)", n);
    const int w = ref[0] ? ref[0]->width : 0, h = ref[0] ? ref[0]->height : 0;
    for (int i = 0; i < n; i++) {
        const gr_image *im[2] = {ref[i], test[i]};
        for (int k = 0; k < 2; k++) {
            if (!im[k] || !im[k]->pixels || im[k]->width != w || im[k]->height != h)
                return gr_fail(err, GR_E_INPUT, "temporal: %s frame %d is missing or not %d x %d", k ? "test" : "reference",
                               i, w, h);
            const size_t ns = (size_t)w * (size_t)h * (size_t)im[k]->nchannels;
            for (size_t j = 0; j < ns; j++)
                if (!isfinite(im[k]->pixels[j]))
                    return gr_fail(err, GR_E_INPUT, "temporal: %s frame %d has a non-finite sample",
                                   k ? "test" : "reference", i);
        }
    }
    const double a = opt->scale == 0.0 ? 1.0 : opt->scale;
    if (!isfinite(a)) return gr_fail(err, GR_E_INPUT, "temporal: the test scale is not finite");
    memset(sum, 0, sizeof *sum);
    sum->n_frames = n;
    const size_t np = (size_t)w * (size_t)h;
    int have_se = 1;
    for (int i = 0; i < n; i++) {
        int s[3];
        have_se = have_se && stderr_channels(ref[i], s);
    }
    sum->have_stderr = have_se;
    /* per frame */
    for (int i = 0; i < n; i++) {
        int rr[3], tr[3];
        gr_metrics_pick_rgb(ref[i], rr);
        gr_metrics_pick_rgb(test[i], tr);
        double se = 0, sr = 0;
        long long cnt = 0;
        for (size_t p = 0; p < np; p++) {
            if (opt->scored && !opt->scored[p]) continue;
            double yt, yr;
            lum3(test[i], tr, p, a, &yt);
            lum3(ref[i], rr, p, 1.0, &yr);
            se += (yt - yr) * (yt - yr), sr += yr * yr, cnt++;
        }
        const double rm = cnt ? sqrt(se / cnt) : 0.0, rr2 = cnt ? sqrt(sr / cnt) : 0.0;
        if (frames) frames[i].rmse_y = rm, frames[i].rel_rmse_y = rr2 > 0 ? rm / rr2 : 0.0;
        sum->frame_rmse_mean += rm / n;
    }
    /* pairs */
    double s_diff2 = 0, s_truth2 = 0, s_test2 = 0;
    for (int i = 0; i + 1 < n; i++) {
        int r0[3], r1[3], t0[3], t1[3], se0[3] = {0, 0, 0}, se1[3] = {0, 0, 0};
        gr_metrics_pick_rgb(ref[i], r0), gr_metrics_pick_rgb(ref[i + 1], r1);
        gr_metrics_pick_rgb(test[i], t0), gr_metrics_pick_rgb(test[i + 1], t1);
        if (have_se) stderr_channels(ref[i], se0), stderr_channels(ref[i + 1], se1);
        double e2 = 0, nv = 0, dr2 = 0, dt2 = 0;
        long long cnt = 0;
        for (size_t p = 0; p < np; p++) {
            if (opt->scored && !opt->scored[p]) continue;
            double ya, yb, xa, xb;
            lum3(ref[i], r0, p, 1.0, &ya), lum3(ref[i + 1], r1, p, 1.0, &yb);
            lum3(test[i], t0, p, a, &xa), lum3(test[i + 1], t1, p, a, &xb);
            const double dR = yb - ya, dT = xb - xa;
            e2 += (dT - dR) * (dT - dR), dr2 += dR * dR, dt2 += dT * dT;
            if (have_se) {
                const double s0 = stderr_y(ref[i], se0, p), s1 = stderr_y(ref[i + 1], se1, p);
                nv += s0 * s0 + s1 * s1; /* independent renders: variances add */
            }
            cnt++;
        }
        gr_temporal_pair pr = {0};
        if (cnt) e2 /= cnt, nv /= cnt, dr2 /= cnt, dt2 /= cnt;
        pr.diff_rmse_raw = sqrt(e2);
        pr.truth_noise_rms = sqrt(nv);
        pr.diff_rmse = sqrt(fmax(0.0, e2 - nv));
        pr.truth_diff_rms = sqrt(fmax(0.0, dr2 - nv));
        pr.test_diff_rms = sqrt(dt2);
        s_diff2 += pr.diff_rmse * pr.diff_rmse, s_truth2 += pr.truth_diff_rms * pr.truth_diff_rms;
        s_test2 += dt2;
        if (pairs) pairs[i] = pr;
    }
    sum->diff_rmse = sqrt(s_diff2 / (n - 1));
    sum->rel_diff_rmse = s_truth2 > 0 ? sum->diff_rmse / sqrt(s_truth2 / (n - 1)) : 0.0;
    sum->flicker_ratio = s_truth2 > 0 ? sqrt(s_test2 / s_truth2) : 0.0;
    if (opt->skip_drift) return GR_OK;
    /* drift: the angular profile of each frame on one ring around the vanishing point */
    gr_structure_options so = opt->structure;
    so.scored = opt->scored;
    const int nt = so.n_theta ? so.n_theta : 1024;
    double r0 = opt->drift_r0, r1 = opt->drift_r1;
    if (r0 == 0.0 && r1 == 0.0) {
        r0 = so.r_min_px != 0.0 ? so.r_min_px : 0.1 * h;
        r1 = so.r_max_px;
        if (r1 == 0.0)
            for (int c = 0; c < 4; c++)
                r1 = fmax(r1, hypot((c & 1 ? (double)w : 0.0) - so.vp_x, (c & 2 ? (double)h : 0.0) - so.vp_y));
    }
    const double maxd = opt->max_drift_deg > 0 ? opt->max_drift_deg : 20.0;
    double *f = malloc(4 * (size_t)nt * sizeof(double));
    unsigned char *v = malloc(4 * (size_t)nt);
    if (!f || !v) {
        free(f), free(v);
        return gr_fail(err, GR_E_NOMEM, "temporal: out of memory");
    }
    gr_status st = GR_OK;
    /* slots: 0, 1 = ref frames i, i + 1; 2, 3 = test frames i, i + 1 */
    for (int i = 0; st == GR_OK && i < n; i++) {
        const int cur = i & 1;
        st = gr_structure_angular_profile(ref[i], &so, r0, r1, f + (size_t)cur * nt, v + (size_t)cur * nt, err);
        if (st == GR_OK)
            st = gr_structure_angular_profile(test[i], &so, r0, r1, f + (size_t)(2 + cur) * nt,
                                              v + (size_t)(2 + cur) * nt, err);
        if (st != GR_OK || i == 0) continue;
        const int prev = cur ^ 1;
        const double dref = gr_temporal_profile_drift(f + (size_t)prev * nt, v + (size_t)prev * nt, f + (size_t)cur * nt,
                                                      v + (size_t)cur * nt, nt, maxd);
        const double dtest = gr_temporal_profile_drift(f + (size_t)(2 + prev) * nt, v + (size_t)(2 + prev) * nt,
                                                       f + (size_t)(2 + cur) * nt, v + (size_t)(2 + cur) * nt, nt, maxd);
        if (pairs) pairs[i - 1].drift_ref_deg = dref, pairs[i - 1].drift_test_deg = dtest,
                   pairs[i - 1].drift_err_deg = fabs(dtest - dref);
        sum->drift_err_mean_deg += fabs(dtest - dref) / (n - 1);
    }
    free(f), free(v);
    if (st == GR_OK) sum->have_drift = 1;
    return st;
}
