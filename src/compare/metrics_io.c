/* Metrics as a table and as JSON (see metrics_io.h, docs/metrics.md). */
#include "compare/metrics_io.h"

#include <math.h>

#include "compare/registry.h"

/* JSON has no infinity: a non-finite number (only PSNR of identical images, or an unbounded
 * stderr bound) is written as null, documented in docs/metrics.md. */
static int add_num(cJSON *o, const char *k, double v)
{
    return (isfinite(v) ? cJSON_AddNumberToObject(o, k, v) : cJSON_AddNullToObject(o, k)) != NULL;
}

static cJSON *channel_json(const gr_channel_metrics *c, int with_sig, int with_blur)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    int ok = add_num(o, "n_samples", (double)c->n_samples) && add_num(o, "ref_mean", c->ref_mean) &&
             add_num(o, "test_mean", c->test_mean) && add_num(o, "bias", c->bias) && add_num(o, "mae", c->mae) &&
             add_num(o, "mse", c->mse) && add_num(o, "rmse", c->rmse) && add_num(o, "rel_mse", c->rel_mse) &&
             add_num(o, "rel_mse_eps", c->rel_mse_eps) && add_num(o, "peak_ref", c->peak_ref) &&
             add_num(o, "psnr_ref_peak_db", c->psnr_ref_db) && add_num(o, "peak_idiff", c->peak_idiff) &&
             add_num(o, "psnr_idiff_db", c->psnr_idiff_db) && add_num(o, "max_abs_error", c->max_abs_err);
    cJSON *at = ok ? cJSON_AddObjectToObject(o, "max_at") : NULL;
    ok = ok && at && add_num(at, "x", c->max_x) && add_num(at, "y", c->max_y) &&
         (c->max_c >= 0 ? add_num(at, "channel", c->max_c) : 1) && add_num(at, "ref", c->max_ref) &&
         add_num(at, "test", c->max_test);
    if (ok && with_blur) {
        cJSON *b = cJSON_AddObjectToObject(o, "rmse_blurred");
        ok = b != NULL;
        for (int s = 0; ok && s < GR_METRICS_NSCALES; s++) {
            char k[32];
            snprintf(k, sizeof k, "sigma_%g", gr_metrics_blur_sigmas[s]);
            ok = add_num(b, k, c->rmse_blur[s]);
        }
    }
    if (ok && with_sig) {
        ok = add_num(o, "n_not_significant", (double)c->n_not_significant) &&
             add_num(o, "fraction_not_significant",
                     c->n_samples > 0 ? (double)c->n_not_significant / (double)c->n_samples : 0.0);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static cJSON *set_json(const gr_metrics *m, const gr_metrics_set *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON *srgb = cJSON_AddObjectToObject(o, "scale_rgb");
    int ok = srgb && add_num(srgb, "R", s->scale_rgb[0]) && add_num(srgb, "G", s->scale_rgb[1]) &&
             add_num(srgb, "B", s->scale_rgb[2]) && add_num(o, "scale", s->scale) &&
             (s->have_ssim ? add_num(o, "ssim_y", s->ssim_y) : cJSON_AddNullToObject(o, "ssim_y") != NULL);
    cJSON *chs = ok ? cJSON_AddObjectToObject(o, "channels") : NULL;
    ok = ok && chs;
    if (ok && s->have_flip) {
        cJSON *fj = gr_flip_to_json(&s->flip, s->scale);
        ok = fj && cJSON_AddItemToObject(o, "flip", fj);
        if (!ok) cJSON_Delete(fj);
    }
    if (ok && s->have_structure) {
        cJSON *sj = cJSON_AddObjectToObject(o, "structure");
        ok = sj && add_num(sj, "score", s->structure_score) && add_num(sj, "bandpass_correlation", s->structure_corr) &&
             add_num(sj, "contrast_log_error", s->structure_contrast_err) &&
             add_num(sj, "log_spectral_distance", s->structure_lsd);
    }
    cJSON *reg = ok ? cJSON_AddObjectToObject(o, "registry") : NULL;
    ok = ok && reg;
    for (int i = 0; ok && i < gr_metric_count(); i++) ok = add_num(reg, gr_metric_at(i)->key, gr_metric_value(s, i));
    for (int c = 0; ok && c < GR_MCH_COUNT; c++) {
        cJSON *cj = channel_json(&s->ch[c], m->have_stderr, s->have_blur);
        ok = cj && cJSON_AddItemToObject(chs, gr_metric_channel_name((gr_metric_channel)c), cj);
        if (!ok) cJSON_Delete(cj);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* The registry's descriptors: what each key of a set's "registry" object means. */
static cJSON *registry_json(void)
{
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    for (int i = 0; ok && i < gr_metric_count(); i++) {
        const gr_metric_desc *d = gr_metric_at(i);
        cJSON *one = cJSON_AddObjectToObject(o, d->key);
        ok = one && cJSON_AddStringToObject(one, "label", d->label) && cJSON_AddStringToObject(one, "doc", d->doc) &&
             cJSON_AddStringToObject(one, "unit", gr_metric_unit_name(d->unit)) &&
             cJSON_AddStringToObject(one, "better", gr_metric_better_name(d->better)) && add_num(one, "best", d->best) &&
             cJSON_AddStringToObject(one, "cost", gr_metric_cost_name(d->cost)) &&
             cJSON_AddBoolToObject(one, "needs_scene", d->needs_scene);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static cJSON *conventions_json(const gr_metrics *m)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON *lw = cJSON_AddObjectToObject(o, "luminance_weights_rec709");
    cJSON *bs = cJSON_AddArrayToObject(o, "blur_sigmas_px");
    int ok = lw && bs && add_num(lw, "R", GR_LUM_R) && add_num(lw, "G", GR_LUM_G) && add_num(lw, "B", GR_LUM_B);
    for (int s = 0; ok && s < GR_METRICS_NSCALES; s++) {
        cJSON *v = cJSON_CreateNumber(gr_metrics_blur_sigmas[s]);
        ok = v && cJSON_AddItemToArray(bs, v);
    }
    ok = ok &&
         cJSON_AddStringToObject(o, "difference", "d = scale * test - ref, per sample; RGB pools the 3 channels") &&
         cJSON_AddStringToObject(o, "rel_mse", "mean(d^2 / (ref^2 + eps)), eps = max(1e-2 * mean(|ref|)^2, 1e-30)") &&
         cJSON_AddStringToObject(o, "psnr_ref_peak", "20 log10(peak_ref / rmse), peak_ref = max ref (1 if none > 0)") &&
         cJSON_AddStringToObject(o, "psnr_idiff", "20 log10(max(1, max ref, max test) / rmse), as OpenImageIO idiff") &&
         cJSON_AddStringToObject(o, "infinite_psnr", "null when rmse = 0") &&
         cJSON_AddStringToObject(o, "max_at", "first maximum in scan order (y, x, channel); y = 0 is the top row") &&
         cJSON_AddStringToObject(o, "blur", "separable Gaussian, truncated at ceil(3 sigma), renormalized over "
                                            "scored pixels (edges, mask)") &&
         cJSON_AddStringToObject(o, "ssim", "Wang et al. 2004 on luminance, 11x11 Gaussian window sigma 1.5 "
                                            "renormalized at edges, K1 0.01, K2 0.03, L = peak_ref of Y") &&
         cJSON_AddStringToObject(o, "significance", "|d| <= z * stderr(ref) + |bias(ref)| is not significant "
                                                    "(bias when REF has bias.* channels); z = Student t975 with "
                                                    "significance_dof degrees of freedom (2 when 0 = unknown); "
                                                    "stderr(Y) = sum of w_c stderr_c (any correlation)") &&
         add_num(o, "significance_dof", m->stderr_dof) && cJSON_AddBoolToObject(o, "reference_bias_channels", m->have_bias) &&
         cJSON_AddStringToObject(o, "stderr_exclusion", "pixels with stderr(Y) / |Y ref| > bound are not scored") &&
         add_num(o, "significance_z", m->stderr_z) && add_num(o, "ssim_K1", GR_SSIM_K1) &&
         add_num(o, "ssim_K2", GR_SSIM_K2) && add_num(o, "ssim_L", m->ssim_L) && add_num(o, "ssim_C1", m->ssim_c1) &&
         add_num(o, "ssim_C2", m->ssim_c2);
    cJSON *reg = ok ? registry_json() : NULL;
    if (reg && !cJSON_AddItemToObject(o, "registry", reg)) cJSON_Delete(reg), reg = NULL;
    ok = ok && reg;
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

cJSON *gr_metrics_to_json(const gr_metrics *m)
{
    if (!m) return NULL;
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    int ok = add_num(o, "width", m->width) && add_num(o, "height", m->height) &&
             add_num(o, "pixels", (double)m->n_pixels) && add_num(o, "scored_pixels", (double)m->n_scored) &&
             add_num(o, "masked_out_pixels", (double)m->n_masked_out) &&
             add_num(o, "stderr_excluded_pixels", (double)m->n_stderr_excluded) &&
             cJSON_AddBoolToObject(o, "reference_has_stderr", m->have_stderr) &&
             add_num(o, "stderr_bound", m->stderr_bound);
    cJSON *conv = ok ? conventions_json(m) : NULL;
    ok = ok && conv && cJSON_AddItemToObject(o, "conventions", conv);
    if (!ok) cJSON_Delete(conv), conv = NULL;
    cJSON *raw = ok ? set_json(m, &m->raw) : NULL;
    ok = ok && raw && cJSON_AddItemToObject(o, "metrics", raw);
    if (!ok) cJSON_Delete(raw);
    if (ok && m->have_fit) {
        cJSON *fit = set_json(m, &m->fit);
        const char *mode = gr_fit_mode_name((gr_fit_mode)m->fit_mode);
        ok = fit && cJSON_AddBoolToObject(fit, "fit_defined", m->fit_defined) &&
             cJSON_AddStringToObject(fit, "fit_mode", mode ? mode : "scale") &&
             cJSON_AddItemToObject(o, "fitted", fit);
        if (!ok) cJSON_Delete(fit);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* One table row: a label and five values. */
static void row(FILE *f, const char *label, const double v[GR_MCH_COUNT], int prec, int fixed)
{
    fprintf(f, "  %-24s", label);
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        if (isinf(v[c])) fprintf(f, " %11s", v[c] > 0 ? "inf" : "-inf");
        else if (fixed) fprintf(f, " %11.*f", prec, v[c]);
        else fprintf(f, " %11.*g", prec, v[c]);
    }
    fputc('\n', f);
}

static void print_set(FILE *f, const gr_metrics *m, const gr_metrics_set *s)
{
    double v[GR_MCH_COUNT];
    fprintf(f, "  %-24s", "");
    for (int c = 0; c < GR_MCH_COUNT; c++) fprintf(f, " %11s", gr_metric_channel_name((gr_metric_channel)c));
    fputc('\n', f);
#define ROW(label, expr, prec, fixed) do { for (int c = 0; c < GR_MCH_COUNT; c++) { const gr_channel_metrics *ch = &s->ch[c]; v[c] = (expr); } row(f, label, v, prec, fixed); } while (0)
    ROW("mean ref", ch->ref_mean, 5, 0);
    ROW("mean test", ch->test_mean, 5, 0);
    ROW("bias (mean t - r)", ch->bias, 4, 0);
    ROW("MAE", ch->mae, 4, 0);
    ROW("RMSE", ch->rmse, 4, 0);
    ROW("rel MSE", ch->rel_mse, 4, 0);
    ROW("  its eps", ch->rel_mse_eps, 3, 0);
    ROW("PSNR dB, peak = ref max", ch->psnr_ref_db, 3, 1);
    ROW("  ref max", ch->peak_ref, 4, 0);
    ROW("PSNR dB, idiff peak", ch->psnr_idiff_db, 3, 1);
    ROW("  idiff peak", ch->peak_idiff, 4, 0);
    ROW("max |t - r|", ch->max_abs_err, 4, 0);
    fprintf(f, "  %-24s", "  at (x, y)");
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        char at[40];
        if (s->ch[c].max_x < 0) snprintf(at, sizeof at, "-");
        else if (s->ch[c].max_c >= 0)
            snprintf(at, sizeof at, "%d,%d,%c", s->ch[c].max_x, s->ch[c].max_y, "RGB"[s->ch[c].max_c]);
        else snprintf(at, sizeof at, "%d,%d", s->ch[c].max_x, s->ch[c].max_y);
        fprintf(f, " %11s", at);
    }
    fputc('\n', f);
    if (s->have_blur) {
        for (int k = 0; k < GR_METRICS_NSCALES; k++) {
            char label[48];
            snprintf(label, sizeof label, "RMSE blurred s=%g px", gr_metrics_blur_sigmas[k]);
            ROW(label, ch->rmse_blur[k], 4, 0);
        }
    }
    if (m->have_stderr) {
        char label[48];
        snprintf(label, sizeof label, "not signif. (<=%.4gse%s) %%", m->stderr_z, m->have_bias ? "+|b|" : "");
        ROW(label, ch->n_samples > 0 ? 100.0 * (double)ch->n_not_significant / (double)ch->n_samples : 0.0, 2, 1);
    }
#undef ROW
    if (s->have_ssim)
        fprintf(f, "  SSIM (luminance) %.6f   (L = %.4g: the reference luminance peak; K1 %g, K2 %g, 11x11 sigma %g)\n",
                s->ssim_y, m->ssim_L, GR_SSIM_K1, GR_SSIM_K2, GR_SSIM_SIGMA);
}

void gr_metrics_print_table(FILE *f, const gr_metrics *m)
{
    if (!f || !m) return;
    fprintf(f, "%d x %d pixels: %lld scored", m->width, m->height, m->n_scored);
    if (m->n_masked_out) fprintf(f, ", %lld masked out", m->n_masked_out);
    if (m->have_stderr) {
        if (isfinite(m->stderr_bound))
            fprintf(f, ", %lld NOT SCORED: reference relative stderr (luminance) > %g", m->n_stderr_excluded,
                    m->stderr_bound);
        else fprintf(f, ", no stderr bound");
    }
    fprintf(f, "\n");
    if (m->n_scored == 0) fprintf(f, "WARNING: no pixel is scored; every error below is 0 by convention\n");
    fprintf(f, "luminance Y = %.4f R + %.4f G + %.4f B (Rec. 709); RGB pools the three channels (as idiff)\n", GR_LUM_R,
            GR_LUM_G, GR_LUM_B);
    print_set(f, m, &m->raw);
    if (m->have_fit) {
        const double *a = m->fit.scale_rgb;
        if (m->fit_defined && m->fit_mode == GR_FIT_RGB)
            fprintf(f, "\nbest per-channel fit: test R x %.6g, G x %.6g, B x %.6g (least squares per channel over "
                    "scored samples; on luminance x %.6g); after fitting:\n", a[0], a[1], a[2], m->fit.scale);
        else if (m->fit_defined)
            fprintf(f, "\nbest scale fit: test x %.6g (least squares over scored RGB samples); after fitting:\n",
                    m->fit.scale);
        else fprintf(f, "\nbest scale fit undefined (the test image is zero over the scored pixels): scale 1\n");
        if (m->fit_defined) print_set(f, m, &m->fit);
    }
}

void gr_metrics_print_summary(FILE *f, const gr_metrics *m, unsigned costs)
{
    if (!f || !m) return;
    const int fit = m->have_fit && m->fit_defined;
    int shown = 0;
    for (int i = 0; i < gr_metric_count(); i++) {
        const gr_metric_desc *d = gr_metric_at(i);
        const double x[2] = {gr_metric_value(&m->raw, i), fit ? gr_metric_value(&m->fit, i) : NAN};
        if (!(costs & (1u << d->cost)) || (isnan(x[0]) && isnan(x[1]))) continue;
        if (!shown++) {
            fprintf(f, "metrics (docs/metrics.md)           %11s", "as given");
            if (fit) fprintf(f, " %11s", m->fit_mode == GR_FIT_RGB ? "x a_R,G,B" : "x scale");
            fprintf(f, "\n");
        }
        char lab[64], v[2][32];
        snprintf(lab, sizeof lab, "%s (%s)", d->label, d->key);
        for (int k = 0; k < 2; k++) {
            if (isnan(x[k])) snprintf(v[k], sizeof v[k], "n/a");
            else snprintf(v[k], sizeof v[k], "%.6g", x[k]);
        }
        fprintf(f, "  %-34s %11s", lab, v[0]);
        if (fit) fprintf(f, " %11s", v[1]);
        if (d->better == GR_METRIC_NEARER) fprintf(f, "   nearer %g is better", d->best);
        else fprintf(f, "   %s is better", gr_metric_better_name(d->better));
        fprintf(f, "%s\n", d->unit == GR_METRIC_RADIANCE ? "; image units" : "");
    }
}

cJSON *gr_flip_to_json(const gr_flip_result *r, double scale)
{
    if (!r) return NULL;
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    int ok = cJSON_AddStringToObject(o, "mode", gr_flip_mode_name(r->mode)) && add_num(o, "pixels_per_degree", r->ppd) &&
             add_num(o, "test_scale", scale) && add_num(o, "pooled_pixels", (double)r->n_pooled) &&
             add_num(o, "mean", r->mean) && add_num(o, "min", r->min) && add_num(o, "max", r->max) &&
             add_num(o, "q1", r->q1) && add_num(o, "median", r->median) && add_num(o, "q3", r->q3);
    if (ok && r->mode == GR_FLIP_HDR) {
        cJSON *e = cJSON_AddObjectToObject(o, "exposures");
        ok = e && cJSON_AddStringToObject(o, "tone_mapper", gr_flip_tonemapper_name(r->tonemapper)) &&
             add_num(e, "start", r->start_exposure) && add_num(e, "stop", r->stop_exposure) &&
             add_num(e, "count", r->n_exposures);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

void gr_flip_print(FILE *f, const char *label, const gr_flip_result *r, double scale)
{
    if (!f || !r) return;
    fprintf(f, "  %-24s mean %.6f  median %.6f  q1 %.6f  q3 %.6f  min %.6f  max %.6f\n", label, r->mean, r->median,
            r->q1, r->q3, r->min, r->max);
    fprintf(f, "  %-24s %s-FLIP, %.4g px/degree, test x %.6g", "", r->mode == GR_FLIP_HDR ? "HDR" : "LDR", r->ppd, scale);
    if (r->mode == GR_FLIP_HDR)
        fprintf(f, ", %s, exposures %.4f .. %.4f (%d)", gr_flip_tonemapper_name(r->tonemapper), r->start_exposure,
                r->stop_exposure, r->n_exposures);
    fprintf(f, ", %lld pixels pooled\n", r->n_pooled);
}

static cJSON *structure_image_json(const gr_structure_image *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON *an = cJSON_AddArrayToObject(o, "annuli");
    int ok = an && add_num(o, "mean_luminance", s->mean_y) && add_num(o, "streak_contrast", s->streak_contrast) &&
             add_num(o, "angular_power", s->angular_power) && add_num(o, "peak_m", s->peak_m) &&
             add_num(o, "usable_annuli", s->n_usable);
    for (int a = 0; ok && a < s->n_annuli; a++) {
        cJSON *one = cJSON_CreateObject();
        ok = one && cJSON_AddItemToArray(an, one);
        cJSON *sp = ok ? cJSON_AddArrayToObject(one, "spectrum") : NULL;
        ok = ok && sp && add_num(one, "r0_px", s->r0[a]) && add_num(one, "r1_px", s->r1[a]) &&
             add_num(one, "arc_deg", s->arc_deg[a]);
        for (int m = 0; ok && m <= s->m_max; m++) {
            cJSON *v = cJSON_CreateNumber(s->spectrum[a][m]);
            ok = v && cJSON_AddItemToArray(sp, v);
        }
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

cJSON *gr_structure_to_json(const gr_structure_compare *c, double vp_x, double vp_y)
{
    if (!c) return NULL;
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON *vp = cJSON_AddObjectToObject(o, "vanishing_point");
    int ok = vp && add_num(vp, "x", vp_x) && add_num(vp, "y", vp_y) &&
             add_num(o, "bandpass_correlation", c->bandpass_corr) && add_num(o, "contrast_ratio", c->contrast_ratio) &&
             add_num(o, "contrast_log_error", c->contrast_log_err) &&
             add_num(o, "log_spectral_distance", c->spectrum_log_dist) && add_num(o, "power_ratio", c->power_ratio) &&
             cJSON_AddStringToObject(o, "spectrum", "P[m] = 2 |sum w f e^(-i m theta)|^2 / (sum w)^2, m cycles per turn; "
                                                    "docs/metrics.md, Beam structure") != NULL;
    cJSON *r = ok ? structure_image_json(&c->ref) : NULL;
    ok = ok && r && cJSON_AddItemToObject(o, "reference", r);
    if (!ok) cJSON_Delete(r), r = NULL;
    cJSON *t = ok ? structure_image_json(&c->test) : NULL;
    ok = ok && t && cJSON_AddItemToObject(o, "test", t);
    if (!ok) {
        if (!r) cJSON_Delete(t);
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

void gr_structure_print(FILE *f, const gr_structure_compare *c, double vp_x, double vp_y)
{
    if (!f || !c) return;
    fprintf(f, "  beam structure around the vanishing point (%.1f, %.1f), luminance over its ring mean:\n", vp_x, vp_y);
    fprintf(f, "  %-24s %11s %11s\n", "", "ref", "test");
    fprintf(f, "  %-24s %11.5f %11.5f   |ln ratio| %.4f\n", "streak contrast", c->ref.streak_contrast,
            c->test.streak_contrast, c->contrast_log_err);
    fprintf(f, "  %-24s %11.5g %11.5g   usable annuli %d / %d\n", "angular power", c->ref.angular_power,
            c->test.angular_power, c->ref.n_usable, c->test.n_usable);
    fprintf(f, "  %-24s %11d %11d\n", "peak m (per 360 deg)", c->ref.peak_m, c->test.peak_m);
    fprintf(f, "  band-pass correlation %.4f   log-spectral distance %.4f\n", c->bandpass_corr, c->spectrum_log_dist);
}
