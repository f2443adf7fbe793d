/* How many renders a sweep, a tune or a pareto run is about to start, and how long they will
 * take (docs/tuning.md, "Budgets"): the count is known from the options before the ground
 * truths; above GR_TUNE_BUDGET_RENDERS the command needs --yes (two 1000-value axes are a
 * million renders, days on llvmpipe); once the first renders are timed, one line estimates
 * the whole. The commands print; nothing here does. */
#ifndef GR_TUNE_BUDGET_H
#define GR_TUNE_BUDGET_H

#include <stddef.h>

#include "common/status.h"
#include "realtime/technique.h"
#include "tune/optimize.h"
#include "tune/session.h"

/* Technique renders a command may start without --yes (docs/tuning.md). */
#define GR_TUNE_BUDGET_RENDERS 20000

typedef struct gr_tune_budget {
    const char *label;      /* "godrays sweep": starts each line */
    const char *unit;       /* what is counted: "grid points", "evaluations", "renders" */
    long long planned;      /* how many */
    int renders_each;       /* technique renders per unit (the cases) */
    double t0;              /* when the first started (gr_tune_budget_start) */
    int told;               /* the estimate was given */
} gr_tune_budget;

/* The cases of a session: frames (at least 1) x (1 + extra views). */
int gr_tune_budget_cases(const gr_tune_session_options *so);
/* An upper bound of the evaluations gr_opt_minimize makes with o for n_params parameters:
 * the first stage, the screening runs, every start's budget (CMA-ES: 4x) and the polish. */
long long gr_tune_budget_search(const gr_opt_options *o, int n_params);
/* The renders of pareto's ladders: per technique, each level (--quick: the quick ones; one at
 * the scene's settings without a ladder) rendered 1 + repeat times (a warm-up). */
long long gr_tune_budget_ladders(const gr_technique_class *const *techs, int n_techs, int quick, long repeat);

/* Fills b (planned units of renders_each renders each). GR_E_USAGE, naming the count, the
 * threshold and --yes, when planned x renders_each > GR_TUNE_BUDGET_RENDERS and yes is 0. */
gr_status gr_tune_budget_init(gr_tune_budget *b, const char *label, const char *unit, long long planned,
                              int renders_each, int yes, gr_error *err);
/* The line announcing the count ("godrays sweep: 256 grid points x 2 cases = 512 renders
 * planned"). */
void gr_tune_budget_plan_line(const gr_tune_budget *b, char *buf, size_t n);
/* Starts the clock at the first unit. */
void gr_tune_budget_start(gr_tune_budget *b);
/* After `done` units: 1 and the estimate line ("godrays sweep: the first 1 of 1000000 grid
 * points took 12.3 ms: about 3.42 h for all") the first time done >= 1; 0 otherwise. */
int gr_tune_budget_eta(gr_tune_budget *b, long long done, char *buf, size_t n);
/* s seconds as "850 ms", "42.1 s", "12.5 min", "3.42 h" or "2.1 days" (%.3g: never hundreds
 * of digits, whatever s). */
void gr_tune_format_duration(double s, char *buf, size_t n);

#endif
