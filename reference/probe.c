#include "reference/probe.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reference/stats.h"

int gr_ref_probe_stats(gr_ref_renderer *r, double *const sum[], uint32_t *const cnt[], int nl, size_t np, int pw, int ph,
                       int off)
{
    enum { NL = 3 };
    /* a fourth level: h with the cells near the camera 2x finer (gr_ref_probe_holds_near): their
     * own error by Richardson toward finer cells, e = (L_h - L_h/2) 2^p / (2^p - 1), with p = 2
     * for the estimate (4/3) and p = 1 for the conservative figures (2) */
    const int near = nl > NL;
    float *bpx = malloc(np * 3 * sizeof *bpx + 1);
    if (!bpx) return -1;
    /* per channel c: d1 = sum |L_2h - L_h|, d2 = sum |L_4h - L_2h|, v = sum L_h over the probe
     * pixels; the RGB mean's too (the order is measured on it: the channels share their
     * geometry, and the mean is the least noisy) */
    double d1 = 0.0, d2 = 0.0, v = 0.0, d1c[3] = {0.0, 0.0, 0.0}, vc[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < np; i++) {
        double l[NL] = {0.0, 0.0, 0.0}, lc[NL][3];
        for (int k = 0; k < NL; k++)
            for (int c = 0; c < 3; c++) {
                lc[k][c] = cnt[k][i] ? sum[k][i * 3 + c] / cnt[k][i] : 0.0;
                l[k] += lc[k][c] / 3.0;
            }
        d1 += fabs(l[1] - l[0]);
        d2 += fabs(l[2] - l[1]);
        v += l[0];
        for (int c = 0; c < 3; c++) {
            /* with the fourth level: |the plain grid's e + the near cells' e| x 3 (order 2) */
            double en = near && cnt[NL][i] ? (lc[0][c] - sum[NL][i * 3 + c] / cnt[NL][i]) * (4.0 / 3.0) : 0.0;
            d1c[c] += fabs(lc[1][c] - lc[0][c] + 3.0 * en);
            vc[c] += lc[0][c];
        }
    }
    /* the worst channel's relative difference (issue 30: the targets hold per channel, not on
     * their mean; a channel whose light is absorbed faster carries more of the tessellation's
     * error, e.g. red on a level view: 4.9 % against 2.6 % for blue, docs/reference.md 4).
     * Channels below 1e-3 of the brightest one's light are left out (invisible, and their
     * relative difference is the probe's residual noise). */
    double vmax = fmax(vc[0], fmax(vc[1], vc[2])), rel1 = v > 0.0 && !near ? d1 / v : 0.0;
    for (int c = 0; c < 3; c++)
        if (vc[c] > 1e-3 * vmax && d1c[c] / vc[c] > rel1) rel1 = d1c[c] / vc[c];
    /* the measured order of convergence, clamped to [1, 2] */
    double ratio = d1 > 0.0 ? d2 / d1 : 4.0, order = ratio > 0.0 ? log2(ratio) : 2.0;
    if (!(order <= 2.0)) order = 2.0;
    if (!(order >= 1.0)) order = 1.0;
    double div = pow(2.0, order) - 1.0; /* Richardson: e_h = (L_2h - L_h) / (2^p - 1) */
    /* the conservative figure per channel (with the fourth level: the near cells' e with p = 1) */
    double consc[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < np; i++)
        for (int c = 0; c < 3; c++) {
            double lh = cnt[0][i] ? sum[0][i * 3 + c] / cnt[0][i] : 0.0, l2h = cnt[1][i] ? sum[1][i * 3 + c] / cnt[1][i] : 0.0;
            double e = (l2h - lh) / div; /* signed, per channel */
            if (near && cnt[NL][i]) e += 2.0 * (lh - sum[NL][i * 3 + c] / cnt[NL][i]);
            consc[c] += fabs(e);
            bpx[i * 3 + c] = isfinite(e) ? (float)e : 0.0f;
        }
    double rel_cons = rel1 / div; /* three levels: the estimate's figure with the measured order */
    if (near) { /* four: the worst channel's sum of the two errors, the near cells' with p = 1 */
        rel_cons = 0.0;
        for (int c = 0; c < 3; c++)
            if (vc[c] > 1e-3 * vmax && consc[c] / vc[c] > rel_cons) rel_cons = consc[c] / vc[c];
    }
    /* the estimate: the asymptotic order 2 (divide by 3); the conservative figure: the
     * measured order (convergence accelerates as h shrinks, so the order measured on the
     * coarser pair is a lower bound of the order at h and the figure an upper one) */
    r->bias_rel = v > 0.0 && isfinite(rel1) ? rel1 / 3.0 : (d1 > 0.0 ? -1.0 : 0.0);
    r->bias_rel_cons = v > 0.0 && isfinite(rel_cons) ? rel_cons : (d1 > 0.0 ? -1.0 : 0.0);
    r->bias_ratio = ratio;
    r->bias_order = order;
    r->bias_probe_pixels = (long long)np;
    free(r->bias_px);
    r->bias_px = bpx;
    r->bias_pw = pw;
    r->bias_ph = ph;
    r->bias_poff = off;
    return 0;
}

