/* Suite tuning (tune/suitetune.h), on cases built in memory (issue 27's checks).
 *  - Identifiability: the "truths" of every case are the shafts' own renders at known look
 *    settings (K and the extinction scale, moving with the ladder level) at a ladder point; the
 *    tuned point must recover them within 2 % at every ladder point checked (the oracle is the
 *    known setting), tuned as `pareto --suite --tune` does: the global search at the anchor,
 *    the continuation's short local search from its neighbour elsewhere.
 *  - Generalization is measured: truths rendered with a K that differs per case (0.8 .. 1.2:
 *    no one setting fits all views); tuning on one case alone fits it (train error ~ 0) and
 *    does worse on the test cases than on its train case, and tuning on the suite's train
 *    cases has the lower test error.
 *  - The budget pick chooses by train error among the points that fit, never by test error.
 *  - Search budgets: a point's work is the cost counters' work of its train renders (summed
 *    here render by render); half the reference work halves the evaluations (the anchor's
 *    global search becomes a local one within the budget); a budget below a local search
 *    evaluates only the candidates and keeps the best of them (never worse than untuned).
 * Every ladder point of the shafts (rgba8 and rgba16f targets; label slow); reduced
 * (GODRAYS_TEST_REDUCED): two ladder points and a shorter global search, 96 x 54. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "tune/suitetune.h"
#include "tune_test.h"

#define W 96
#define H 54
enum { NCASE = 5 };

/* The default scene turned to (yaw, pitch) at water time t: one view of the suite. */
static gr_scene *view(double yaw, double pitch, double t)
{
    gr_scene *base = tune_test_default_scene(W, H, NULL, 0), *s = malloc(sizeof *s);
    gr_error err;
    CHECK(s != NULL);
    gr_tune_view v = {yaw, pitch};
    CHECK_OK(gr_tune_make_case(base, t, yaw == 0 && pitch == 0 ? NULL : &v, s, &err), err);
    free(base);
    return s;
}

/* The look the truths of ladder level l are rendered with: K and the extinction scale move
 * with the level (3 % and -2 % of their anchor values per level from the anchor a), so that
 * the continuation's local search must move from its neighbour's optimum to find them. */
static void truth_look(int l, int a, double *xt)
{
    xt[0] = 0.9 * (1.0 + 0.03 * (l - a));
    xt[1] = 1.3 * (1.0 - 0.02 * (l - a));
}

/* Identifiability with the continuation of `pareto --suite --tune`: the levels lv[0..n) in
 * the continuation's order (tune/suitetune.h), the global search at the anchor, the local
 * search from the neighbour's and the anchor's tuned values elsewhere; each level's truths are
 * its own renders at truth_look; every level recovers them within 2 %. */
static void identify(gr_technique *r, gr_scene **sc, gr_image **truth, const int *lv, int n, int reduced)
{
    gr_error err;
    int order[64], prev[64];
    const int a = gr_st_continuation_order(n, order, prev);
    gr_st_point *tuned = calloc((size_t)n, sizeof *tuned);
    CHECK(tuned != NULL);
    for (int k = 0; k < n; k++) {
        const int i = order[k], level = lv[i];
        gr_st_options o = {.params = "shafts.K,shafts.extinction", .max_evals = reduced ? 40 : 60,
                           .n_starts = reduced ? 1 : 2, .seed = 1};
        if (prev[k] >= 0) gr_st_continue_from(&o, &tuned[a], &tuned[order[prev[k]]]);
        double xt[2];
        truth_look(level, lv[a], xt);
        gr_st_case cases[NCASE];
        for (int c = 0; c < NCASE; c++) {
            gr_section_store s;
            CHECK_OK(gr_st_level_settings(&gr_shafts_class, sc[0], level, &o, xt, s.bytes, &err), err);
            CHECK_OK(gr_technique_render(r, sc[c], s.bytes, truth[c], NULL, &err), err);
            cases[c] = (gr_st_case){sc[c], truth[c], c < 3 ? GR_SPLIT_TRAIN : GR_SPLIT_TEST};
        }
        gr_st_point u, *t = &tuned[i];
        CHECK_OK(gr_st_tune_level(r, cases, NCASE, level, &o, &u, t, &err), err);
        printf("level %d (%s), %s search from %d start(s), %d evals: K %.4f (true %.4f), extinction x%.4f (true %.4f); "
               "train %.3g test %.3g (untuned %.3g / %.3g)\n", level, t->ladder, t->local ? "local" : "global",
               t->local ? 1 + o.n_from : 0, t->evals, t->x[0], xt[0], t->x[1], xt[1], t->train_error, t->test_error,
               u.train_error, u.test_error);
        CHECK(t->local == (prev[k] >= 0));
        CHECK_REL(t->x[0], xt[0], 0.02);
        CHECK_REL(t->x[1], xt[1], 0.02);
        CHECK(t->test_error < u.test_error);
        if (t->local) CHECK(t->evals <= 2 + 2 * gr_st_local_evals(2) + 6); /* short: candidates, simplex, polish */
    }
    free(tuned);
}

