/* SIGINT and SIGTERM for a whole godrays command (docs/reliability.md, "Signals").
 *
 * gr_signals_install (main, before any command) handles both signals for the process:
 *  - in a held region (gr_signals_hold_begin/end: a render that polls gr_signals_flag and
 *    stops at its next check), a first signal only sets the flag; the command keeps what its
 *    docs promise (a partial EXR, or nothing cached) and ends with GR_E_INTERRUPTED;
 *  - while an output file is being written (gr_signals_defer_begin/end, used by
 *    common/outfile), the signal waits until the file is in place or removed;
 *  - anywhere else, and on a second signal, the registered temporary files are removed and
 *    the process ends at once with 128 + the signal number (130 for SIGINT, 143 for SIGTERM).
 * The handler only calls async-signal-safe functions (unlink, write, _exit). */
#ifndef GR_SIGNALS_H
#define GR_SIGNALS_H

#include <signal.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GR_SIGNALS_MAX_TEMPS 64

void gr_signals_install(void);
/* The flag a render polls: 0, or the number of the signal received. A cheap volatile read. */
volatile sig_atomic_t *gr_signals_flag(void);
/* The signal received so far (0: none). */
int gr_signals_pending(void);

void gr_signals_hold_begin(void);
/* Ends a held region; a signal received in it counts as handled by the command. */
void gr_signals_hold_end(void);

void gr_signals_defer_begin(void);
/* Ends a deferred region; a signal that arrived in it and that no held region handles now
 * removes the temporary files and ends the process (128 + signal). */
void gr_signals_defer_end(void);

/* Registers a temporary file to remove on a fatal signal; returns its slot, or -1 when the
 * registry is full (the file is then not removed on a signal). */
int gr_signals_add_temp(const char *path);
void gr_signals_remove_temp(int slot);

#ifdef __cplusplus
}
#endif
#endif
