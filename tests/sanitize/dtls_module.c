/* A module with GR_TLS_WORDS pointers of thread-local storage, loaded by dtls_main.c: a
 * dlopen'ed library's TLS is dynamic, one malloc'd block per thread (tests/sanitize/). */
#include <stdlib.h>

static __thread void *words[GR_TLS_WORDS];

void *gr_dtls_touch(void);
void *gr_dtls_touch(void)
{
    /* reachable only through this thread's dynamic TLS block: not a leak */
    words[0] = malloc(32);
    words[GR_TLS_WORDS - 1] = words[0];
    return words;
}
