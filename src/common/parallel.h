/* Independent jobs on a few threads: the comparisons of a run (a technique's metrics, a
 * baseline, a rung of the blurred truth's ladder). Each job writes only its own results, so
 * what the jobs compute does not depend on the thread count (docs/architecture.md). */
#ifndef GR_PARALLEL_H
#define GR_PARALLEL_H

/* At most this many threads, whatever is asked: each comparison job holds tens of MB at
 * 640 x 360 (some hundreds at 1080p). */
#define GR_PARALLEL_MAX 4

/* The threads gr_parallel_for uses for `want` (<= 0: the online processors), in [1, GR_PARALLEL_MAX]. */
int gr_parallel_threads(int want);
/* Calls fn(ctx, i) once for every i in [0, n), on up to gr_parallel_threads(threads) threads
 * (the calling one included; a thread that cannot be started leaves its share to the others);
 * returns when every call has returned. */
void gr_parallel_for(int n, int threads, void (*fn)(void *ctx, int i), void *ctx);

#endif
