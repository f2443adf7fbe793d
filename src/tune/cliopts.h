/* Command-line options shared by `godrays sweep` and `godrays tune` (frames, views, metric,
 * scale fit, cache), parsed in one place so that both commands accept and check them the same
 * way. The options every command shares (-o, --set, --size, --gl-platform) are read by the
 * command line's own src/cli/args.h; gr_tune_cli_help() lists both. */
#ifndef GR_TUNE_CLIOPTS_H
#define GR_TUNE_CLIOPTS_H

#include "common/status.h"
#include "tune/objective.h"
#include "tune/optimize.h"
#include "tune/session.h"

typedef struct gr_tune_cli {
    gr_tune_session_options so;   /* sets, n_sets, gl_platform, scene_path: the caller's */
    gr_tune_metric metric;
    double weights[GR_METRIC_MAX]; /* --objective (metric GR_TM_WEIGHTED) */
    int fit;                      /* a gr_fit_mode (compare/fit.h); -1: auto (scale, unless the
                                     gain_key setting is a parameter: none; rgb with
                                     rgb_per_channel) */
    int rgb_per_channel;          /* --rgb-per-channel: fold the per-channel fit into the gain */
    int normalize;                /* --normalize */
    int quiet;
    int yes;                      /* --yes: more renders than GR_TUNE_BUDGET_RENDERS (tune/budget.h) */
    double fps;
    const char *frames_spec;      /* parsed in gr_tune_cli_finish (needs --fps) */
    const char *times_spec;
    const char *technique_name;   /* --technique (NULL: from the parameters) */
} gr_tune_cli;

/* Defaults: metric rmse, fit auto, fps 30, cache on, progress on. */
void gr_tune_cli_init(gr_tune_cli *c);

/* Tries argv[*i] as a shared option; consumes its value (advancing *i). Returns 1 if it was
 * one, 0 if not, -1 with err (GR_E_USAGE naming the flag) for a bad value. */
int gr_tune_cli_option(gr_tune_cli *c, int argc, char **argv, int *i, gr_error *err);

/* After all arguments: the frames/times lists; progress follows quiet. */
gr_status gr_tune_cli_finish(gr_tune_cli *c, gr_error *err);

/* After gr_tune_cli_finish and the caller's own checks: the technique (--technique, else the
 * one params name, else the first registered; GR_E_USAGE if a parameter belongs to another),
 * the fit default (scale, unless its gain_key is among params; rgb with --rgb-per-channel, which
 * is GR_E_USAGE naming the technique when its gain_key is not an RGB setting, or with another
 * --fit), gr_tune_session_open with c->so (s is the caller's; close
 * it even after a failure), and p set up from the session, params, metric, fit and
 * normalization, and initialized (gr_tune_problem_free it). */
gr_status gr_tune_cli_open(gr_tune_cli *c, const gr_tune_param *params, int n_params, gr_tune_session *s,
                           gr_tune_problem *p, gr_error *err);

/* `godrays tune`'s default search for n_params parameters from x0 (docs/tuning.md "The
 * optimizer"): a first stage of 16 x n_params sample points (seed 0); 16 candidates (x0 and the
 * sample's best separated points) screened by Nelder-Mead runs of 20 + 10 n evaluations; the
 * 4 best (x0's always) continued for up to 60 + 40 n evaluations each; a polish of as many. */
void gr_tune_search_defaults(gr_opt_options *o, int n_params, const double *x0);

/* The help text of the shared options (--metric lists the metric registry's keys). */
const char *gr_tune_cli_help(void);

#endif
