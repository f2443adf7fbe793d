/* Pareto fronts (src/tune/pareto.h) against a brute-force definition on random point sets,
 * plus hand-made cases: ties, duplicates, non-finite points, per-family marking. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"
#include "tune/pareto.h"

/* brute force: i is dominated iff some j is no worse in both and better in one */
static int dominated(int n, const double *c, const double *e, int i)
{
    for (int j = 0; j < n; j++)
        if (j != i && c[j] <= c[i] && e[j] <= e[i] && (c[j] < c[i] || e[j] < e[i])) return 1;
    return 0;
}

int main(void)
{
    double c[64], e[64];
    int f[64];
    for (int trial = 0; trial < 200; trial++) {
        gr_rng r = gr_rng_make(7, (uint64_t)trial, 0);
        int n = 1 + (int)(gr_rng_u32(&r) % 60);
        for (int i = 0; i < n; i++) {
            /* coarse values so that ties happen */
            c[i] = floor(gr_rng_double(&r) * 10);
            e[i] = floor(gr_rng_double(&r) * 10);
        }
        gr_pareto_front(n, c, e, f);
        int any = 0;
        for (int i = 0; i < n; i++) {
            CHECK(f[i] == !dominated(n, c, e, i));
            any |= f[i];
        }
        CHECK(any); /* a finite set always has a front */
    }
    /* duplicates are both on the front; NaN never is and never dominates */
    double c2[4] = {1, 1, NAN, 0.5}, e2[4] = {2, 2, 0, INFINITY};
    gr_pareto_front(4, c2, e2, f);
    CHECK(f[0] == 1 && f[1] == 1 && f[2] == 0 && f[3] == 0);

    gr_pareto_point pts[4];
    memset(pts, 0, sizeof pts);
    pts[0] = (gr_pareto_point){.family = GR_PARETO_REFERENCE, .time_s = 10, .cost_s = 10, .error = 0.01};
    pts[1] = (gr_pareto_point){.family = GR_PARETO_REFERENCE, .time_s = 20, .cost_s = 20, .error = 0.02};
    pts[2] = (gr_pareto_point){.family = 1, .time_s = 0.01, .cost_s = 0.01, .error = 0.5};
    pts[3] = (gr_pareto_point){.family = 1, .time_s = 0.02, .cost_s = 0.02, .error = 0.4};
    gr_pareto_mark_fronts(pts, 4);
    /* per family: the shafts are not dominated by the (slower, better) reference points */
    CHECK(pts[0].on_front == 1 && pts[1].on_front == 0 && pts[2].on_front == 1 && pts[3].on_front == 1);

    /* a third family (a second technique): its own front, whatever the others' points */
    gr_pareto_point q[6];
    memcpy(q, pts, sizeof pts);
    q[4] = (gr_pareto_point){.family = 2, .time_s = 0.05, .cost_s = 0.05, .error = 0.9}; /* dominated by family 1 */
    q[5] = (gr_pareto_point){.family = 2, .time_s = 0.06, .cost_s = 0.06, .error = 0.95};
    gr_pareto_mark_fronts(q, 6);
    CHECK(q[2].on_front == 1 && q[3].on_front == 1);
    CHECK(q[4].on_front == 1 && q[5].on_front == 0);
    CHECK_DONE();
}
