/* Independent jobs on a few threads: the comparisons of a run (a technique's metrics, a
 * baseline, a rung of the blurred truth's ladder). Each job writes only its own results, so
 * what the jobs compute does not depend on the thread count (docs/architecture.md). */
#ifndef GR_PARALLEL_H
#define GR_PARALLEL_H

#include "common/status.h"

/* At most this many threads, whatever is asked: each comparison job holds tens of MB at
 * 640 x 360 (some hundreds at 1080p). */
#define GR_PARALLEL_MAX 4

/* The threads gr_parallel_for uses for `want` (<= 0: the online processors), in [1, GR_PARALLEL_MAX]. */
int gr_parallel_threads(int want);
/* Calls fn(ctx, i) once for every i in [0, n), on up to gr_parallel_threads(threads) threads
 * (the calling one included; a thread that cannot be started leaves its share to the others);
 * returns when every call has returned. */
void gr_parallel_for(int n, int threads, void (*fn)(void *ctx, int i), void *ctx);
/* gr_parallel_for for jobs that can fail: fn(ctx, i, e) returns a status with its message in
 * its own e. Every job runs; the result is the first failure in index order (its message in
 * *err), else GR_OK; GR_E_NOMEM when the statuses cannot be held (then no job runs). */
gr_status gr_parallel_try(int n, int threads, gr_status (*fn)(void *ctx, int i, gr_error *err), void *ctx,
                          gr_error *err);

#endif
