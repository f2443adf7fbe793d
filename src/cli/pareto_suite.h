/* `godrays pareto --suite SUITE [--tune] [--budgets LIST] [--timing-size WxH]`: the tuned fronts
 * and the budget table over a view suite (tune/suitetune.h; docs/tuning.md "Tuned fronts and
 * budgets"). Part of cmd_pareto, in its own file to keep each under its size. */
#ifndef GR_CLI_PARETO_SUITE_H
#define GR_CLI_PARETO_SUITE_H

#include "cli/args.h"
#include "realtime/technique.h"

#define GR_PS_MAX_BUDGETS 16

typedef struct gr_ps_opts {
    const char *suite_path, *outopt;
    int tune, quick, quiet, use_cache;
    int repeat;          /* renders timed per point (0: 3 on a CPU rasterizer, 5 on a GPU) */
    double timing_cap_s; /* fewer timed renders once they took this long (0: no cap) */
    int timing_w, timing_h;
    int n_budgets;
    double budgets_ms[GR_PS_MAX_BUDGETS];
    int max_evals;       /* the global search's, per local search (0: its default) */
    int tune_full;       /* the global search at every ladder point (else only at the anchor) */
    int local_evals;     /* the continuation's local search (0: gr_st_local_evals) */
    int no_search_budget;/* every point its whole search (tune/suitetune.h "Search budgets");
                            --tune-full implies it */
    unsigned long long seed;
    gr_gl_platform platform;
    const gr_technique_class *const *techs;
    int n_techs;
} gr_ps_opts;

/* Everything after the command line (the suite loaded with args' overrides); an exit code. */
int gr_pareto_suite(gr_args *args, const gr_ps_opts *o);

#endif
