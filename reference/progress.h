/* Progress of a long step on stderr, once it has lasted a couple of seconds (short runs and
 * tests stay silent) and only when enabled (--quiet disables it). On a terminal: a one-line
 * bar with the ETA, redrawn in place. Not on a terminal (a pipe, a CI log, a build farm): one
 * whole line per 10 % or per 10 s, whichever comes first, "LABEL:  40%  elapsed 00:12
 * remaining 00:18  NOTE". Call from one thread. */
#ifndef GR_REF_PROGRESS_H
#define GR_REF_PROGRESS_H

typedef struct gr_progress gr_progress;

/* enabled = 0 (e.g. --quiet) gives a progress object that never prints. NULL on no memory. */
gr_progress *gr_progress_create(const char *label, int enabled);
/* fraction in [0, 1] of the whole job; redraws at most ~10 times a second. */
void gr_progress_update(gr_progress *p, double fraction, const char *note);
/* Clears the line if anything was drawn. */
void gr_progress_finish(gr_progress *p);
void gr_progress_destroy(gr_progress *p); /* accepts NULL */
/* Seconds since creation. */
double gr_progress_elapsed(const gr_progress *p);

#endif
