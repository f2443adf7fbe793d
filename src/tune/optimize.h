/* Bounded derivative-free minimization: Nelder-Mead (Nelder & Mead 1965, with the standard
 * coefficients 1, 2, 1/2, 1/2 of Lagarias et al. 1998) on the unit box, points projected onto
 * the box, restarted from several starting points spread over it (a lattice Latin hypercube)
 * and, per start, once more from its result with a smaller simplex (O'Neill 1971's restart),
 * which unsticks a simplex that collapsed on a flat step of a quantized (8-bit) error surface.
 * Optionally a first, global stage (a two-stage search): a shifted Halton sample of the box
 * (Halton 1960; the shift a Cranley-Patterson rotation drawn from the seed) is evaluated and
 * the local searches start from its best points that lie apart from each other, instead of
 * from fixed lattice points, so that they begin in the basins the sample found.
 * Deterministic: same function, same options (seed included), same evaluations in the same
 * order. docs/tuning.md "The optimizer". */
#ifndef GR_TUNE_OPTIMIZE_H
#define GR_TUNE_OPTIMIZE_H

#include "common/status.h"

#define GR_OPT_MAX_DIM 8
#define GR_OPT_MAX_STARTS 32

/* The objective at x (in the caller's units, inside [lo, hi]); a failure stops the search and
 * its status is returned by gr_opt_minimize. f must be finite. */
typedef gr_status (*gr_opt_fn)(void *user, const double *x, double *f, gr_error *err);

typedef enum gr_opt_method {
    GR_OPT_NELDER_MEAD = 0, /* local searches from several starts (see above) */
    GR_OPT_CMAES = 1        /* CMA-ES (Hansen 2016, "The CMA Evolution Strategy: A Tutorial"),
                               restarted with a doubled population (IPOP, Auger & Hansen 2005):
                               n_starts runs, the first from x0 (else the centre), the others from
                               the first stage's best points (else lattice points); each run
                               ends with a Nelder-Mead search from its best point */
} gr_opt_method;

typedef struct gr_opt_options {
    gr_opt_method method;
    int n_starts;          /* starting points (0: 4); start 0 is x0 if given */
    const double *x0;      /* first start in caller units (NULL: the lattice point) */
    int max_evals;         /* evaluations per start (0: 60 + 40 n; CMA-ES: 4x that per run, the
                              final Nelder-Mead search included) */
    double init_step;      /* initial simplex edge, fraction of each box side (0: 0.2) */
    double xtol;           /* stop when every vertex is within xtol (fraction of the box side) of
                              the best one (0: 2e-3) */
    double refine_factor;  /* the restart's simplex = init_step * this (0: 0.2; < 0: no restart) */
    int coarse;            /* first stage: this many sample points over the box; the starts
                              after x0 are the best of them, each at least min_sep from the
                              starts already chosen (0: no first stage; the starts after x0
                              are the lattice points) */
    double min_sep;        /* separation of the starts chosen from the sample, max-norm on the
                              unit box (0: 0.25; halved until enough starts are found) */
    unsigned long long seed; /* the sample's random shift */
    int screen;            /* with a first stage: this many candidates (x0 and the sample's best
                              separated points, at most GR_OPT_MAX_STARTS) each get a short
                              Nelder-Mead run of screen_evals; the n_starts best of them (x0's
                              always) continue from where it ended (0 or <= n_starts: none) */
    int screen_evals;      /* 0: 20 + 10 n */
    int polish;            /* last stage: at most this many evaluations of a compass search
                              (Kolda, Lewis & Torczon 2003) from the best point, steps from
                              init_step / 4 down to xtol, moving along box faces where Nelder-Mead's
                              projected simplex stalls (0: none) */
} gr_opt_options;

typedef struct gr_opt_start {
    double x0[GR_OPT_MAX_DIM];  /* starting point (caller units; with screening, the candidate's) */
    double x[GR_OPT_MAX_DIM];   /* best point found from it */
    double f;
    int evals;
    int converged;              /* 1: simplex shrank below xtol; 0: ran out of evaluations */
    int coarse_rank;            /* rank of x0 in the first stage's sample (0 = its best); -1:
                                   not from the sample */
    double f0;                  /* objective at x0 */
} gr_opt_start;

typedef struct gr_opt_result {
    int n;
    double x[GR_OPT_MAX_DIM];   /* best over all starts */
    double f;
    int best_start;
    int evals;                  /* total (the first stage's included) */
    int coarse_evals;           /* the first stage's */
    double coarse_best;         /* the best sample value (INFINITY without a first stage) */
    int screen_evals;           /* the screening runs' (all candidates) */
    int n_screened;             /* candidates screened (0: no screening) */
    int polish_evals;           /* the last stage's */
    double polish_gain;         /* how much it lowered the best value */
    int n_starts;
    gr_opt_start starts[GR_OPT_MAX_STARTS];
} gr_opt_result;

/* Starting point j of m (lattice Latin hypercube on the unit box, in (0, 1)^n): coordinate d
 * is ((j * a_d + d) mod m + 0.5) / m with a_d the d-th integer coprime to m, so each
 * coordinate takes every stratum once. */
void gr_opt_lattice_point(int n, int j, int m, double *u);

/* Point j (>= 0) of the first stage's sample on the unit box: the Halton point j (bases
 * 2, 3, 5, 7, 11, 13, 17, 19) shifted modulo 1 by a vector drawn from seed (core/rng). */
void gr_opt_sample_point(int n, int j, unsigned long long seed, double *u);

/* Minimizes fn over the box [lo, hi] (n <= GR_OPT_MAX_DIM, lo < hi). o may be NULL.
 * GR_E_INPUT for a bad dimension or box, or whatever fn returned. */
gr_status gr_opt_minimize(int n, const double *lo, const double *hi, gr_opt_fn fn, void *user,
                          const gr_opt_options *o, gr_opt_result *res, gr_error *err);

#endif
