#include "common/parallel.h"

#include <pthread.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <unistd.h>

int gr_parallel_threads(int want)
{
    if (want <= 0) {
        long c = sysconf(_SC_NPROCESSORS_ONLN);
        want = c > 0 ? (int)(c < GR_PARALLEL_MAX ? c : GR_PARALLEL_MAX) : 1;
    }
    return want < 1 ? 1 : want > GR_PARALLEL_MAX ? GR_PARALLEL_MAX : want;
}

typedef struct pjob {
    void (*fn)(void *ctx, int i);
    void *ctx;
    int n;
    atomic_int next; /* the next index to take */
} pjob;

static void *worker(void *arg)
{
    pjob *j = arg;
    for (int i; (i = atomic_fetch_add(&j->next, 1)) < j->n;) j->fn(j->ctx, i);
    return NULL;
}

void gr_parallel_for(int n, int threads, void (*fn)(void *ctx, int i), void *ctx)
{
    if (n <= 0 || !fn) return;
    int t = gr_parallel_threads(threads);
    if (t > n) t = n;
    pjob j = {fn, ctx, n, 0};
    pthread_t th[GR_PARALLEL_MAX];
    int started = 0;
    for (int k = 1; k < t; k++)
        if (pthread_create(&th[started], NULL, worker, &j) == 0) started++;
    worker(&j);
    for (int k = 0; k < started; k++) pthread_join(th[k], NULL);
}

typedef struct tjob {
    gr_status (*fn)(void *ctx, int i, gr_error *err);
    void *ctx;
    gr_status *st;
    gr_error *err;
} tjob;

static void try_one(void *arg, int i)
{
    tjob *t = arg;
    t->err[i] = (gr_error){GR_OK, ""};
    t->st[i] = t->fn(t->ctx, i, &t->err[i]);
}

gr_status gr_parallel_try(int n, int threads, gr_status (*fn)(void *ctx, int i, gr_error *err), void *ctx,
                          gr_error *err)
{
    if (n <= 0 || !fn) return GR_OK;
    tjob t = {fn, ctx, calloc((size_t)n, sizeof *t.st), calloc((size_t)n, sizeof *t.err)};
    gr_status st = GR_OK;
    if (!t.st || !t.err) {
        st = gr_fail(err, GR_E_NOMEM, "out of memory for %d jobs", n);
    } else {
        gr_parallel_for(n, threads, try_one, &t);
        for (int i = 0; i < n && st == GR_OK; i++)
            if ((st = t.st[i]) != GR_OK && err) *err = t.err[i];
    }
    free(t.st);
    free(t.err);
    return st;
}
