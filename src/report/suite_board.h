/* The leaderboard over a view suite (`godrays run --suite`, docs/report.md "Suites"): every
 * technique's verdict (compare/registry.h, after the fit) on every case of the suite, and its
 * aggregate: the mean over the cases, the worst case, the means over the train and the test
 * cases. One definition for the terminal (src/cli), DIR/index.html (a case x technique table
 * with thumbnails linking each case's own report in DIR/cases/CASE/) and DIR/metrics.json.
 * Library code: writes files, prints nothing. */
#ifndef GR_SUITE_BOARD_H
#define GR_SUITE_BOARD_H

#include <stddef.h>
#include "common/status.h"
#include "suite/suite.h"

#define GR_SUITE_BOARD_MAX_TECHNIQUES 32

typedef struct gr_suite_board_input {
    const gr_suite *suite;          /* the cases, in order */
    int n_techniques;               /* 1..GR_SUITE_BOARD_MAX_TECHNIQUES */
    const char *const *techniques;  /* their names */
    /* per case c and technique k, at [c * n_techniques + k]: */
    const double *verdict;          /* the verdict after the fit; NaN: the technique failed there */
    const double *error_fit;        /* its first component (relative RMSE of Y after the fit; may be NULL) */
    const double *structure;        /* its second (the structure score; may be NULL) */
    const double *gpu_ms;           /* the render's GPU time (may be NULL; NaN: unknown) */
    const char *const *reasons;     /* a failed cell's one-line reason (may be NULL) */
    const double *constant;         /* per case: the constant-image baseline's verdict (may be NULL) */
    const char *command_line;       /* NULL: unknown */
    double seconds;                 /* the whole run (< 0: unknown) */
} gr_suite_board_input;

/* A technique's aggregate over the cases it scored on. */
typedef struct gr_suite_aggregate {
    double mean;                    /* mean verdict over the scored cases (NaN: none scored) */
    double worst;                   /* the largest verdict */
    int worst_case;                 /* its case (-1: none) */
    double mean_train, mean_test;   /* means over the scored train / test cases (NaN: none) */
    int n_scored, n_failed;         /* cases scored; cases where it failed */
} gr_suite_aggregate;

/* agg[k] for every technique, and order: the techniques by mean verdict, lower first; those
 * that failed in some case after those that scored everywhere; ties in input order. */
void gr_suite_board_aggregate(const gr_suite_board_input *in, gr_suite_aggregate *agg, int *order);

/* DIR/index.html and DIR/metrics.json (each atomically); the case reports are DIR/cases/CASE/
 * (written before, by the caller, with gr_report_write). GR_E_IO naming the file, GR_E_NOMEM. */
gr_status gr_suite_board_write(const char *dir, const gr_suite_board_input *in, gr_error *err);

#endif
