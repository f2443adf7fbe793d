#include "reference/pool.h"

#include <stdlib.h>

#include "reference/phase.h"
#include <time.h>
#if defined(__SSE2__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

typedef struct gr_ref_pool gr_ref_pool;
typedef struct pool_call {
    void *(*fn)(void *);
    void *arg;
    double t0, t1; /* this worker's start and end (the serial part: gr_ref_overlap_s) */
    gr_ref_pool *pool;
} pool_call;

struct gr_ref_pool {
    int threads;
    pthread_t *th;
    pool_call *calls;
    /* the workers that ended, signalled as each ends: the caller wakes at the last one, not
     * at its next poll (a poll's sleep after the last worker is time with no thread busy) */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int ended;
};


double gr_ref_mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Every worker thread: flush denormals, so deep, murky water does not slow down (hard case
 * sigma_t = 20 /m). */
static void flush_denormals(void)
{
#if defined(__SSE2__)
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
}

static void *pool_main(void *arg)
{
    pool_call *c = arg;
    c->t0 = gr_ref_mono_s();
    flush_denormals();
    void *ret = c->fn(c->arg);
    c->t1 = gr_ref_mono_s();
    pthread_mutex_lock(&c->pool->mu);
    c->pool->ended++;
    pthread_cond_signal(&c->pool->cv);
    pthread_mutex_unlock(&c->pool->mu);
    return ret;
}

void gr_ref_work_init(gr_ref_work *w, int row0)
{
    atomic_init(&w->next_row, row0);
    atomic_init(&w->rows_done, 0);
    atomic_init(&w->stop, 0);
    atomic_init(&w->queries, 0);
    atomic_init(&w->shadow_rays, 0);
    atomic_init(&w->max_hits, 0);
    w->par_s = 0.0;
}

gr_ref_pool *gr_ref_pool_create(int threads)
{
    gr_ref_pool *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    p->threads = threads > 0 ? threads : 1;
    p->th = calloc((size_t)p->threads, sizeof *p->th);
    p->calls = calloc((size_t)p->threads, sizeof *p->calls);
    if (!p->th || !p->calls || pthread_mutex_init(&p->mu, NULL) != 0) {
        free(p->th);
        free(p->calls);
        free(p);
        return NULL;
    }
    if (pthread_cond_init(&p->cv, NULL) != 0) {
        pthread_mutex_destroy(&p->mu);
        free(p->th);
        free(p->calls);
        free(p);
        return NULL;
    }
    return p;
}

void gr_ref_pool_destroy(gr_ref_pool *p)
{
    if (!p) return;
    pthread_cond_destroy(&p->cv);
    pthread_mutex_destroy(&p->mu);
    free(p->th);
    free(p->calls);
    free(p);
}

gr_status gr_ref_pool_run(gr_ref_pool *p, void *(*fn)(void *), void *arg, gr_ref_work *w, int rows,
                          volatile sig_atomic_t *interrupt, gr_progress *prog, double frac0, double span,
                          const char *note, gr_error *err)
{
    int started = 0;
    p->ended = 0;
    for (int i = 0; i < p->threads; i++) {
        p->calls[i] = (pool_call){fn, arg, 0.0, 0.0, p};
        if (pthread_create(&p->th[i], NULL, pool_main, &p->calls[i]) != 0) break;
        started++;
    }
    if (!started)
        return gr_fail(err, GR_E_RUNTIME, "reference: could not start worker threads (reference.threads = %d)", p->threads);
    for (;;) {
        int done = atomic_load(&w->rows_done);
        gr_progress_update(prog, frac0 + span * (double)done / rows, note);
        if (done >= rows || atomic_load(&w->stop) || (interrupt && *interrupt)) break;
        /* wait for the workers to end, waking every 20 ms (the bar, a stop, Ctrl-C) */
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 20 * 1000 * 1000;
        if (ts.tv_nsec >= 1000000000L) { ts.tv_sec++; ts.tv_nsec -= 1000000000L; }
        pthread_mutex_lock(&p->mu);
        int all = p->ended >= started;
        if (!all) pthread_cond_timedwait(&p->cv, &p->mu, &ts);
        all = p->ended >= started;
        pthread_mutex_unlock(&p->mu);
        if (all) break;
    }
    for (int i = 0; i < started; i++) pthread_join(p->th[i], NULL);
    {
        double a[64], b[64]; /* the workers' spans; past 64 threads the first 64 (an underestimate) */
        int n = started < 64 ? started : 64;
        for (int i = 0; i < n; i++) { a[i] = p->calls[i].t0; b[i] = p->calls[i].t1; }
        w->par_s = gr_ref_overlap_s(a, b, n);
    }
    if (atomic_load(&w->stop) == 2) return gr_fail(err, GR_E_NOMEM, "reference: out of memory in a worker thread");
    return GR_OK;
}
