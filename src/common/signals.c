/* SIGINT/SIGTERM for the whole command (signals.h). */
#include "common/signals.h"

#include <limits.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define TEMP_NAME_MAX 4352

static volatile sig_atomic_t g_flag = 0;   /* the signal received (0: none) */
static atomic_int g_hold = 0;              /* depth of held regions */
static atomic_int g_defer = 0;             /* depth of deferred regions */
static atomic_int g_handled = 0;           /* a held region saw the signal: the command ends itself */
/* Temporary files: a slot is 0 free, 1 being filled, 2 live (the handler unlinks live ones). */
static atomic_int g_used[GR_SIGNALS_MAX_TEMPS];
static char g_names[GR_SIGNALS_MAX_TEMPS][TEMP_NAME_MAX];

static void remove_temps(void)
{
    for (int i = 0; i < GR_SIGNALS_MAX_TEMPS; i++)
        if (atomic_load(&g_used[i]) == 2) unlink(g_names[i]);
}

static void die(int sig)
{
    remove_temps();
    _exit(128 + sig);
}

static void on_signal(int sig)
{
    if (g_flag) die(sig); /* the second signal ends the process at once */
    g_flag = sig;
    if (atomic_load(&g_hold) > 0 || atomic_load(&g_defer) > 0) return;
    die(sig);
}

void gr_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

volatile sig_atomic_t *gr_signals_flag(void) { return &g_flag; }
int gr_signals_pending(void) { return (int)g_flag; }

void gr_signals_hold_begin(void) { atomic_fetch_add(&g_hold, 1); }

void gr_signals_hold_end(void)
{
    if (g_flag) atomic_store(&g_handled, 1);
    atomic_fetch_sub(&g_hold, 1);
}

void gr_signals_defer_begin(void) { atomic_fetch_add(&g_defer, 1); }

void gr_signals_defer_end(void)
{
    if (atomic_fetch_sub(&g_defer, 1) == 1 && g_flag && atomic_load(&g_hold) == 0 && !atomic_load(&g_handled)) {
        fflush(stdout);
        fflush(stderr);
        die((int)g_flag);
    }
}

int gr_signals_add_temp(const char *path)
{
    if (!path || strlen(path) >= TEMP_NAME_MAX) return -1;
    for (int i = 0; i < GR_SIGNALS_MAX_TEMPS; i++) {
        int expect = 0;
        if (atomic_compare_exchange_strong(&g_used[i], &expect, 1)) {
            memcpy(g_names[i], path, strlen(path) + 1);
            atomic_store(&g_used[i], 2);
            return i;
        }
    }
    return -1;
}

void gr_signals_remove_temp(int slot)
{
    if (slot >= 0 && slot < GR_SIGNALS_MAX_TEMPS) atomic_store(&g_used[slot], 0);
}
