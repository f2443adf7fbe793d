/* Speed against error (`godrays pareto`): points (time, error) of the ground truth and of every
 * real-time technique (one family each), their Pareto fronts (the points no other point of the
 * same family beats in both time and error), the CSV and the log-log plot with every family
 * and its front, one colour per family. docs/tuning.md. */
#ifndef GR_TUNE_PARETO_H
#define GR_TUNE_PARETO_H

#include "common/status.h"

enum { GR_PARETO_REFERENCE = 0 }; /* family 0; a technique's points: family 1, 2, ... */

#define GR_PARETO_MAX_FAMILIES 33 /* the ground truth + GR_TECH_MAX techniques */

typedef struct gr_pareto_point {
    int family;              /* GR_PARETO_REFERENCE, or 1 + the technique's position in the run */
    char family_name[32];    /* "reference" or the technique's name (CSV, legend) */
    char label[96];          /* e.g. "N=11 scale=0.5 rgba8" or "q3 (default)" */
    char settings[256];      /* the settings as KEY=VALUE;... for the CSV */
    double time_s;           /* wall time per frame (reference: whole render) */
    double gpu_s;            /* techniques: summed GL pass timers per frame; -1 unknown */
    double cost_s;           /* what the fronts and the plot rank by: time_s, except for the
                                techniques on a hardware GPU, where it is gpu_s (their wall time
                                there is mostly the harness's synchronous float readback) */
    double error;            /* the verdict (compare/registry.h) against the high-quality reference */
    int on_front;            /* set by gr_pareto_mark_fronts */
    int colour;              /* the chart's colour slot, 1..9 (0: from the family) */
    int light;               /* 1: a lighter shade of it (e.g. untuned beside tuned) */
} gr_pareto_point;

/* on_front[i] = 1 iff no j with cost[j] <= cost[i] and err[j] <= err[i], one strictly
 * (non-finite points are never on the front and never dominate). O(n^2). */
void gr_pareto_front(int n, const double *cost, const double *err, int *on_front);

/* Marks each point's on_front within its own family, by (cost_s, error). */
void gr_pareto_mark_fronts(gr_pareto_point *pts, int n);

/* pareto.csv: family,label,settings,time_s,gpu_s,cost_s,error,on_front. */
gr_status gr_pareto_write_csv(const char *path, const gr_pareto_point *pts, int n, gr_error *err);

/* The plot (PLplot, log-log): every family as markers of its own colour (legend: its name),
 * its front as a dashed line. time_label names the techniques' timing ("llvmpipe wall time" /
 * "GPU time"). *drawn = 0 without PLplot. */
gr_status gr_pareto_write_plot(const char *path, const gr_pareto_point *pts, int n, const char *title,
                               const char *time_label, int *drawn, gr_error *err);

#endif
