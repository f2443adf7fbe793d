/* Bounded Nelder-Mead with restarts (optimize.h). Works on the unit box u in [0, 1]^n,
 * x = lo + u (hi - lo); trial points outside the box are projected onto it. */
#include "tune/optimize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

typedef struct nm_ctx {
    int n;
    const double *lo, *hi;
    gr_opt_fn fn;
    void *user;
    int evals, budget;
    double xtol;
    double f_first;  /* the value at the last run's starting point */
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

/* Radical inverse of i in base b (Halton 1960). */
static double radical_inverse(unsigned long long i, unsigned b)
{
    double r = 0.0, f = 1.0 / b;
    for (; i; i /= b, f /= b) r += f * (double)(i % b);
    return r;
}

void gr_opt_sample_point(int n, int j, unsigned long long seed, double *u)
{
    static const unsigned primes[GR_OPT_MAX_DIM] = {2, 3, 5, 7, 11, 13, 17, 19};
    for (int d = 0; d < n && d < GR_OPT_MAX_DIM; d++) {
        /* Cranley-Patterson rotation: the shift keeps the sample's low discrepancy */
        gr_rng r = gr_rng_make(seed, 0x6f707473ULL /* "opts" */, (uint64_t)d);
        double v = radical_inverse((unsigned long long)j, primes[d]) + gr_rng_double(&r);
        u[d] = v - floor(v);
    }
}

static void clamp_unit(int n, double *u)
{
    for (int d = 0; d < n; d++) u[d] = fmin(1.0, fmax(0.0, u[d]));
}

static double xtol_of(const nm_ctx *c)
{
    return c->xtol;
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
    c->f_first = fv[0];
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

/* Coordinate scans, then compass search, on the unit box from u (value *f). A scan visits
 * the whole side of each coordinate in turn on a grid of SCAN points (the others fixed), moves
 * to the best, and refines it on a grid SCAN times finer around it: a rough one-dimensional
 * error (the shaft width against the pixel grid) has local minima that a simplex does not
 * leave. Scans repeat while they improve. Then the compass search (Kolda, Lewis & Torczon
 * 2003): each coordinate tries +step and -step (clamped), keeps an improvement; a sweep
 * without one halves the step; down to xtol. Stops at the budget. */
#define SCAN 16
static gr_status polish(nm_ctx *c, double *u, double *f, double step, double xtol)
{
    const int n = c->n;
    gr_status st;
    for (int sweep = 0, improved = 1; improved && sweep < 4; sweep++) {
        improved = 0;
        for (int d = 0; d < n; d++) {
            for (int level = 0; level < 2; level++) {
                const double h = level ? 1.0 / (SCAN * SCAN) : 1.0 / SCAN, c0 = u[d];
                double best = *f, bu = c0;
                for (int k = -SCAN / 2; k <= SCAN / 2; k++) {
                    double t[GR_OPT_MAX_DIM], ft;
                    memcpy(t, u, (size_t)n * sizeof(double));
                    /* level 0: the whole side (k + SCAN/2) / SCAN; level 1: around c0 */
                    t[d] = level ? c0 + k * h : (double)(k + SCAN / 2) / SCAN;
                    if (k == 0 && level) continue;
                    if (t[d] < 0.0 || t[d] > 1.0 || t[d] == c0) continue;
                    if (c->evals + 1 > c->budget) goto done;
                    if ((st = eval_u(c, t, &ft)) != GR_OK) return st;
                    if (ft < best) best = ft, bu = t[d];
                }
                if (best < *f) {
                    u[d] = bu;
                    *f = best;
                    improved = 1;
                }
            }
        }
    }
    while (step >= xtol) {
        int improved = 0;
        for (int d = 0; d < n; d++) {
            for (int sgn = 1; sgn >= -1; sgn -= 2) {
                double t[GR_OPT_MAX_DIM], ft;
                memcpy(t, u, (size_t)n * sizeof(double));
                t[d] = fmin(1.0, fmax(0.0, u[d] + sgn * step));
                if (t[d] == u[d]) continue;
                if (c->evals + 1 > c->budget) goto done;
                if ((st = eval_u(c, t, &ft)) != GR_OK) return st;
                if (ft < *f) {
                    memcpy(u, t, (size_t)n * sizeof(double));
                    *f = ft;
                    improved = 1;
                    break;
                }
            }
        }
        if (!improved) step *= 0.5;
    }
done:
    return GR_OK;
}
#undef SCAN

/* Eigen-decomposition of the symmetric n x n matrix a (row-major, destroyed) by cyclic Jacobi
 * rotations: a = V diag(w) V^T, V's columns the eigenvectors. */
static void jacobi_eigen(int n, double a[GR_OPT_MAX_DIM][GR_OPT_MAX_DIM], double *w,
                         double v[GR_OPT_MAX_DIM][GR_OPT_MAX_DIM])
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) v[i][j] = i == j;
    for (int sweep = 0; sweep < 60; sweep++) {
        double off = 0.0;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) off += a[p][q] * a[p][q];
        if (off < 1e-30) break;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) {
                if (fabs(a[p][q]) < 1e-300) continue;
                const double th = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
                const double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                const double cs = 1.0 / sqrt(t * t + 1.0), sn = t * cs;
                for (int k = 0; k < n; k++) { /* columns p, q */
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = cs * akp - sn * akq;
                    a[k][q] = sn * akp + cs * akq;
                }
                for (int k = 0; k < n; k++) { /* rows p, q */
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = cs * apk - sn * aqk;
                    a[q][k] = sn * apk + cs * aqk;
                }
                for (int k = 0; k < n; k++) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = cs * vkp - sn * vkq;
                    v[k][q] = sn * vkp + cs * vkq;
                }
            }
    }
    for (int i = 0; i < n; i++) w[i] = a[i][i];
}

