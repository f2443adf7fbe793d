#include "reference/phase.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "reference/integrator.h"
#include "reference/pool.h"

_Static_assert(GR_REF_PHASES == REF_PH_COUNT, "reference/integrator.h names every phase");

const char *const gr_ref_phase_names[GR_REF_PHASES] = {"beams", "grid", "pilot", "march", "probe", "stats", "other"};

double gr_ref_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void gr_ref_phases_start(gr_ref_phases *p, int phase)
{
    memset(p, 0, sizeof *p);
    p->on = 1;
    p->cur = phase;
    p->w0 = gr_ref_mono_s();
    p->c0 = gr_ref_cpu_s();
}

int gr_ref_phases_switch(gr_ref_phases *p, int phase)
{
    if (!p || !p->on) return phase;
    double w = gr_ref_mono_s(), c = gr_ref_cpu_s();
    int prev = p->cur;
    p->wall_s[prev] += w - p->w0;
    p->cpu_s[prev] += c - p->c0;
    p->par_s[prev] += p->par_total - p->p0;
    p->w0 = w;
    p->c0 = c;
    p->p0 = p->par_total;
    p->cur = phase;
    return prev;
}

void gr_ref_phases_move(gr_ref_phases *p, int from, int to, double wall, double cpu, double par)
{
    if (!p || !p->on) return;
    p->wall_s[from] -= wall; p->wall_s[to] += wall;
    p->cpu_s[from] -= cpu; p->cpu_s[to] += cpu;
    p->par_s[from] -= par; p->par_s[to] += par;
}

typedef struct ev { double t; int d; } ev;
static int cmp_ev(const void *a, const void *b)
{
    const ev *x = a, *y = b;
    if (x->t != y->t) return (x->t > y->t) - (x->t < y->t);
    return x->d - y->d; /* ends before starts at the same instant */
}

double gr_ref_overlap_s(const double *t0, const double *t1, int n)
{
    if (n < 2) return 0.0;
    ev *e = malloc((size_t)n * 2 * sizeof *e);
    if (!e) return 0.0; /* unmeasured: counted as serial (the conservative side) */
    int m = 0;
    for (int i = 0; i < n; i++) {
        if (!(t1[i] > t0[i])) continue;
        e[m++] = (ev){t0[i], 1};
        e[m++] = (ev){t1[i], -1};
    }
    qsort(e, (size_t)m, sizeof *e, cmp_ev);
    double s = 0.0;
    int busy = 0;
    for (int i = 0; i < m; i++) {
        if (busy >= 2 && i > 0) s += e[i].t - e[i - 1].t;
        busy += e[i].d;
    }
    free(e);
    return s;
}
