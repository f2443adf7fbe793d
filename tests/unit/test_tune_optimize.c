/* The bounded Nelder-Mead with restarts (src/tune/optimize.h) against functions whose minima
 * are known in closed form: an anisotropic quadratic inside the box, the same quadratic with
 * its minimum outside the box (the answer is the nearest box point, coordinate-wise here),
 * Rosenbrock's valley (minimum (1, 1)), and an 8-bit-quantized quadratic (flat steps, as the
 * rgba8 target makes the error surface). Also: the lattice of starting points is a Latin
 * hypercube, runs are deterministic, bad boxes and objective failures are reported.
 * The global stages: the shifted Halton sample's first 2^k points of a base-2 coordinate fall
 * one into each 2^-k interval (a rotation modulo 1 keeps the equal spacing); the two-stage search
 * finds the deeper of two basins when its first start lies in the shallower one; CMA-ES finds
 * Rosenbrock's minimum; both are deterministic for a seed. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "tune/optimize.h"

typedef struct quad {
    double c[GR_OPT_MAX_DIM], w[GR_OPT_MAX_DIM];
    int quantize; /* 1: round f to 1/255 steps */
    int evals;
} quad;

static gr_status f_quad(void *user, const double *x, double *f, gr_error *err)
{
    quad *q = user;
    double s = 0;
    for (int d = 0; d < GR_OPT_MAX_DIM; d++) s += q->w[d] * (x[d] - q->c[d]) * (x[d] - q->c[d]);
    *f = q->quantize ? floor(s * 255.0) / 255.0 : s;
    q->evals++;
    return GR_OK;
}

static gr_status f_rosen(void *user, const double *x, double *f, gr_error *err)
{
    (void)user;
    *f = (1 - x[0]) * (1 - x[0]) + 100 * (x[1] - x[0] * x[0]) * (x[1] - x[0] * x[0]);
    return GR_OK;
}

/* two basins on [0, 1]^2: a wide shallow one around (0.2, 0.25), value 0.1 at its floor, and a
 * narrow deep one around (0.8, 0.7), value 0 */
static gr_status f_basins(void *user, const double *x, double *f, gr_error *err)
{
    int *evals = user;
    const double a = 0.1 + 2.0 * ((x[0] - 0.2) * (x[0] - 0.2) + (x[1] - 0.25) * (x[1] - 0.25));
    const double b = 40.0 * ((x[0] - 0.8) * (x[0] - 0.8) + (x[1] - 0.7) * (x[1] - 0.7));
    *f = fmin(a, b);
    ++*evals;
    return GR_OK;
}

static gr_status f_fail(void *user, const double *x, double *f, gr_error *err)
{
    int *calls = user;
    if (++*calls == 5) return gr_fail(err, GR_E_GL, "render failed (test)");
    *f = x[0] * x[0];
    return GR_OK;
}