/* Standard normal deviate (Box-Muller) from r. */
static double normal(gr_rng *r)
{
    double u1 = gr_rng_double(r), u2 = gr_rng_double(r);
    if (u1 < 1e-300) u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

#define CMA_MAX_LAMBDA 256
/* One CMA-ES run (Hansen 2016, "The CMA Evolution Strategy: A Tutorial", default strategy
 * parameters of its Table 1) on the unit box from mean u with step sigma and population lambda.
 * A sample outside the box is evaluated at its projection plus a penalty (1 + 10 d^2) on the
 * value's magnitude (d: the distance moved), so the mean is pulled back inside. The best point
 * evaluated comes back in u / *fbest. Stops when sigma times the largest axis falls below xtol,
 * or at the budget. */
static gr_status cmaes(nm_ctx *c, double *u, double *fbest, double sigma, int lambda, unsigned long long seed,
                       int run)
{
    const int n = c->n;
    if (lambda > CMA_MAX_LAMBDA) lambda = CMA_MAX_LAMBDA;
    const int mu = lambda / 2;
    double w[CMA_MAX_LAMBDA], wsum = 0.0, w2 = 0.0;
    for (int i = 0; i < mu; i++) w[i] = log((lambda + 1) / 2.0) - log(i + 1.0), wsum += w[i];
    for (int i = 0; i < mu; i++) w[i] /= wsum, w2 += w[i] * w[i];
    const double mueff = 1.0 / w2;
    const double cc = (4.0 + mueff / n) / (n + 4.0 + 2.0 * mueff / n);
    const double cs = (mueff + 2.0) / (n + mueff + 5.0);
    const double c1 = 2.0 / ((n + 1.3) * (n + 1.3) + mueff);
    const double cmu = fmin(1.0 - c1, 2.0 * (mueff - 2.0 + 1.0 / mueff) / ((n + 2.0) * (n + 2.0) + mueff));
    const double damps = 1.0 + 2.0 * fmax(0.0, sqrt((mueff - 1.0) / (n + 1.0)) - 1.0) + cs;
    const double chin = sqrt((double)n) * (1.0 - 1.0 / (4.0 * n) + 1.0 / (21.0 * n * n));
    double m[GR_OPT_MAX_DIM], pc[GR_OPT_MAX_DIM] = {0}, ps[GR_OPT_MAX_DIM] = {0};
    double C[GR_OPT_MAX_DIM][GR_OPT_MAX_DIM], B[GR_OPT_MAX_DIM][GR_OPT_MAX_DIM], D[GR_OPT_MAX_DIM];
    memcpy(m, u, (size_t)n * sizeof(double));
    for (int i = 0; i < n; i++) {
        D[i] = 1.0;
        for (int j = 0; j < n; j++) C[i][j] = B[i][j] = i == j;
    }
    static double z[CMA_MAX_LAMBDA][GR_OPT_MAX_DIM], y[CMA_MAX_LAMBDA][GR_OPT_MAX_DIM];
    double fx[CMA_MAX_LAMBDA];
    int idx[CMA_MAX_LAMBDA];
    *fbest = INFINITY;
    gr_status st;
    for (int gen = 0;; gen++) {
        if (c->evals + lambda > c->budget) break;
        double maxd = 0.0;
        for (int i = 0; i < n; i++) maxd = fmax(maxd, D[i]);
        if (sigma * maxd < xtol_of(c)) break;
        for (int k = 0; k < lambda; k++) {
            gr_rng r = gr_rng_make(seed, 0x636d6165ULL + (uint64_t)run, (uint64_t)gen * CMA_MAX_LAMBDA + (uint64_t)k);
            for (int i = 0; i < n; i++) z[k][i] = normal(&r);
            double x[GR_OPT_MAX_DIM], xc[GR_OPT_MAX_DIM], d2 = 0.0;
            for (int i = 0; i < n; i++) {
                y[k][i] = 0.0;
                for (int j = 0; j < n; j++) y[k][i] += B[i][j] * D[j] * z[k][j];
                x[i] = m[i] + sigma * y[k][i];
                xc[i] = fmin(1.0, fmax(0.0, x[i]));
                d2 += (x[i] - xc[i]) * (x[i] - xc[i]);
            }
            double f;
            if ((st = eval_u(c, xc, &f)) != GR_OK) return st;
            if (f < *fbest) *fbest = f, memcpy(u, xc, (size_t)n * sizeof(double));
            fx[k] = f + fabs(f) * 10.0 * d2;
            idx[k] = k;
        }
        for (int i = 1; i < lambda; i++) { /* stable sort by penalized value */
            int t = idx[i], k = i - 1;
            while (k >= 0 && fx[idx[k]] > fx[t]) idx[k + 1] = idx[k], k--;
            idx[k + 1] = t;
        }
        double yw[GR_OPT_MAX_DIM] = {0}, zw[GR_OPT_MAX_DIM] = {0};
        for (int r = 0; r < mu; r++)
            for (int i = 0; i < n; i++) yw[i] += w[r] * y[idx[r]][i], zw[i] += w[r] * z[idx[r]][i];
        for (int i = 0; i < n; i++) m[i] += sigma * yw[i];
        /* ps = (1 - cs) ps + sqrt(cs (2 - cs) mueff) C^{-1/2} yw, with C^{-1/2} yw = B zw */
        double bz[GR_OPT_MAX_DIM], psn = 0.0;
        for (int i = 0; i < n; i++) {
            bz[i] = 0.0;
            for (int j = 0; j < n; j++) bz[i] += B[i][j] * zw[j];
            ps[i] = (1.0 - cs) * ps[i] + sqrt(cs * (2.0 - cs) * mueff) * bz[i];
            psn += ps[i] * ps[i];
        }
        psn = sqrt(psn);
        const int hsig = psn / sqrt(1.0 - pow(1.0 - cs, 2.0 * (gen + 1))) / chin < 1.4 + 2.0 / (n + 1.0);
        for (int i = 0; i < n; i++) pc[i] = (1.0 - cc) * pc[i] + hsig * sqrt(cc * (2.0 - cc) * mueff) * yw[i];
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double rmu = 0.0;
                for (int r = 0; r < mu; r++) rmu += w[r] * y[idx[r]][i] * y[idx[r]][j];
                C[i][j] = (1.0 - c1 - cmu) * C[i][j] + c1 * (pc[i] * pc[j] + (1 - hsig) * cc * (2.0 - cc) * C[i][j]) +
                          cmu * rmu;
            }
        sigma *= exp((cs / damps) * (psn / chin - 1.0));
        if (sigma > 1.0) sigma = 1.0;
        double A[GR_OPT_MAX_DIM][GR_OPT_MAX_DIM], ev[GR_OPT_MAX_DIM];
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) A[i][j] = 0.5 * (C[i][j] + C[j][i]);
        jacobi_eigen(n, A, ev, B);
        for (int i = 0; i < n; i++) D[i] = sqrt(fmax(ev[i], 1e-20));
    }
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
    res->coarse_best = INFINITY;
    nm_ctx c = {.n = n, .lo = lo, .hi = hi, .fn = fn, .user = user, .err = err};
    /* the starting points on the unit box; rank[j] >= 0 for those taken from the sample */
    double su[GR_OPT_MAX_STARTS][GR_OPT_MAX_DIM];
    int rank[GR_OPT_MAX_STARTS];
    /* candidates: the starts, or with screening more of them, each screened by a short run */
    int ncand = starts;
    if (o->coarse > 0 && o->screen > starts) ncand = o->screen < GR_OPT_MAX_STARTS ? o->screen : GR_OPT_MAX_STARTS;
    for (int j = 0; j < ncand; j++) {
        rank[j] = -1;
        if (j == 0 && o->x0) {
            for (int d = 0; d < n; d++) su[j][d] = (o->x0[d] - lo[d]) / (hi[d] - lo[d]);
            clamp_unit(n, su[j]);
        } else {
            /* the lattice over the starts that are not x0 */
            int m = o->x0 ? ncand - 1 : ncand, k = o->x0 ? j - 1 : j;
            gr_opt_lattice_point(n, k, m, su[j]);
        }
    }
    if (o->coarse > 0) {
        /* first stage: the sample, then its best points, apart from each other, as starts */
        const int m = o->coarse;
        double *pu = malloc((size_t)m * GR_OPT_MAX_DIM * sizeof(double)), *pf = malloc((size_t)m * sizeof(double));
        int *order = malloc((size_t)m * sizeof(int));
        if (!pu || !pf || !order) {
            free(pu), free(pf), free(order);
            return gr_fail(err, GR_E_NOMEM, "optimizer: out of memory for %d sample points", m);
        }
        c.evals = 0;
        gr_status st = GR_OK;
        for (int i = 0; i < m && st == GR_OK; i++) {
            gr_opt_sample_point(n, i, o->seed, pu + (size_t)i * GR_OPT_MAX_DIM);
            st = eval_u(&c, pu + (size_t)i * GR_OPT_MAX_DIM, &pf[i]);
            order[i] = i;
        }
        res->coarse_evals = c.evals;
        res->evals += c.evals;
        if (st != GR_OK) {
            free(pu), free(pf), free(order);
            return st;
        }
        /* insertion sort by value, ties by index: deterministic */
        for (int i = 1; i < m; i++) {
            int t = order[i], k = i - 1;
            while (k >= 0 && pf[order[k]] > pf[t]) order[k + 1] = order[k], k--;
            order[k + 1] = t;
        }
        res->coarse_best = pf[order[0]];
        const int first = o->x0 ? 1 : 0;
        int chosen = first;
        unsigned char *used = calloc((size_t)m, 1);
        if (!used) {
            free(pu), free(pf), free(order);
            return gr_fail(err, GR_E_NOMEM, "optimizer: out of memory");
        }
        for (double sep = o->min_sep > 0 ? o->min_sep : 0.25; chosen < ncand; sep *= 0.5) {
            for (int r = 0; r < m && chosen < ncand; r++) {
                if (used[order[r]]) continue;
                const double *q = pu + (size_t)order[r] * GR_OPT_MAX_DIM;
                int apart = 1;
                for (int j = 0; j < chosen && apart; j++) {
                    double dist = 0.0;
                    for (int d = 0; d < n; d++) dist = fmax(dist, fabs(q[d] - su[j][d]));
                    if (dist < sep) apart = 0;
                }
                if (!apart && sep > 1e-9) continue;
                used[order[r]] = 1;
                memcpy(su[chosen], q, (size_t)n * sizeof(double));
                rank[chosen++] = r;
            }
            if (sep <= 1e-9) break; /* fewer sample points than starts: the rest stay on the lattice */
        }
        free(used), free(pu), free(pf), free(order);
    }
    /* screening: a short Nelder-Mead run from every candidate; the best continue (x0 first) */
    double orig[GR_OPT_MAX_STARTS][GR_OPT_MAX_DIM], fs[GR_OPT_MAX_STARTS];
    int sev[GR_OPT_MAX_STARTS] = {0};
    memcpy(orig, su, sizeof orig);
    if (ncand > starts) {
        const int sbudget = o->screen_evals > 0 ? o->screen_evals : 20 + 10 * n;
        int order[GR_OPT_MAX_STARTS];
        for (int j = 0; j < ncand; j++) {
            int conv = 0;
            c.evals = 0;
            c.budget = sbudget;
            c.xtol = xtol;
            gr_status st = nelder_mead(&c, su[j], &fs[j], step, xtol, &conv);
            sev[j] = c.evals;
            res->screen_evals += c.evals;
            res->evals += c.evals;
            if (st != GR_OK) return st;
            order[j] = j;
        }
        const int first = o->x0 ? 1 : 0;
        for (int i = first + 1; i < ncand; i++) { /* stable sort of the others by screened value */
            int t = order[i], k = i - 1;
            while (k >= first && fs[order[k]] > fs[t]) order[k + 1] = order[k], k--;
            order[k + 1] = t;
        }
        double tu[GR_OPT_MAX_STARTS][GR_OPT_MAX_DIM], to[GR_OPT_MAX_STARTS][GR_OPT_MAX_DIM];
        int tr[GR_OPT_MAX_STARTS], te[GR_OPT_MAX_STARTS];
        for (int j = 0; j < starts; j++) {
            memcpy(tu[j], su[order[j]], sizeof tu[j]);
            memcpy(to[j], orig[order[j]], sizeof to[j]);
            tr[j] = rank[order[j]], te[j] = sev[order[j]];
        }
        for (int j = 0; j < starts; j++) {
            memcpy(su[j], tu[j], sizeof su[j]);
            memcpy(orig[j], to[j], sizeof orig[j]);
            rank[j] = tr[j], sev[j] = te[j];
        }
        res->n_screened = ncand;
    }
    for (int j = 0; j < starts; j++) {
        double u[GR_OPT_MAX_DIM], f = INFINITY;
        memcpy(u, su[j], sizeof u);
        gr_opt_start *s = &res->starts[j];
        s->coarse_rank = rank[j];
        for (int d = 0; d < n; d++) s->x0[d] = lo[d] + orig[j][d] * (hi[d] - lo[d]);
        c.evals = 0;
        c.budget = budget;
        c.xtol = xtol;
        int conv = 0;
        gr_status st = GR_OK;
        if (o->method == GR_OPT_CMAES) {
            /* IPOP: population 4 + 3 ln n, doubled per run; then Nelder-Mead from the best */
            c.budget = 3 * budget;
            const int lambda = (4 + (int)floor(3.0 * log((double)n))) << (j < 5 ? j : 5);
            st = cmaes(&c, u, &f, 0.3, lambda, o->seed, j);
            s->f0 = f;
            c.budget = 4 * budget;
        }
        if (st == GR_OK) st = nelder_mead(&c, u, &f, o->method == GR_OPT_CMAES ? step * 0.2 : step, xtol, &conv);
        if (o->method != GR_OPT_CMAES) s->f0 = c.f_first;
        if (st == GR_OK && refine > 0 && c.evals + n + 3 <= c.budget) {
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
    if (o->polish > 0 && isfinite(res->f)) {
        double u[GR_OPT_MAX_DIM], f = res->f;
        for (int d = 0; d < n; d++) u[d] = (res->x[d] - lo[d]) / (hi[d] - lo[d]);
        c.evals = 0;
        c.budget = o->polish;
        gr_status st = polish(&c, u, &f, 0.25 * step, xtol);
        res->polish_evals = c.evals;
        res->evals += c.evals;
        if (st != GR_OK) return st;
        if (f < res->f) {
            res->polish_gain = res->f - f;
            res->f = f;
            for (int d = 0; d < n; d++) res->x[d] = lo[d] + u[d] * (hi[d] - lo[d]);
        }
    }
    return GR_OK;
}