static void generalization(gr_technique *r, gr_scene **sc, gr_image **truth)
{
    gr_error err;
    const gr_st_options o = {.params = "shafts.K", .max_evals = 24, .n_starts = 1, .coarse = 6, .seed = 3};
    /* per case, the K its truth was rendered with: train 0.8, 1.0, 1.2; test 0.95, 1.05 */
    const double k_case[NCASE] = {0.8, 1.0, 1.2, 0.95, 1.05};
    const int level = 9; /* N=11, half-size rgba16f target */
    gr_st_case cases[NCASE], one[NCASE];
    for (int i = 0; i < NCASE; i++) {
        gr_section_store s;
        CHECK_OK(gr_st_level_settings(&gr_shafts_class, sc[0], level, &o, &k_case[i], s.bytes, &err), err);
        CHECK_OK(gr_technique_render(r, sc[i], s.bytes, truth[i], NULL, &err), err);
        cases[i] = (gr_st_case){sc[i], truth[i], i < 3 ? GR_SPLIT_TRAIN : GR_SPLIT_TEST};
        one[i] = cases[i];
        if (i == 1 || i == 2) one[i].split = 2; /* neither split: tuned on case 0 alone */
    }
    gr_st_point suite, single;
    CHECK_OK(gr_st_tune_level(r, cases, NCASE, level, &o, NULL, &suite, &err), err);
    CHECK_OK(gr_st_tune_level(r, one, NCASE, level, &o, NULL, &single, &err), err);
    printf("one case: K %.4f train %.4g test %.4g (gap %.3g); suite: K %.4f train %.4g test %.4g (gap %.3g)\n",
           single.x[0], single.train_error, single.test_error, single.test_error - single.train_error, suite.x[0],
           suite.train_error, suite.test_error, suite.test_error - suite.train_error);
    CHECK(single.test_error > single.train_error); /* overfits its one view */
    CHECK(suite.test_error < single.test_error);   /* the suite generalizes better */

    /* the pick: by train error among the points within budget */
    gr_st_point pts[3] = {single, suite, suite};
    pts[0].timed = pts[1].timed = pts[2].timed = 1;
    pts[0].timing.cost_ms = 1, pts[1].timing.cost_ms = 3, pts[2].timing.cost_ms = 2;
    pts[2].train_error = suite.train_error, pts[2].test_error = 0; /* a perfect test error must not sway it */
    pts[1].train_error = fmin(single.train_error, suite.train_error) * 0.5;
    const double budgets[3] = {0.5, 2.5, 10};
    int pick[3];
    gr_st_pick(pts, 3, budgets, 3, pick);
    CHECK(pick[0] == -1);
    CHECK(pick[1] == (single.train_error < suite.train_error ? 0 : 2));
    CHECK(pick[2] == 1);
}

