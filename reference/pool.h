/* The integrator's worker threads (internal to reference/): a pass over rows, shared by the
 * march (reference/march.h) and the step pilot (reference/pilot.h). Threads take bands of rows
 * from a shared counter; the caller's thread waits for the last worker to end (woken by it),
 * updating the progress bar every 20 ms meanwhile, and stops waiting on a stop flag or an
 * interrupt. Every worker runs with denormals flushed. */
#ifndef GR_REF_POOL_H
#define GR_REF_POOL_H

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include "common/status.h"
#include "reference/progress.h"

/* What the workers of one run share: the next row to take, the rows finished, stop (1: stop,
 * 2: out of memory in a worker: the run fails) and counters summed as each worker ends. */
typedef struct gr_ref_work {
    atomic_int next_row, rows_done, stop;
    atomic_llong queries, shadow_rays, max_hits; /* max_hits: the most beams at one point */
    double par_s; /* set by gr_ref_pool_run: the time with at least two workers busy */
} gr_ref_work;
/* Zeroed, the next row row0. */
void gr_ref_work_init(gr_ref_work *w, int row0);

/* Seconds on a monotonic clock (the integrator's timings). */
double gr_ref_mono_s(void);

typedef struct gr_ref_pool gr_ref_pool;
/* Room for `threads` workers (at least one). NULL if no memory. */
gr_ref_pool *gr_ref_pool_create(int threads);
void gr_ref_pool_destroy(gr_ref_pool *p); /* accepts NULL */
/* Runs fn(arg) on every worker and waits for them: until `rows` units (rows or tiles) are done, w->stop is
 * set or *interrupt (may be NULL) is; meanwhile the bar goes from frac0 to frac0 + span
 * with the rows done, labelled note. GR_E_RUNTIME when no thread starts, GR_E_NOMEM when a
 * worker ran out of memory (w->stop == 2); otherwise GR_OK (w->rows_done < rows: interrupted). */
gr_status gr_ref_pool_run(gr_ref_pool *p, void *(*fn)(void *), void *arg, gr_ref_work *w, int rows,
                          volatile sig_atomic_t *interrupt, gr_progress *prog, double frac0, double span,
                          const char *note, gr_error *err);

#endif
