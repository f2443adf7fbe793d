/* The metric registry (registry.h): the built-in descriptors and run-time additions. */
#include "compare/registry.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- the built-ins' extract functions: values of a computed set (docs/metrics.md) ---------- */

static const gr_channel_metrics *lum(const gr_metrics_set *s) { return &s->ch[GR_MCH_Y]; }

static double x_rmse(const gr_metrics_set *s)
{
    return lum(s)->rmse;
}

/* RMSE over |mean reference Y|: the leaderboard's ranking (a technique's scale is arbitrary,
 * so its error is read against the brightness of the truth) */
static double x_rel_rmse(const gr_metrics_set *s)
{
    const gr_channel_metrics *y = lum(s);
    return y->ref_mean != 0 ? y->rmse / fabs(y->ref_mean) : NAN;
}

static double x_relmse(const gr_metrics_set *s)
{
    return lum(s)->rel_mse;
}

static double x_bias(const gr_metrics_set *s)
{
    return lum(s)->bias;
}

static double x_ssim(const gr_metrics_set *s)
{
    return s->have_ssim ? s->ssim_y : NAN;
}

static double x_msrmse(const gr_metrics_set *s)
{
    if (!s->have_blur) return NAN;
    double v = 0.0;
    for (int k = 0; k < GR_METRICS_NSCALES; k++) v += lum(s)->rmse_blur[k];
    return v / GR_METRICS_NSCALES;
}

static double x_flip(const gr_metrics_set *s)
{
    return s->have_flip ? s->flip.mean : NAN;
}

static double x_structure(const gr_metrics_set *s)
{
    return s->have_structure ? s->structure_score : NAN;
}

/* The verdict's weights by registry index (registry.h: GR_VERDICT_OBJECTIVE says the same;
 * unit.verdict checks that both agree with tune's default objective). */
static const double verdict_w[GR_METRIC_N_BUILTIN] = {[GR_METRIC_RMSE] = 1.0, [GR_METRIC_STRUCTURE] = 1.0};

static double x_verdict(const gr_metrics_set *s)
{
    double w[GR_METRIC_MAX];
    gr_metric_verdict_weights(w);
    const double v = gr_metric_weighted(s, w);
    return v < 1e300 ? v : NAN;
}

/* ---- the registry ------------------------------------------------------------------------ */

/* The built-ins first, in the order of the GR_METRIC_* enum; gr_metric_register appends. */
static gr_metric_desc table[GR_METRIC_MAX] = {
    {.key = "rmse", .label = "RMSE Y", .doc = "root mean square error of luminance Y",
     .unit = GR_METRIC_RADIANCE, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_PASS, .extract = x_rmse},
    {.key = "rel_rmse", .label = "rel. RMSE Y", .doc = "RMSE of Y over |mean reference Y| (the verdict's error term)",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_PASS, .leaderboard = 1,
     .extract = x_rel_rmse},
    {.key = "relmse", .label = "rel. MSE Y", .doc = "mean of (t - r)^2 / (r^2 + eps) on Y",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_PASS, .extract = x_relmse},
    {.key = "bias", .label = "bias Y", .doc = "mean of t - r on Y (signed: > 0 too bright)",
     .unit = GR_METRIC_RADIANCE, .better = GR_METRIC_NEARER, .cost = GR_METRIC_COST_PASS, .extract = x_bias},
    {.key = "ssim", .label = "SSIM", .doc = "mean SSIM of luminance, 11x11 Gaussian window (1 = identical)",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_HIGHER, .best = 1.0, .cost = GR_METRIC_COST_SSIM,
     .extract = x_ssim},
    {.key = "msrmse", .label = "multi-scale RMSE Y", .doc = "mean of the RMSEs of Y after Gaussian blurs at 1, 4, 16 px",
     .unit = GR_METRIC_RADIANCE, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_BLUR, .extract = x_msrmse},
    {.key = "flip", .label = "FLIP mean", .doc = "mean FLIP (HDR-FLIP for HDR inputs) over the scored pixels",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_FLIP, .leaderboard = 1,
     .extract = x_flip},
    {.key = "structure", .label = "structure score",
     .doc = "beam structure against the truth's in [0, 1]: band-pass correlation, streak contrast, angular spectrum",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_LOWER, .needs_scene = 1, .cost = GR_METRIC_COST_STRUCTURE,
     .leaderboard = 1, .extract = x_structure},
    {.key = "verdict", .label = "verdict",
     .doc = "(rel. RMSE of Y + structure score) / 2: the leaderboard's rank and tune's default objective",
     .unit = GR_METRIC_UNITLESS, .better = GR_METRIC_LOWER, .needs_scene = 1, .cost = GR_METRIC_COST_STRUCTURE,
     .leaderboard = 1, .extract = x_verdict},
};
static int count = GR_METRIC_N_BUILTIN;

int gr_metric_count(void) { return count; }

const gr_metric_desc *gr_metric_at(int i) { return i >= 0 && i < count ? &table[i] : NULL; }

int gr_metric_find(const char *key)
{
    for (int i = 0; key && i < count; i++)
        if (!strcmp(table[i].key, key)) return i;
    return -1;
}

