/* Tuning over a view suite (`godrays pareto --suite SUITE --tune`, docs/tuning.md "Tuned
 * fronts and budgets"): for one technique and one point of its cost ladder
 * (gr_technique_class.ladder), its look settings (its tune_keys) are tuned on the suite's
 * train cases with the default objective (the verdict, tune/objective.h) by the global search
 * of tune/optimize.h, then scored on its test cases; each point is timed warm at a timing size
 * (realtime/timing.h); a budget table picks, for each frame budget, the point with the lowest
 * TRAIN error among those that fit (the test error is never used to choose: it is what the
 * table reports, so the choice does not peek at the views it is judged on).
 *
 * Continuation along the ladder (docs/tuning.md "Continuation along the ladder"): the full global
 * search runs at one anchor point per technique (the middle of its ladder); every other point
 * gets a short local search (Nelder-Mead with a small simplex and its restart, o->local_evals)
 * started from the best, on the train cases, of the untuned point, the neighbouring point's
 * tuned values and the anchor's (gr_st_options.from). The look settings that fit a ladder point
 * move little between neighbouring points (they change cost, not the look), so the local search
 * starts in the basin the anchor's global search found, at a tenth of its evaluations.
 *
 * Search budgets (docs/tuning.md "Search budgets"; gr_st_options.work_ref): a point whose
 * render work (cost counters, gr_technique_stats_work) is r times the ladder's cheapest point's
 * gets 1/r of its search's evaluations: the anchor's global search becomes a local one from the
 * untuned point when it does not fit, and a point whose budget is below the least local search
 * takes the best on the train cases of its untuned settings and its candidates (carried). The
 * budget comes from counted work, not from measured time, so the result stays deterministic.
 *
 * Settings derived from the scene (a descriptor's scene_source: the camera position, the
 * medium's extinction) and not tuned are left unresolved, so that each case resolves them from
 * its own scene; a tuned RGB setting (extinction) is tuned as a scale on case 0's value, and
 * the preset states the absolute value found. Deterministic for a seed. */
#ifndef GR_TUNE_SUITETUNE_H
#define GR_TUNE_SUITETUNE_H

#include "common/status.h"
#include "compare/baseline.h"
#include "image/image.h"
#include "realtime/technique.h"
#include "realtime/timing.h"
#include "scene/scene.h"
#include "suite/suite.h"
#include "tune/objective.h"

/* One case: a scene (camera size = the error size, the same for all) and its ground truth. */
typedef struct gr_st_case {
    const gr_scene *scene;
    const gr_image *truth;
    gr_split split;
} gr_st_case;

typedef struct gr_st_options {
    const char *params;       /* "NAME.KEY,..." to tune (NULL: the class's tune_keys) */
    int max_evals;            /* per local search (0: the search's default, 60 + 40 n) */
    int n_starts;             /* 0: 2 */
    int coarse;               /* first-stage sample points (0: 8 per parameter) */
    unsigned long long seed;
    /* continuation: n_from > 0 replaces the global search by a local one (local_evals for the
     * simplex and as many for the polish; 0: gr_st_local_evals) from the best on the train
     * cases of from[0..n_from) and the untuned point */
    int n_from;
    double from[2][GR_TUNE_MAX_PARAMS];
    int local_evals;
    /* > 0: the search budget (see above): a point whose untuned train evaluation did more work
     * than this gets work_ref / its work of its search's evaluations (0: no budget) */
    double work_ref;
} gr_st_options;

/* How a tuned point was searched (gr_st_point.local). */
enum { GR_ST_GLOBAL = 0, GR_ST_LOCAL = 1, GR_ST_CARRIED = 2 };
const char *gr_st_search_name(int local); /* "global", "local", "carried" */

/* The continuation's default budget for n tuned settings: 20 + 12 n evaluations for the simplex
 * and as many for the polish (44 each for 2 settings: the least that recovered the
 * identifiability check's settings within 2 % at every ladder point; 16-30 did not). */
int gr_st_local_evals(int n);

