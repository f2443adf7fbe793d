/* common/parallel.h: every job index runs exactly once, whatever the thread count asked for
 * (1 .. 8, 0 = the online processors) and the number of jobs (0 .. 40, fewer or more than the
 * threads); the thread count is clamped to [1, GR_PARALLEL_MAX]; and jobs do run side by side
 * when more than one thread is allowed (two jobs that wait for each other finish); and
 * gr_parallel_try runs every job and reports the first failure in index order, whatever job
 * fails first in time. */
#include <stdatomic.h>
#include <string.h>
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

/* Jobs 5 and 9 fail (9 at once, 5 after a pause, so that 9 usually fails first in time). */
static gr_status fail_job(void *arg, int i, gr_error *err)
{
    counts *c = arg;
    atomic_fetch_add(&c->hits[i], 1);
    if (i == 5) nanosleep(&(struct timespec){0, 20000000}, NULL);
    if (i == 5 || i == 9) return gr_fail(err, i == 5 ? GR_E_INPUT : GR_E_NOMEM, "job %d failed", i);
    return GR_OK;
}

static gr_status ok_job(void *arg, int i, gr_error *err)
{
    (void)err;
    counts *c = arg;
    atomic_fetch_add(&c->hits[i], 1);
    return GR_OK;
}

int main(void)
{
    for (int threads = 1; threads <= 4; threads++) {
        counts *c = calloc(1, sizeof *c);
        CHECK(c != NULL);
        if (!c) return 1;
        gr_error err = {GR_OK, ""};
        gr_status st = gr_parallel_try(12, threads, fail_job, c, &err);
        CHECK_MSG(st == GR_E_INPUT && strcmp(err.msg, "job 5 failed") == 0, "threads %d: status %d, '%s'", threads,
                  (int)st, err.msg);
        for (int i = 0; i < 12; i++) CHECK(atomic_load(&c->hits[i]) == 1);
        memset(c, 0, sizeof *c);
        err = (gr_error){GR_OK, ""};
        CHECK(gr_parallel_try(7, threads, ok_job, c, &err) == GR_OK && err.msg[0] == 0);
        for (int i = 0; i < 7; i++) CHECK(atomic_load(&c->hits[i]) == 1);
        free(c);
    }
    CHECK(gr_parallel_try(0, 2, ok_job, NULL, NULL) == GR_OK);
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
