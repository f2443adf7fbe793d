/* The leaderboard of `godrays run` as rows, one definition for the terminal table (src/cli),
 * index.html and metrics.json (report/report.c): every technique that rendered, the baselines
 * (compare/baseline.h: black, constant, the blurred truth) and every technique that failed, with
 * the verdict (compare/registry.h) and its components after the fit: relative RMSE of Y,
 * structure score, FLIP, band-pass correlation, streak contrast ratio, scale; each technique's
 * equivalent blur and, in words, whether it is no better than the constant image.
 * docs/metrics.md "The verdict", docs/report.md. */
#ifndef GR_LEADERBOARD_H
#define GR_LEADERBOARD_H

#include "compare/baseline.h"
#include "report/report.h"

#define GR_LB_MAX_ROWS (2 * GR_REPORT_MAX_TECHNIQUES + GR_BASELINE_COUNT)

/* The flag in words (terminal, index.html, metrics.json "flag"): the verdict no better than
 * the constant image's, or its first component alone (the radiance error after the fit; the
 * structure score can rank a technique whose light is no closer than a constant above it). */
#define GR_LB_NO_BETTER "no better than a constant image"
#define GR_LB_NO_BETTER_ERROR "no better than a constant image in error after the fit"

typedef enum gr_lb_kind { GR_LB_TECHNIQUE = 0, GR_LB_BASELINE, GR_LB_FAILED } gr_lb_kind;

typedef struct gr_lb_row {
    gr_lb_kind kind;
    int index;                 /* into in->techniques, GR_BASELINE_*, or into in->failed */
    const char *name;          /* the technique's name, or the baseline's key */
    const char *text;          /* description, baseline label, or the failure's one-line reason */
    int rank;                  /* techniques: 1 = the best; 0 for the others */
    const gr_metrics *m;       /* NULL for a failed row */
    /* after the fit (NaN: not computed, or a failed row) */
    double verdict, error_fit, structure, flip, corr, contrast_ratio, scale;
    double eq_blur_px;         /* the equivalent blur (scored rows; NaN without baselines) */
    int eq_where;              /* -1: below the ladder, +1: above, 0: inside */
    int no_better;             /* a technique no better than the constant image: 1 by the verdict,
                                  2 by the error after the fit alone (0: better by both) */
} gr_lb_row;

/* The flag's words for a row (NULL: no flag). */
const char *gr_lb_flag(const gr_lb_row *r);

typedef struct gr_leaderboard {
    int n;                     /* rows: by verdict (techniques and baselines), then the failed */
    gr_lb_row rows[GR_LB_MAX_ROWS];
    int n_flagged;             /* techniques no better than the constant image */
} gr_leaderboard;

/* The rows of in's techniques (ranked by gr_report_rank), in->baselines (if any) and
 * in->failed. flip[k] (may be NULL): technique k's FLIP after the fit where its metrics have
 * none (the report's FLIP map). */
void gr_leaderboard_build(const gr_report_input *in, const double *flip, gr_leaderboard *lb);

/* The row of technique k (NULL: none). */
const gr_lb_row *gr_lb_technique_row(const gr_leaderboard *lb, int k);

/* Whether registry metric i is one of the verdict's own columns (verdict, rel_rmse, structure,
 * flip: shown after the fit); the other leaderboard metrics (gr_metric_desc.leaderboard) get
 * columns raw and after the fit. */
int gr_lb_verdict_column(int i);

/* The equivalent blur of row r as text ("6.2 px", "< 0.5 px", "> 64 px", "n/a"). */
const char *gr_lb_eq_blur_text(const gr_report_input *in, const gr_lb_row *r, char *buf, size_t n);

#endif