typedef struct gr_st_point {
    const gr_technique_class *cls;
    int level;                    /* index into cls->ladder; -1: the scene's settings */
    char ladder[192];             /* the level's settings text ("" for the scene's) */
    int tuned;                    /* 0: the ladder point as it is; 1: its look tuned */
    gr_section_store settings;    /* every setting as rendered (unresolved scene-derived ones NaN) */
    int n_params;
    char keys[GR_TUNE_MAX_PARAMS][64];
    double x[GR_TUNE_MAX_PARAMS]; /* the tuned parameters' values (RGB: the scale) */
    double train_error, test_error; /* mean verdict after the scale fit over the split's cases */
    int evals;
    int local;                    /* GR_ST_GLOBAL, GR_ST_LOCAL (the continuation's local search, or
                                     the anchor's under a budget) or GR_ST_CARRIED (the budget
                                     allowed only the candidates: the best of them on train) */
    int budget;                   /* evaluations the search budget allowed (0: unbounded) */
    double work;                  /* untuned: the work of one train evaluation (the sum of
                                     gr_technique_stats_work over the train cases) */
    gr_timing timing;             /* at the timing size (timed = 1) */
    int timed;
    int on_front;                 /* on the front of (cost, test error) of its technique and kind */
} gr_st_point;

/* Scores settings s on the cases of one split: *mean verdict after the scale fit; renders into
 * a scratch frame. GR_E_INPUT when the split has no case. */
gr_status gr_st_score(gr_technique *r, const gr_st_case *cases, int n_cases, gr_split split, const void *s,
                      double *mean, gr_error *err);

/* The ladder level (-1: none) of r's class: the untuned point (its settings as the level sets
 * them, scored on train and test) and the tuned one (tuned on train, scored on test). Either
 * output may be NULL (the untuned point is always scored: the search starts there). */
gr_status gr_st_tune_level(gr_technique *r, const gr_st_case *cases, int n_cases, int level, const gr_st_options *o,
                           gr_st_point *untuned, gr_st_point *tuned, gr_error *err);

/* The settings of r's class at ladder level (-1: none) with the tuned parameters (o->params, or
 * the tune_keys) at x, as gr_st_tune_level renders them (the identifiability check's truths). */
gr_status gr_st_level_settings(const gr_technique_class *cls, const gr_scene *scene0, int level, const gr_st_options *o,
                               const double *x, void *out, gr_error *err);

/* The continuation's order over n ladder points (positions 0..n-1) from the anchor n / 2:
 * the anchor, the points above it upwards, then the points below it downwards; prev[k] is the
 * position of order[k]'s neighbour tuned before it (-1 for the anchor). */
int gr_st_continuation_order(int n, int *order, int *prev);

/* o with from[] set to the tuned values of the anchor and of the neighbour (either NULL or
 * untuned: left out; both the same point: once) and n_from to their count. */
void gr_st_continue_from(gr_st_options *o, const gr_st_point *anchor, const gr_st_point *neighbour);

/* Times pt's settings warm (1 warm-up, then up to repeat renders, fewer once the timed renders
 * took cap_s seconds: gr_timing_measure_capped) on scene (a case at the timing size). */
gr_status gr_st_time_point(gr_technique *r, const gr_scene *scene, int repeat, double cap_s, gr_st_point *pt,
                           gr_error *err);

/* The points of each (technique, tuned) family on the front of (timing cost, test error). */
void gr_st_mark_fronts(gr_st_point *pts, int n);

/* For each budget (ms), the index of the timed point whose cost fits and whose TRAIN error is
 * lowest (ties: the cheaper one); -1 when none fits. */
void gr_st_pick(const gr_st_point *pts, int n, const double *budgets_ms, int n_budgets, int *pick);

/* The blur ladder of the split's cases, its verdicts averaged over them (for
 * gr_equivalent_blur of a mean verdict over the same cases). */
gr_status gr_st_baselines(const gr_st_case *cases, int n_cases, gr_split split, gr_baselines *out, gr_error *err);

/* "K=0.91 extinction=x1.2 g=0.77" (the tuned values) or the ladder text, into buf. */
void gr_st_point_label(const gr_st_point *pt, char *buf, size_t n);

/* "0.5,1,2,4" -> budgets (ms, each > 0 and finite, at most max). GR_E_USAGE naming flag. */
gr_status gr_st_parse_budgets(const char *flag, const char *s, double *budgets, int max, int *n, gr_error *err);

#endif