static void budgets(gr_technique *r, gr_scene **sc, gr_image **truth)
{
    gr_error err;
    const int level = 9;
    const double xt[2] = {0.8, 1.2};
    gr_st_options o = {.params = "shafts.K,shafts.extinction", .seed = 2};
    gr_st_case cases[NCASE];
    double work = 0.0;
    for (int c = 0; c < NCASE; c++) {
        gr_section_store s;
        CHECK_OK(gr_st_level_settings(&gr_shafts_class, sc[0], level, &o, xt, s.bytes, &err), err);
        CHECK_OK(gr_technique_render(r, sc[c], s.bytes, truth[c], NULL, &err), err);
        cases[c] = (gr_st_case){sc[c], truth[c], c < 3 ? GR_SPLIT_TRAIN : GR_SPLIT_TEST};
    }
    /* the oracle of the work: the untuned settings rendered case by case, their counters summed */
    {
        gr_st_point u;
        CHECK_OK(gr_st_tune_level(r, cases, NCASE, level, &o, &u, NULL, &err), err);
        gr_image *img = gr_image_create(W, H, 3, NULL);
        for (int c = 0; c < 3; c++) {
            gr_technique_stats stats;
            CHECK_OK(gr_technique_render(r, sc[c], u.settings.bytes, img, &stats, &err), err);
            work += (double)gr_technique_stats_work(&stats);
        }
        gr_image_destroy(img);
        CHECK(work > 0 && u.work == work);
    }
    /* half the work: the anchor's global search (over 500 evaluations) fits in half of them only
     * as the local search from the untuned point */
    gr_st_point u, half, carried;
    o.work_ref = 0.5 * work;
    CHECK_OK(gr_st_tune_level(r, cases, NCASE, level, &o, &u, &half, &err), err);
    printf("budget 1/2: %s search, %d of %d evaluations, train %.4g (untuned %.4g)\n", gr_st_search_name(half.local),
           half.evals, half.budget, half.train_error, u.train_error);
    CHECK(half.budget > 200 && half.local == GR_ST_LOCAL && half.evals <= half.budget);
    CHECK(half.train_error < u.train_error);
    /* a tiny budget with two candidates (one of them the truth's look): only they are evaluated */
    o.work_ref = 1e-3 * work;
    o.n_from = 2;
    o.from[0][0] = 1.0, o.from[0][1] = 1.0;
    o.from[1][0] = xt[0], o.from[1][1] = xt[1];
    CHECK_OK(gr_st_tune_level(r, cases, NCASE, level, &o, &u, &carried, &err), err);
    printf("budget 1/1000: %s, %d evaluations of a budget of %d: K %.4f ext x%.4f, train %.4g (untuned %.4g)\n",
           gr_st_search_name(carried.local), carried.evals, carried.budget, carried.x[0], carried.x[1],
           carried.train_error, u.train_error);
    CHECK(carried.local == GR_ST_CARRIED && carried.evals == 2 && carried.budget >= 1);
    CHECK(carried.x[0] == xt[0] && carried.x[1] == xt[1] && carried.train_error <= u.train_error);
    /* the candidate's train error is the search's value: the same as scoring its settings */
    double again;
    CHECK_OK(gr_st_score(r, cases, NCASE, GR_SPLIT_TRAIN, carried.settings.bytes, &again, &err), err);
    CHECK(again == carried.train_error);
}

int main(void)
{
    gr_technique *r = tune_test_renderer();
    gr_scene *sc[NCASE] = {view(0, 0, 0), view(25, 0, 0.5), view(-20, -5, 1.0), view(12, 4, 0.25), view(-8, 0, 1.5)};
    gr_image *truth[NCASE];
    for (int i = 0; i < NCASE; i++) truth[i] = gr_image_create(W, H, 3, NULL);
    const int reduced = tune_test_reduced();
    /* every ladder point of the shafts; reduced: levels 9 and 10 (N=11, rgba16f at half size and
     * rgba8 at full size: the anchor is 10, level 9 gets the local search) */
    int lv[64], n = 0;
    for (int l = 0; l < gr_shafts_class.n_ladder && n < 64; l++)
        if (!reduced || l == 9 || l == 10) lv[n++] = l;
    identify(r, sc, truth, lv, n, reduced);
    generalization(r, sc, truth);
    budgets(r, sc, truth);
    for (int i = 0; i < NCASE; i++) {
        gr_image_destroy(truth[i]);
        free(sc[i]);
    }
    tune_test_renderer_destroy(r);
    CHECK_DONE(); /* every CHECK above counted: a failed one fails the test */
}