void gr_ref_probe_grid(const gr_ref_renderer *r, int *off, int *pw, int *ph)
{
    int W = r->scene.camera.width, H = r->scene.camera.height;
    *off = W > PROBE_STRIDE / 2 && H > PROBE_STRIDE / 2 ? PROBE_STRIDE / 2 : 0;
    *pw = (W - *off + PROBE_STRIDE - 1) / PROBE_STRIDE;
    *ph = (H - *off + PROBE_STRIDE - 1) / PROBE_STRIDE;
}

int gr_ref_probe_holds_near(const gr_ref_renderer *r)
{
    enum { NL = 3, FMAX = 64 }; /* levels h, 2h, 4h; beams.c's largest refine_factor */
    return r->near_F > 1 && r->near_F * r->near_cpw >= r->scene.reference.near_cells_per_wavelength &&
           (r->near_F << (NL - 1)) <= FMAX;
}

gr_status gr_ref_probe_march(gr_ref_renderer *r, ref_accum *a, int pass, int off, gr_ref_pool *pool, gr_progress *prog,
                             double frac0, double span, const char *note, ref_march_totals *tot, int *complete,
                             gr_error *err)
{
    /* a part probes its own rows' probe pixels */
    int y0 = gr_ref_probe_row(r->opt.row0, PROBE_STRIDE, off, a->H);
    int y1 = gr_ref_probe_row(r->opt.row1, PROBE_STRIDE, off, a->H);
    return gr_ref_march_pass(r, a, pass, 0, PROBE_STRIDE, off, y0, y1, pool, prog, frac0, span, note, tot, complete, err);
}

gr_status gr_ref_probe_run(gr_ref_renderer *r, gr_ref_sums *keep, ref_accum *captured, ref_accum *captured_fine,
                           gr_ref_pool *pool, gr_progress *prog, double frac0, double span, ref_march_totals *tot,
                           gr_error *err)
{
    enum { NL = 3, NMAX = 4 }; /* levels h, 2h, 4h (and h with the near cells 2x finer) */
    /* the near set's cells keep their size at 2h and 4h, and a fourth level measures their own
     * error (gr_ref_probe_holds_near) */
    const int F0 = r->near_F, hold = gr_ref_probe_holds_near(r), nl = NL + hold;
    int off, pw, ph;
    gr_ref_probe_grid(r, &off, &pw, &ph);
    int res = r->set.surface_res, lres[NMAX], lnear[NMAX];
    for (int k = 0; k < NL; k++) {
        lres[k] = (res >> k) > 2 ? res >> k : 2;
        lnear[k] = hold ? F0 << k : F0;
    }
    lres[NL] = res;
    lnear[NL] = 2 * F0;
    int passes = r->passes_per_round < PROBE_PASSES ? r->passes_per_round : PROBE_PASSES;
    ref_accum a[NMAX];
    memset(a, 0, sizeof a);
    for (int k = 0; k < nl; k++) {
        a[k].W = pw;
        a[k].H = ph;
        a[k].B = 1; /* the passes summed: the sums a part file carries (src/farm/parts.h) */
    }
    size_t np = (size_t)a[0].W * a[0].H;
    gr_status st = GR_OK;
    /* level h taken from the main passes when every probe pass ran there (a part whose batches
     * miss some of them renders level h here, as the others) */
    int have[NMAX] = {0, 0, 0, 0};
    unsigned want = (1u << passes) - 1u;
    if (captured && captured->sum && (r->probe_captured & want) == want) {
        a[0].sum = captured->sum;
        a[0].count = captured->count;
        captured->sum = NULL;
        captured->count = NULL;
        have[0] = 1;
    }
    /* the fourth level likewise (gr_ref_render marched it with the main passes' plain sets) */
    if (hold && captured_fine && captured_fine->sum && (r->probe_captured_fine & want) == want) {
        a[NL].sum = captured_fine->sum;
        a[NL].count = captured_fine->count;
        captured_fine->sum = NULL;
        captured_fine->count = NULL;
        have[NL] = 1;
    }
    int todo = 0; /* the levels rendered here */
    for (int k = 0; k < nl; k++) todo += !have[k];
    for (int k = 0; k < nl && st == GR_OK; k++) {
        if (have[k]) continue;
        a[k].sum = calloc(np * 3, sizeof *a[k].sum);
        a[k].count = calloc(np, sizeof *a[k].count);
        if (!a[k].sum || !a[k].count) st = gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
    }
    int complete = 1;
    for (int p = 0, done = 0; p < passes && st == GR_OK && complete; p++)
        for (int k = 0; k < nl && st == GR_OK && complete; k++) {
            if (have[k]) continue;
            r->set.surface_res = lres[k];
            /* the fourth level as gr_ref_render takes it: the pass's sets, then the near set
             * replaced by the finer one (gr_ref_near_fine; the same sums either way) */
            r->near_F = k == NL ? F0 : lnear[k];
            r->beams_pass = -1; /* another resolution: rebuild */
            st = gr_ref_prepare_pass(r, p, err);
            if (st == GR_OK && k == NL) st = gr_ref_near_fine(r, p, lnear[NL], err);
            if (st == GR_E_INTERRUPTED) { st = GR_OK; complete = 0; break; }
            if (st == GR_OK)
                st = gr_ref_probe_march(r, &a[k], p, off, pool, prog, frac0 + span * done / (todo * (double)passes),
                                        span / (todo * (double)passes), "surface-bias probe", tot, &complete, err);
            done++;
        }
    r->set.surface_res = res;
    r->near_F = F0;
    r->beams_pass = -1;
    if (st == GR_OK && complete) {
        double *sums[NMAX] = {a[0].sum, a[1].sum, a[2].sum, a[3].sum};
        uint32_t *cnts[NMAX] = {a[0].count, a[1].count, a[2].count, a[3].count};
        if (gr_ref_probe_stats(r, sums, cnts, nl, np, a[0].W, a[0].H, off) != 0)
            st = gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
        r->bias_probe_passes = passes;
        if (st == GR_OK && keep) { /* hand the sums over */
            keep->probe_w = a[0].W;
            keep->probe_h = a[0].H;
            keep->probe_levels = nl;
            for (int k = 0; k < nl; k++) {
                free(keep->probe_sum[k]);
                free(keep->probe_count[k]);
                keep->probe_sum[k] = a[k].sum;
                keep->probe_count[k] = a[k].count;
                a[k].sum = NULL;
                a[k].count = NULL;
            }
            keep->probe = 1;
            keep->probe_stride = PROBE_STRIDE;
            keep->probe_off = off;
            keep->probe_passes = passes;
        }
    }
    for (int k = 0; k < NMAX; k++) {
        free(a[k].sum);
        free(a[k].count);
    }
    return st;
}

