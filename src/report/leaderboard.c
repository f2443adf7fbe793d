/* The leaderboard's rows (leaderboard.h). */
#include "report/leaderboard.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compare/registry.h"

static const gr_metrics_set *fit_of(const gr_metrics *m) { return m->have_fit ? &m->fit : &m->raw; }

/* A scored row's numbers, from its metrics after the fit. */
static void fill(gr_lb_row *r, const gr_metrics *m, double flip_fallback)
{
    const gr_metrics_set *s = fit_of(m);
    r->m = m;
    r->verdict = gr_metric_value(s, GR_METRIC_VERDICT);
    r->error_fit = gr_metric_value(s, GR_METRIC_REL_RMSE);
    r->structure = gr_metric_value(s, GR_METRIC_STRUCTURE);
    r->flip = s->have_flip ? gr_metric_value(s, GR_METRIC_FLIP) : flip_fallback;
    r->corr = s->have_structure ? s->structure_corr : NAN;
    r->contrast_ratio = s->have_structure ? s->structure_contrast_ratio : NAN;
    r->scale = m->have_fit && m->fit_defined ? m->fit.scale : 1.0;
    r->eq_blur_px = NAN;
}

/* a before b: a finite verdict before a larger or non-finite one */
static int before(double a, double b) { return isfinite(a) && (!isfinite(b) || a < b); }

void gr_leaderboard_build(const gr_report_input *in, const double *flip, gr_leaderboard *lb)
{
    memset(lb, 0, sizeof *lb);
    int order[GR_REPORT_MAX_TECHNIQUES];
    const int nt = in->n_techniques;
    gr_report_rank(in->techniques, nt, order);
    const gr_baselines *b = in->baselines;
    const double v_const = b ? gr_metric_value(fit_of(&b->m[GR_BASELINE_CONSTANT]), GR_METRIC_VERDICT) : NAN;
    const double e_const = b ? gr_metric_value(fit_of(&b->m[GR_BASELINE_CONSTANT]), GR_METRIC_REL_RMSE) : NAN;
    /* merge the ranked techniques with the baselines sorted by verdict (a tie: the technique first) */
    int bo[GR_BASELINE_COUNT], nb = b ? GR_BASELINE_COUNT : 0;
    for (int i = 0; i < nb; i++) {
        int j = i;
        const double v = gr_metric_value(fit_of(&b->m[i]), GR_METRIC_VERDICT);
        while (j > 0 && before(v, gr_metric_value(fit_of(&b->m[bo[j - 1]]), GR_METRIC_VERDICT))) bo[j] = bo[j - 1], j--;
        bo[j] = i;
    }
    int it = 0, ib = 0;
    while (it < nt || ib < nb) {
        gr_lb_row *r = &lb->rows[lb->n++];
        const int k = it < nt ? order[it] : -1;
        const double vt = k >= 0 ? gr_metric_value(fit_of(in->techniques[k].metrics), GR_METRIC_VERDICT) : NAN;
        const double vb = ib < nb ? gr_metric_value(fit_of(&b->m[bo[ib]]), GR_METRIC_VERDICT) : NAN;
        if (k >= 0 && (ib >= nb || !before(vb, vt))) {
            r->kind = GR_LB_TECHNIQUE, r->index = k, r->rank = ++it;
            r->name = in->techniques[k].name;
            r->text = in->techniques[k].description;
            fill(r, in->techniques[k].metrics, flip ? flip[k] : NAN);
            /* no better than knowing only the truth's mean: by the verdict, or by its radiance
             * error alone (a NaN is not better either) */
            r->no_better = !b ? 0 : !(r->verdict < v_const) ? 1 : !(r->error_fit < e_const) ? 2 : 0;
            lb->n_flagged += r->no_better != 0;
        } else {
            r->kind = GR_LB_BASELINE, r->index = bo[ib++];
            r->name = gr_baseline_key(r->index);
            r->text = gr_baseline_label(r->index);
            fill(r, &b->m[r->index], NAN);
        }
        if (b) r->eq_blur_px = gr_equivalent_blur(b, r->verdict, &r->eq_where);
    }
    for (int f = 0; f < in->n_failed && lb->n < GR_LB_MAX_ROWS; f++) {
        gr_lb_row *r = &lb->rows[lb->n++];
        r->kind = GR_LB_FAILED, r->index = f;
        r->name = in->failed[f].name;
        r->text = in->failed[f].reason;
        r->verdict = r->error_fit = r->structure = r->flip = r->corr = r->contrast_ratio = r->scale = NAN;
        r->eq_blur_px = NAN;
    }
}

const char *gr_lb_flag(const gr_lb_row *r)
{
    return !r || !r->no_better ? NULL : r->no_better == 1 ? GR_LB_NO_BETTER : GR_LB_NO_BETTER_ERROR;
}

const char *gr_lb_eq_blur_text(const gr_report_input *in, const gr_lb_row *r, char *buf, size_t n)
{
    if (r->kind == GR_LB_FAILED || !in->baselines) {
        snprintf(buf, n, "n/a");
        return buf;
    }
    return gr_equivalent_blur_text(in->baselines, r->verdict, buf, n);
}

const gr_lb_row *gr_lb_technique_row(const gr_leaderboard *lb, int k)
{
    for (int i = 0; lb && i < lb->n; i++)
        if (lb->rows[i].kind == GR_LB_TECHNIQUE && lb->rows[i].index == k) return &lb->rows[i];
    return NULL;
}

int gr_lb_verdict_column(int i)
{
    return i == GR_METRIC_VERDICT || i == GR_METRIC_REL_RMSE || i == GR_METRIC_STRUCTURE || i == GR_METRIC_FLIP;
}
