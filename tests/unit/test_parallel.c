/* common/parallel.h: every job index runs exactly once, whatever the thread count asked for
 * (1 .. 8, 0 = the online processors) and the number of jobs (0 .. 40, fewer or more than the
 * threads); the thread count is clamped to [1, GR_PARALLEL_MAX]; and jobs do run side by side
 * when more than one thread is allowed (two jobs that wait for each other finish). */
#include <stdatomic.h>
#include <time.h>

#include "check.h"
#include "common/parallel.h"

typedef struct counts {
    atomic_int hits[64];
    atomic_int active, overlap;
} counts;

static void count_job(void *arg, int i)
{
    counts *c = arg;
    atomic_fetch_add(&c->hits[i], 1);
}

/* Job i waits (up to 2 s) until some other job is running at the same time. */
static void meet_job(void *arg, int i)
{
    (void)i;
    counts *c = arg;
    atomic_fetch_add(&c->active, 1);
    for (int t = 0; t < 2000 && atomic_load(&c->active) < 2; t++) nanosleep(&(struct timespec){0, 1000000}, NULL);
    if (atomic_load(&c->active) >= 2) atomic_fetch_add(&c->overlap, 1);
}

int main(void)
{
    for (int threads = 0; threads <= 8; threads++)
        for (int n = 0; n <= 40; n++) {
            counts *c = calloc(1, sizeof *c);
            CHECK(c != NULL);
            if (!c) return 1;
            gr_parallel_for(n, threads, count_job, c);
            for (int i = 0; i < 64; i++)
                CHECK_MSG(atomic_load(&c->hits[i]) == (i < n ? 1 : 0), "threads %d, n %d: job %d ran %d times", threads, n,
                          i, atomic_load(&c->hits[i]));
            free(c);
        }
    CHECK(gr_parallel_threads(1) == 1);
    CHECK(gr_parallel_threads(3) == (3 < GR_PARALLEL_MAX ? 3 : GR_PARALLEL_MAX));
    CHECK(gr_parallel_threads(1000) == GR_PARALLEL_MAX);
    CHECK(gr_parallel_threads(-5) >= 1 && gr_parallel_threads(0) <= GR_PARALLEL_MAX);
    gr_parallel_for(3, 1, NULL, NULL); /* no function: nothing to do */
    /* two threads allowed: two jobs run at once */
    counts *c = calloc(1, sizeof *c);
    CHECK(c != NULL);
    if (c) {
        gr_parallel_for(2, 2, meet_job, c);
        CHECK_MSG(atomic_load(&c->overlap) == 2, "the two jobs overlapped in %d of 2", atomic_load(&c->overlap));
        free(c);
    }
    CHECK_DONE();
}