static int good_key(const char *k)
{
    if (!k || !(k[0] >= 'a' && k[0] <= 'z') || strlen(k) >= GR_METRIC_KEY_MAX) return 0;
    for (const char *c = k; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_')) return 0;
    return 1;
}

gr_status gr_metric_register(const gr_metric_desc *d, gr_error *err)
{
    if (!d) return gr_fail(err, GR_E_INPUT, "metric registry: no descriptor");
    const char *k = d->key ? d->key : "(null)";
    if (!good_key(d->key))
        return gr_fail(err, GR_E_INPUT, "metric '%s': the key must match [a-z][a-z0-9_]* (< %d characters)", k,
                       GR_METRIC_KEY_MAX);
    if (gr_metric_find(d->key) >= 0) return gr_fail(err, GR_E_INPUT, "metric '%s': already registered", k);
    if (!d->label || !d->label[0] || !d->doc || !d->doc[0])
        return gr_fail(err, GR_E_INPUT, "metric '%s': needs a label and a one-line doc", k);
    if (!d->extract == !d->compute)
        return gr_fail(err, GR_E_INPUT, "metric '%s': give exactly one of extract and compute", k);
    if (!d->compute != (d->cost != GR_METRIC_COST_OWN))
        return gr_fail(err, GR_E_INPUT, "metric '%s': a compute function goes with cost 'own' and only with it", k);
    if ((int)d->unit < 0 || d->unit > GR_METRIC_RADIANCE || (int)d->better < 0 || d->better > GR_METRIC_NEARER ||
        (int)d->cost < 0 || d->cost >= GR_METRIC_COST_COUNT || isnan(d->best))
        return gr_fail(err, GR_E_INPUT, "metric '%s': unit, better, cost or best out of range", k);
    if (count >= GR_METRIC_MAX)
        return gr_fail(err, GR_E_INPUT, "metric '%s': the registry is full (%d metrics)", k, GR_METRIC_MAX);
    table[count++] = *d;
    return GR_OK;
}

double gr_metric_value(const gr_metrics_set *s, int i)
{
    const gr_metric_desc *d = gr_metric_at(i);
    if (!d || !s) return NAN;
    if (d->extract) return d->extract(s);
    return i < s->n_extra ? s->extra[i] : NAN;
}

double gr_metric_loss(const gr_metric_desc *d, double v)
{
    if (!d) return NAN;
    switch (d->better) {
    case GR_METRIC_HIGHER: return d->best - v;
    case GR_METRIC_NEARER: return fabs(v - d->best);
    case GR_METRIC_LOWER: break;
    }
    return v - d->best;
}

void gr_metric_verdict_weights(double w[GR_METRIC_MAX])
{
    for (int k = 0; k < GR_METRIC_MAX; k++) w[k] = k < GR_METRIC_N_BUILTIN ? verdict_w[k] : 0.0;
}

double gr_metric_weighted(const gr_metrics_set *s, const double w[GR_METRIC_MAX])
{
    if (!s || !w) return 1e300;
    const double mean_y = s->ch[GR_MCH_Y].ref_mean;
    /* each term made dimensionless (image units over the mean reference Y; relmse, 1 - SSIM,
     * FLIP and the structure score already are), then weighted (docs/tuning.md); the
     * registry's order is the order of the sum */
    double sum = 0.0, wsum = 0.0;
    for (int k = 0; k < count; k++) {
        if (!(w[k] > 0.0)) continue;
        const gr_metric_desc *d = &table[k];
        const double raw = gr_metric_value(s, k);
        if (d->needs_scene && isnan(raw)) continue; /* no vanishing point: the term is left out */
        double v = gr_metric_loss(d, raw);
        if (!isfinite(v)) v = 1e300;
        if (d->unit == GR_METRIC_RADIANCE && mean_y > 0) v /= mean_y;
        sum += w[k] * v, wsum += w[k];
    }
    const double v = wsum > 0 ? sum / wsum : 1e300;
    return isfinite(v) ? v : 1e300;
}

int gr_metric_is_objective(const gr_metric_desc *d) { return d && isfinite(d->best); }

void gr_metric_keys(char *buf, size_t n, const char *sep, int objectives_only)
{
    if (!buf || n == 0) return;
    buf[0] = '\0';
    size_t used = 0;
    for (int i = 0; i < count && used < n; i++) {
        if (objectives_only && !gr_metric_is_objective(&table[i])) continue;
        int w = snprintf(buf + used, n - used, "%s%s", used ? sep : "", table[i].key);
        if (w < 0) break;
        used += (size_t)w;
    }
}

const char *gr_metric_unit_name(gr_metric_unit u) { return u == GR_METRIC_RADIANCE ? "radiance" : "1"; }

const char *gr_metric_better_name(gr_metric_better b)
{
    return b == GR_METRIC_HIGHER ? "higher" : b == GR_METRIC_NEARER ? "nearer best" : "lower";
}

const char *gr_metric_cost_name(gr_metric_cost c)
{
    static const char *const names[GR_METRIC_COST_COUNT] = {"pass", "ssim", "blur", "flip", "structure", "own"};
    return (int)c >= 0 && c < GR_METRIC_COST_COUNT ? names[c] : "?";
}
