/* Render budgets of sweep, tune and pareto (budget.h). */
#include "tune/budget.h"

#include <math.h>
#include <stdio.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int gr_tune_budget_cases(const gr_tune_session_options *so)
{
    return (so->n_times > 0 ? so->n_times : 1) * (1 + so->n_views);
}

long long gr_tune_budget_search(const gr_opt_options *o, int n_params)
{
    /* the defaults gr_opt_minimize applies to zero fields (optimize.h) */
    const long long per_start = o->max_evals > 0 ? o->max_evals : 60 + 40 * n_params;
    const long long starts = o->n_starts > 0 ? o->n_starts : 4;
    const long long screen_evals = o->screen_evals > 0 ? o->screen_evals : 20 + 10 * n_params;
    long long total = (o->coarse > 0 ? o->coarse : 0) + (o->polish > 0 ? o->polish : 0);
    if (o->method == GR_OPT_CMAES) return total + starts * 4 * per_start;
    if (o->coarse > 0 && o->screen > starts) total += o->screen * screen_evals;
    return total + starts * per_start;
}

long long gr_tune_budget_ladders(const gr_technique_class *const *techs, int n_techs, int quick, long repeat)
{
    long long levels = 0;
    for (int k = 0; k < n_techs; k++) {
        const gr_technique_class *c = techs[k];
        if (c->n_ladder <= 0) levels++;
        for (int l = 0; l < c->n_ladder; l++) levels += !quick || c->ladder[l].quick;
    }
    return levels * (1 + repeat);
}

/* " x 3 cases = 768 renders" when a unit is several renders, else "" */
static void cases_part(const gr_tune_budget *b, char *buf, size_t n)
{
    buf[0] = '\0';
    if (b->renders_each > 1)
        snprintf(buf, n, " x %d cases = %lld renders", b->renders_each, b->planned * (long long)b->renders_each);
}

gr_status gr_tune_budget_init(gr_tune_budget *b, const char *label, const char *unit, long long planned,
                              int renders_each, int yes, gr_error *err)
{
    *b = (gr_tune_budget){label, unit, planned, renders_each > 0 ? renders_each : 1, 0.0, 0};
    char part[96];
    cases_part(b, part, sizeof part);
    if (planned * (long long)b->renders_each > GR_TUNE_BUDGET_RENDERS && !yes)
        return gr_fail(err, GR_E_USAGE,
                       "%lld %s%s: over the %d renders that start without --yes (docs/tuning.md \"Budgets\"): add "
                       "--yes to start them, or plan fewer", planned, unit, part, GR_TUNE_BUDGET_RENDERS);
    return GR_OK;
}

void gr_tune_budget_plan_line(const gr_tune_budget *b, char *buf, size_t n)
{
    char part[96];
    cases_part(b, part, sizeof part);
    snprintf(buf, n, "%s: %lld %s%s planned", b->label, b->planned, b->unit, part);
}

void gr_tune_budget_start(gr_tune_budget *b)
{
    b->t0 = now_s();
}

int gr_tune_budget_eta(gr_tune_budget *b, long long done, char *buf, size_t n)
{
    if (b->told || done < 1) return 0;
    b->told = 1;
    const double took = now_s() - b->t0;
    char first[32], all[32];
    gr_tune_format_duration(took, first, sizeof first);
    gr_tune_format_duration(took / (double)done * (double)b->planned, all, sizeof all);
    snprintf(buf, n, "%s: the first %lld of %lld %s took %s: about %s for all", b->label, done, b->planned, b->unit,
             first, all);
    return 1;
}

void gr_tune_format_duration(double s, char *buf, size_t n)
{
    if (!isfinite(s) || s < 0) snprintf(buf, n, "?");
    else if (s < 1.0) snprintf(buf, n, "%.3g ms", 1e3 * s);
    else if (s < 120.0) snprintf(buf, n, "%.3g s", s);
    else if (s < 7200.0) snprintf(buf, n, "%.3g min", s / 60.0);
    else if (s < 172800.0) snprintf(buf, n, "%.3g h", s / 3600.0);
    else snprintf(buf, n, "%.3g days", s / 86400.0);
}