void gr_ref_block_bias(gr_ref_renderer *r, const gr_image *img)
{
    r->bias_block_p95 = -1.0;
    r->bias_blocks = 0;
    if (!r->bias_px || !img) return;
    /* the image's mean per channel; channels below 1e-3 of the brightest are left out (as in
     * gr_ref_probe_stats) */
    double im[3] = {0.0, 0.0, 0.0};
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++) {
            const float *px = gr_image_pixel((gr_image *)img, x, y);
            for (int c = 0; c < 3; c++) im[c] += px[c];
        }
    for (int c = 0; c < 3; c++) im[c] /= (double)img->width * img->height;
    const double imax = fmax(im[0], fmax(im[1], im[2]));
    int bw = (r->bias_pw + 1) / 2, bh = (r->bias_ph + 1) / 2, bs = 2 * PROBE_STRIDE;
    double *v = malloc((size_t)bw * bh * sizeof *v);
    if (!v) return;
    size_t n = 0;
    for (int J = 0; J < bh; J++)
        for (int I = 0; I < bw; I++) {
            double b[3] = {0.0, 0.0, 0.0}, m[3] = {0.0, 0.0, 0.0};
            int nb = 0, nm = 0;
            for (int j = 2 * J; j < 2 * J + 2 && j < r->bias_ph; j++)
                for (int i = 2 * I; i < 2 * I + 2 && i < r->bias_pw; i++, nb++)
                    for (int c = 0; c < 3; c++) b[c] += r->bias_px[((size_t)j * r->bias_pw + (size_t)i) * 3 + c];
            for (int y = J * bs; y < (J + 1) * bs && y < img->height; y++)
                for (int x = I * bs; x < (I + 1) * bs && x < img->width; x++, nm++) {
                    const float *px = gr_image_pixel((gr_image *)img, x, y);
                    for (int c = 0; c < 3; c++) m[c] += px[c];
                }
            if (!nb || !nm) continue;
            /* the worst channel's |block bias| / max(block mean, image mean) */
            double w = -1.0;
            for (int c = 0; c < 3; c++) {
                double den = fmax(m[c] / nm, im[c]);
                if (!(den > 0.0) || !(im[c] > 1e-3 * imax)) continue;
                double q = fabs(b[c] / nb) / den;
                if (q > w) w = q;
            }
            if (w >= 0.0) v[n++] = w;
        }
    if (n) {
        r->bias_block_p95 = gr_ref_percentile(v, n, 0.95);
        r->bias_blocks = (int)n;
    }
    free(v);
}