int main(void)
{
    gr_error err;
    gr_opt_result res;

    /* lattice: for m = 5 starts in 3 dimensions every coordinate visits each fifth once */
    for (int m = 1; m <= 9; m++)
        for (int d = 0; d < 3; d++) {
            int seen[16] = {0};
            for (int j = 0; j < m; j++) {
                double u[3];
                gr_opt_lattice_point(3, j, m, u);
                int k = (int)floor(u[d] * m);
                CHECK(k >= 0 && k < m && fabs(u[d] - (k + 0.5) / m) < 1e-12);
                seen[k]++;
            }
            for (int k = 0; k < m; k++) CHECK_MSG(seen[k] == 1, "m %d dim %d stratum %d seen %d", m, d, k, seen[k]);
        }

    /* interior minimum of an anisotropic quadratic in 3 D: found to within the tolerance */
    quad q = {.c = {0.3, -1.2, 4.0}, .w = {1, 10, 0.1}};
    double lo[3] = {-1, -2, 0}, hi[3] = {1, 2, 10};
    gr_opt_options o = {.n_starts = 3, .xtol = 1e-4, .max_evals = 600};
    CHECK_OK(gr_opt_minimize(3, lo, hi, f_quad, &q, &o, &res, &err), err);
    for (int d = 0; d < 3; d++) CHECK_NEAR(res.x[d], q.c[d], 1e-3 * (hi[d] - lo[d]));
    CHECK(res.f < 1e-5);
    CHECK(res.evals == q.evals);
    for (int j = 0; j < res.n_starts; j++) CHECK(res.starts[j].converged);

    /* minimum outside the box: separable quadratic, so the constrained optimum is the clamp */
    quad q2 = {.c = {2.0, -3.0}, .w = {1, 1}};
    CHECK_OK(gr_opt_minimize(2, (double[]){-1, -1}, (double[]){1, 1}, f_quad, &q2, &o, &res, &err), err);
    CHECK_NEAR(res.x[0], 1.0, 1e-9);
    CHECK_NEAR(res.x[1], -1.0, 1e-9);

    /* Rosenbrock in [-2, 2]^2 from the far corner */
    gr_opt_options ro = {.n_starts = 2, .x0 = (double[]){-1.5, 1.8}, .xtol = 1e-5, .max_evals = 2000};
    CHECK_OK(gr_opt_minimize(2, (double[]){-2, -2}, (double[]){2, 2}, f_rosen, NULL, &ro, &res, &err), err);
    CHECK_NEAR(res.x[0], 1.0, 2e-3);
    CHECK_NEAR(res.x[1], 1.0, 4e-3);

    /* quantized surface: the minimum step around c is |x - c| < sqrt(1/255 / w) wide (0.063 for
     * w = 1); every start must end inside it, and the starts agree to that width */
    quad q3 = {.c = {0.37, 0.61}, .w = {1, 1}, .quantize = 1};
    gr_opt_options qo = {.n_starts = 6};
    CHECK_OK(gr_opt_minimize(2, (double[]){-1, -1}, (double[]){2, 2}, f_quad, &q3, &qo, &res, &err), err);
    for (int j = 0; j < res.n_starts; j++) {
        const double *x = res.starts[j].x;
        double r2 = (x[0] - 0.37) * (x[0] - 0.37) + (x[1] - 0.61) * (x[1] - 0.61);
        CHECK_MSG(res.starts[j].f == 0.0 && r2 < 1.0 / 255.0, "start %d ended at (%g, %g) f %g", j, x[0], x[1],
                  res.starts[j].f);
    }

    /* deterministic: the same call gives the same bits */
    gr_opt_result again;
    q3.evals = 0;
    CHECK_OK(gr_opt_minimize(2, (double[]){-1, -1}, (double[]){2, 2}, f_quad, &q3, &qo, &again, &err), err);
    CHECK(memcmp(res.x, again.x, sizeof res.x) == 0 && res.evals == again.evals && res.f == again.f);

    /* the first stage's sample: in [0, 1), stratified along a base-2 coordinate for any seed */
    for (unsigned long long seed = 0; seed < 3; seed++) {
        int seen[16] = {0};
        for (int j = 0; j < 16; j++) {
            double u[4];
            gr_opt_sample_point(4, j, seed, u);
            for (int d = 0; d < 4; d++) CHECK(u[d] >= 0.0 && u[d] < 1.0);
            seen[(int)floor(u[0] * 16)]++;
        }
        for (int k = 0; k < 16; k++) CHECK_MSG(seen[k] == 1, "seed %llu: interval %d holds %d points", seed, k, seen[k]);
    }
    {
        double a[2], b[2];
        gr_opt_sample_point(2, 5, 1, a);
        gr_opt_sample_point(2, 5, 2, b);
        CHECK(a[0] != b[0] || a[1] != b[1]);
    }

    /* two basins, the first start in the shallow one: the lattice-free local search from x0 stays
     * there; the two-stage search (sample + a second start from its best point) and CMA-ES end
     * in the deep one, the same bits for the same seed */
    {
        const double blo[2] = {0, 0}, bhi[2] = {1, 1}, bx0[2] = {0.15, 0.3};
        int ev = 0;
        gr_opt_options one = {.n_starts = 1, .x0 = bx0, .xtol = 1e-5};
        CHECK_OK(gr_opt_minimize(2, blo, bhi, f_basins, &ev, &one, &res, &err), err);
        CHECK_MSG(fabs(res.f - 0.1) < 1e-6, "one local search from the shallow basin: f %g", res.f);
        gr_opt_options two = {.n_starts = 2, .x0 = bx0, .xtol = 1e-5, .coarse = 32, .polish = 100, .seed = 7};
        for (int m = 0; m < 2; m++) {
            two.method = m ? GR_OPT_CMAES : GR_OPT_NELDER_MEAD;
            gr_opt_result r2;
            ev = 0;
            CHECK_OK(gr_opt_minimize(2, blo, bhi, f_basins, &ev, &two, &res, &err), err);
            CHECK_MSG(res.f < 1e-6 && fabs(res.x[0] - 0.8) < 1e-3 && fabs(res.x[1] - 0.7) < 1e-3,
                      "%s: f %g at (%g, %g)", m ? "CMA-ES" : "two-stage", res.f, res.x[0], res.x[1]);
            CHECK(res.evals == ev && res.coarse_evals == 32 && res.starts[1].coarse_rank >= 0);
            CHECK_OK(gr_opt_minimize(2, blo, bhi, f_basins, &ev, &two, &r2, &err), err);
            CHECK(memcmp(res.x, r2.x, sizeof res.x) == 0 && res.evals == r2.evals);
        }
    }

    /* CMA-ES alone on Rosenbrock from the far corner */
    gr_opt_options co = {.method = GR_OPT_CMAES, .n_starts = 1, .x0 = (double[]){-1.5, 1.8}, .xtol = 1e-6,
                         .max_evals = 1500, .seed = 3};
    CHECK_OK(gr_opt_minimize(2, (double[]){-2, -2}, (double[]){2, 2}, f_rosen, NULL, &co, &res, &err), err);
    CHECK_MSG(fabs(res.x[0] - 1.0) < 2e-3 && fabs(res.x[1] - 1.0) < 4e-3, "CMA-ES Rosenbrock: (%g, %g)", res.x[0],
              res.x[1]);

    /* errors */
    CHECK(gr_opt_minimize(0, lo, hi, f_quad, &q, NULL, &res, &err) == GR_E_INPUT);
    CHECK(gr_opt_minimize(GR_OPT_MAX_DIM + 1, lo, hi, f_quad, &q, NULL, &res, &err) == GR_E_INPUT);
    CHECK(gr_opt_minimize(1, (double[]){1}, (double[]){1}, f_quad, &q, NULL, &res, &err) == GR_E_INPUT &&
          strstr(err.msg, "bounds"));
    int calls = 0;
    CHECK(gr_opt_minimize(1, (double[]){-1}, (double[]){1}, f_fail, &calls, NULL, &res, &err) == GR_E_GL &&
          calls == 5 && strstr(err.msg, "render failed"));
    CHECK_DONE();
}
