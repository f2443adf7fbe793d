/* The progress of a long step (progress.h). */
#include "reference/progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define GR_PROGRESS_DELAY_S 2.0 /* stay silent for runs shorter than this */

#define GR_PROGRESS_LINE_S 10.0 /* not a terminal: a line at least this often ... */
#define GR_PROGRESS_LINE_STEP 0.1 /* ... and at every 10 % */

struct gr_progress {
    char label[64];
    int enabled, drawn;
    int lines;           /* stderr is no terminal (a pipe, a CI log): whole lines, no bar */
    double t0, last;
    double line_t, line_f; /* lines mode: when, and at what fraction, the last line was */
};

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

gr_progress *gr_progress_create(const char *label, int enabled)
{
    gr_progress *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "");
    p->enabled = enabled != 0;
    p->lines = !isatty(STDERR_FILENO);
    p->t0 = mono_s();
    p->line_t = p->t0;
    p->last = -1.0;
    return p;
}

double gr_progress_elapsed(const gr_progress *p) { return p ? mono_s() - p->t0 : 0.0; }

static void fmt_time(char *buf, size_t n, double s)
{
    if (!(s >= 0.0) || s > 359999.0) { snprintf(buf, n, "--:--"); return; }
    int t = (int)(s + 0.5);
    if (t >= 3600) snprintf(buf, n, "%d:%02d:%02d", t / 3600, (t / 60) % 60, t % 60);
    else snprintf(buf, n, "%02d:%02d", t / 60, t % 60);
}

void gr_progress_update(gr_progress *p, double fraction, const char *note)
{
    if (!p || !p->enabled) return;
    double now = mono_s(), el = now - p->t0;
    if (p->lines) {
        /* a pipe or a log (issue 29): one line per 10 % or per 10 s, whichever comes first */
        if (!(fraction >= 0.0)) fraction = 0.0;
        if (fraction > 1.0) fraction = 1.0;
        int step = (int)(fraction / GR_PROGRESS_LINE_STEP + 1e-9) > (int)(p->line_f / GR_PROGRESS_LINE_STEP + 1e-9);
        if (el < GR_PROGRESS_DELAY_S || (!step && now - p->line_t < GR_PROGRESS_LINE_S) || fraction >= 1.0) return;
        char e[32], r[32];
        fmt_time(e, sizeof e, el);
        fmt_time(r, sizeof r, fraction > 0.0 ? el * (1.0 - fraction) / fraction : -1.0);
        fprintf(stderr, "%s: %3.0f%%  elapsed %s  remaining %s%s%s\n", p->label, 100.0 * fraction, e, r,
                note && note[0] ? "  " : "", note ? note : "");
        fflush(stderr);
        p->line_t = now;
        p->line_f = fraction;
        return;
    }
    if (el < GR_PROGRESS_DELAY_S || now - p->last < 0.1) return;
    p->last = now;
    if (!(fraction >= 0.0)) fraction = 0.0;
    if (fraction > 1.0) fraction = 1.0;
    enum { W = 30 };
    char bar[W + 1];
    int full = (int)(fraction * W);
    for (int i = 0; i < W; i++) bar[i] = i < full ? '#' : '.';
    bar[W] = '\0';
    char e[32], r[32];
    fmt_time(e, sizeof e, el);
    fmt_time(r, sizeof r, fraction > 0.0 ? el * (1.0 - fraction) / fraction : -1.0);
    fprintf(stderr, "\r%s [%s] %5.1f%%  elapsed %s  ETA %s  %s\033[K", p->label, bar, 100.0 * fraction, e, r,
            note ? note : "");
    fflush(stderr);
    p->drawn = 1;
}

void gr_progress_finish(gr_progress *p)
{
    if (!p || !p->drawn) return;
    fprintf(stderr, "\r\033[K");
    fflush(stderr);
    p->drawn = 0;
}

void gr_progress_destroy(gr_progress *p)
{
    if (!p) return;
    gr_progress_finish(p);
    free(p);
}
