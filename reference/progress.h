/* A one-line progress bar with ETA on stderr, for long renders. It shows only when enabled,
 * stderr is a terminal, and the run has lasted longer than a couple of seconds, so short
 * runs, pipes, logs and tests stay silent. Call from one thread. */
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
