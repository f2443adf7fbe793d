/* Bounded Nelder-Mead with restarts (optimize.h). Works on the unit box u in [0, 1]^n,
 * x = lo + u (hi - lo); trial points outside the box are projected onto it. */
#include "tune/optimize.h"

#include <math.h>
#include <string.h>

typedef struct nm_ctx {
    int n;
    const double *lo, *hi;
    gr_opt_fn fn;
    void *user;
    int evals, budget;
    gr_error *err;
} nm_ctx;

static int gcd(int a, int b)
{
    while (b) {
        int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* The d-th multiplier coprime to m (1 first): j -> (a j + d) mod m is then a permutation of
 * the m strata for every coordinate (a Korobov-style rank-1 lattice). */
static int lattice_mult(int d, int m)
{
    int a = 1, found = 0;
    for (int cand = 1; cand < 4 * m + 64; cand++) {
        if (gcd(cand, m) != 1) continue;
        a = cand;
        if (found++ == d) break;
    }
    return m > 1 ? a : 1;
}

void gr_opt_lattice_point(int n, int j, int m, double *u)
{
    if (m < 1) m = 1;
    for (int d = 0; d < n; d++) {
        int k = (int)(((long long)j * lattice_mult(d, m) + d) % m);
        u[d] = ((double)k + 0.5) / (double)m;
    }
}

static void clamp_unit(int n, double *u)
{
    for (int d = 0; d < n; d++) u[d] = fmin(1.0, fmax(0.0, u[d]));
}

static gr_status eval_u(nm_ctx *c, const double *u, double *f)
{
    double x[GR_OPT_MAX_DIM];
    for (int d = 0; d < c->n; d++) x[d] = c->lo[d] + u[d] * (c->hi[d] - c->lo[d]);
    c->evals++;
    gr_status st = c->fn(c->user, x, f, c->err);
    if (st != GR_OK) return st;
    if (!isfinite(*f)) return gr_fail(c->err, GR_E_RUNTIME, "optimizer: objective is not finite");
    return GR_OK;
}

/* One Nelder-Mead run from u0 with an initial simplex of edge `step`; the best point and
 * value come back in u0 / *fbest. *converged = 1 when the simplex shrank below xtol. */
static gr_status nelder_mead(nm_ctx *c, double *u0, double *fbest, double step, double xtol, int *converged)
{
    const int n = c->n;
    double v[GR_OPT_MAX_DIM + 1][GR_OPT_MAX_DIM], fv[GR_OPT_MAX_DIM + 1];
    gr_status st;
    *converged = 0;
    memcpy(v[0], u0, (size_t)n * sizeof(double));
    clamp_unit(n, v[0]);
    if ((st = eval_u(c, v[0], &fv[0])) != GR_OK) return st;
    for (int i = 1; i <= n; i++) {
        memcpy(v[i], v[0], (size_t)n * sizeof(double));
        /* step inward when the vertex would leave the box */
        v[i][i - 1] += v[0][i - 1] + step <= 1.0 ? step : -step;
        clamp_unit(n, v[i]);
        if ((st = eval_u(c, v[i], &fv[i])) != GR_OK) return st;
    }
    for (;;) {
        /* order: insertion sort by f (stable: ties keep their order, so runs are deterministic) */
        for (int i = 1; i <= n; i++) {
            double ft = fv[i], vt[GR_OPT_MAX_DIM];
            memcpy(vt, v[i], (size_t)n * sizeof(double));
            int j = i - 1;
            while (j >= 0 && fv[j] > ft) {
                fv[j + 1] = fv[j];
                memcpy(v[j + 1], v[j], (size_t)n * sizeof(double));
                j--;
            }
            fv[j + 1] = ft;
            memcpy(v[j + 1], vt, (size_t)n * sizeof(double));
        }
        double size = 0.0;
        for (int i = 1; i <= n; i++)
            for (int d = 0; d < n; d++) size = fmax(size, fabs(v[i][d] - v[0][d]));
        if (size < xtol) {
            *converged = 1;
            break;
        }
        if (c->evals + 2 > c->budget) break;
        double cen[GR_OPT_MAX_DIM], xr[GR_OPT_MAX_DIM], xt[GR_OPT_MAX_DIM], fr, ft;
        for (int d = 0; d < n; d++) {
            cen[d] = 0.0;
            for (int i = 0; i < n; i++) cen[d] += v[i][d];
            cen[d] /= (double)n;
        }
        for (int d = 0; d < n; d++) xr[d] = cen[d] + (cen[d] - v[n][d]); /* reflection */
        clamp_unit(n, xr);
        if ((st = eval_u(c, xr, &fr)) != GR_OK) return st;
        int shrink = 0;
        if (fr < fv[0]) {
            for (int d = 0; d < n; d++) xt[d] = cen[d] + 2.0 * (cen[d] - v[n][d]); /* expansion */
            clamp_unit(n, xt);
            if ((st = eval_u(c, xt, &ft)) != GR_OK) return st;
            if (ft < fr) {
                memcpy(v[n], xt, (size_t)n * sizeof(double));
                fv[n] = ft;
            } else {
                memcpy(v[n], xr, (size_t)n * sizeof(double));
                fv[n] = fr;
            }
        } else if (fr < fv[n - 1]) {
            memcpy(v[n], xr, (size_t)n * sizeof(double));
            fv[n] = fr;
        } else if (fr < fv[n]) {
            for (int d = 0; d < n; d++) xt[d] = cen[d] + 0.5 * (xr[d] - cen[d]); /* outside contraction */
            if ((st = eval_u(c, xt, &ft)) != GR_OK) return st;
            if (ft <= fr) {
                memcpy(v[n], xt, (size_t)n * sizeof(double));
                fv[n] = ft;
            } else {
                shrink = 1;
            }
        } else {
            for (int d = 0; d < n; d++) xt[d] = cen[d] + 0.5 * (v[n][d] - cen[d]); /* inside contraction */
            if ((st = eval_u(c, xt, &ft)) != GR_OK) return st;
            if (ft < fv[n]) {
                memcpy(v[n], xt, (size_t)n * sizeof(double));
                fv[n] = ft;
            } else {
                shrink = 1;
            }
        }
        if (shrink) {
            for (int i = 1; i <= n; i++) {
                for (int d = 0; d < n; d++) v[i][d] = v[0][d] + 0.5 * (v[i][d] - v[0][d]);
                if ((st = eval_u(c, v[i], &fv[i])) != GR_OK) return st;
            }
        }
    }
    int b = 0;
    for (int i = 1; i <= n; i++)
        if (fv[i] < fv[b]) b = i;
    memcpy(u0, v[b], (size_t)n * sizeof(double));
    *fbest = fv[b];
    return GR_OK;
}

gr_status gr_opt_minimize(int n, const double *lo, const double *hi, gr_opt_fn fn, void *user,
                          const gr_opt_options *o, gr_opt_result *res, gr_error *err)
{
    memset(res, 0, sizeof *res);
    if (n < 1 || n > GR_OPT_MAX_DIM) return gr_fail(err, GR_E_INPUT, "optimizer: %d dimensions (1..%d)", n, GR_OPT_MAX_DIM);
    for (int d = 0; d < n; d++)
        if (!(isfinite(lo[d]) && isfinite(hi[d]) && lo[d] < hi[d]))
            return gr_fail(err, GR_E_INPUT, "optimizer: bounds of coordinate %d are [%g, %g]", d, lo[d], hi[d]);
    gr_opt_options def = {0};
    if (!o) o = &def;
    int starts = o->n_starts > 0 ? o->n_starts : 4;
    if (starts > GR_OPT_MAX_STARTS) starts = GR_OPT_MAX_STARTS;
    int budget = o->max_evals > 0 ? o->max_evals : 60 + 40 * n;
    double step = o->init_step > 0 ? o->init_step : 0.2;
    double xtol = o->xtol > 0 ? o->xtol : 2e-3;
    double refine = o->refine_factor == 0 ? 0.2 : o->refine_factor;

    res->n = n;
    res->n_starts = starts;
    res->f = INFINITY;
    nm_ctx c = {.n = n, .lo = lo, .hi = hi, .fn = fn, .user = user, .err = err};
    for (int j = 0; j < starts; j++) {
        double u[GR_OPT_MAX_DIM], f = INFINITY;
        if (j == 0 && o->x0) {
            for (int d = 0; d < n; d++) u[d] = (o->x0[d] - lo[d]) / (hi[d] - lo[d]);
            clamp_unit(n, u);
        } else {
            /* the lattice over the starts that are not x0 */
            int m = o->x0 ? starts - 1 : starts, k = o->x0 ? j - 1 : j;
            gr_opt_lattice_point(n, k, m, u);
        }
        gr_opt_start *s = &res->starts[j];
        for (int d = 0; d < n; d++) s->x0[d] = lo[d] + u[d] * (hi[d] - lo[d]);
        c.evals = 0;
        c.budget = budget;
        int conv = 0;
        gr_status st = nelder_mead(&c, u, &f, step, xtol, &conv);
        if (st == GR_OK && refine > 0 && c.evals + n + 3 <= budget) {
            double u2[GR_OPT_MAX_DIM], f2;
            memcpy(u2, u, sizeof u2);
            int conv2 = 0;
            st = nelder_mead(&c, u2, &f2, step * refine, xtol, &conv2);
            if (st == GR_OK && f2 <= f) {
                memcpy(u, u2, sizeof u);
                f = f2;
            }
            conv = conv2;
        }
        res->evals += c.evals;
        if (st != GR_OK) return st;
        for (int d = 0; d < n; d++) s->x[d] = lo[d] + u[d] * (hi[d] - lo[d]);
        s->f = f;
        s->evals = c.evals;
        s->converged = conv;
        if (f < res->f) {
            res->f = f;
            res->best_start = j;
            memcpy(res->x, s->x, sizeof res->x);
        }
    }
    return GR_OK;
}
