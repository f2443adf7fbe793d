/* Bounded derivative-free minimization: Nelder-Mead (Nelder & Mead 1965, with the standard
 * coefficients 1, 2, 1/2, 1/2 of Lagarias et al. 1998) on the unit box, points projected onto
 * the box, restarted from several starting points spread over it (a lattice Latin hypercube)
 * and, per start, once more from its result with a smaller simplex (O'Neill 1971's restart),
 * which unsticks a simplex that collapsed on a flat step of a quantized (8-bit) error surface.
 * Deterministic: same function, same options, same evaluations in the same order. */
#ifndef GR_TUNE_OPTIMIZE_H
#define GR_TUNE_OPTIMIZE_H

#include "common/status.h"

#define GR_OPT_MAX_DIM 8
#define GR_OPT_MAX_STARTS 32

/* The objective at x (in the caller's units, inside [lo, hi]); a failure stops the search and
 * its status is returned by gr_opt_minimize. f must be finite. */
typedef gr_status (*gr_opt_fn)(void *user, const double *x, double *f, gr_error *err);

typedef struct gr_opt_options {
    int n_starts;          /* starting points (0: 4); start 0 is x0 if given */
    const double *x0;      /* first start in caller units (NULL: the lattice point) */
    int max_evals;         /* evaluations per start (0: 60 + 40 n) */
    double init_step;      /* initial simplex edge, fraction of each box side (0: 0.2) */
    double xtol;           /* stop when every vertex is within xtol (fraction of the box side) of
                              the best one (0: 2e-3) */
    double refine_factor;  /* the restart's simplex = init_step * this (0: 0.2; < 0: no restart) */
} gr_opt_options;

typedef struct gr_opt_start {
    double x0[GR_OPT_MAX_DIM];  /* starting point (caller units) */
    double x[GR_OPT_MAX_DIM];   /* best point found from it */
    double f;
    int evals;
    int converged;              /* 1: simplex shrank below xtol; 0: ran out of evaluations */
} gr_opt_start;

typedef struct gr_opt_result {
    int n;
    double x[GR_OPT_MAX_DIM];   /* best over all starts */
    double f;
    int best_start;
    int evals;                  /* total */
    int n_starts;
    gr_opt_start starts[GR_OPT_MAX_STARTS];
} gr_opt_result;

/* Starting point j of m (lattice Latin hypercube on the unit box, in (0, 1)^n): coordinate d
 * is ((j * a_d + d) mod m + 0.5) / m with a_d the d-th integer coprime to m, so each
 * coordinate takes every stratum once. */
void gr_opt_lattice_point(int n, int j, int m, double *u);

/* Minimizes fn over the box [lo, hi] (n <= GR_OPT_MAX_DIM, lo < hi). o may be NULL.
 * GR_E_INPUT for a bad dimension or box, or whatever fn returned. */
gr_status gr_opt_minimize(int n, const double *lo, const double *hi, gr_opt_fn fn, void *user,
                          const gr_opt_options *o, gr_opt_result *res, gr_error *err);

#endif
