/* LeakSanitizer against dynamic TLS (src/sanitize/default_options.c; docs/reliability.md,
 * "Sanitizers"): loads each module named on the command line; GR_DTLS_THREADS threads each
 * have every module keep a heap pointer in its dynamic TLS and then stay alive, blocked, until
 * the process exits (a live thread's dynamic TLS is what the leak check scans, as with Mesa's
 * rasterizer threads); the program leaks 77 bytes of its own. The leak check at exit must
 * report exactly those 77 bytes and must not crash in its tracer (test_dtls_leak.sh). With
 * hundreds of blocks some start 16 bytes past a page: GCC 12's interceptor misreads those. */
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_DTLS_THREADS 64
#define GR_DTLS_MAX_MODULES 16

typedef void *(*touch_fn)(void);

static touch_fn touches[GR_DTLS_MAX_MODULES];
static int ntouches;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t changed = PTHREAD_COND_INITIALIZER;
static int ready;
static void *volatile sink;

static void *worker(void *arg)
{
    (void)arg;
    for (int m = 0; m < ntouches; m++) touches[m]();
    pthread_mutex_lock(&lock);
    ready++;
    pthread_cond_broadcast(&changed);
    for (;;) pthread_cond_wait(&changed, &lock); /* alive until exit */
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc - 1 > GR_DTLS_MAX_MODULES) {
        fprintf(stderr, "dtls_main: at most %d modules\n", GR_DTLS_MAX_MODULES);
        return 2;
    }
    for (int i = 1; i < argc; i++) {
        void *h = dlopen(argv[i], RTLD_NOW | RTLD_LOCAL);
        void *sym = h ? dlsym(h, "gr_dtls_touch") : NULL;
        if (!sym) {
            fprintf(stderr, "dtls_main: %s: %s\n", argv[i], h ? "no gr_dtls_touch" : dlerror());
            return 2;
        }
        memcpy(&touches[ntouches++], &sym, sizeof sym);
    }
    for (int m = 0; m < ntouches; m++) touches[m]();
    for (int t = 0; t < GR_DTLS_THREADS; t++) {
        pthread_t th;
        if (pthread_create(&th, NULL, worker, NULL) != 0) {
            fprintf(stderr, "dtls_main: pthread_create failed\n");
            return 2;
        }
        pthread_detach(th);
    }
    pthread_mutex_lock(&lock);
    while (ready < GR_DTLS_THREADS) pthread_cond_wait(&changed, &lock);
    pthread_mutex_unlock(&lock);
    char *lost = malloc(77); /* the one leak the check must find */
    if (lost) lost[0] = 1;
    sink = lost;
    sink = NULL;
    printf("dtls_main: %d modules loaded, %d threads holding their TLS\n", ntouches, GR_DTLS_THREADS);
    fflush(stdout); /* the leak check ends the process by _exit */
    return 0;
}
