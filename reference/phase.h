/* Per-phase wall and CPU time of a render, and its serial part (internal to reference/;
 * docs/reference.md 3, "Phases"). The render is always in exactly one phase; switching
 * charges the time since the last switch to the phase left. Every parallel region (the pool's
 * runs, the beam builds' jobs) adds the wall time during which at least two of its threads
 * were busy to `par_total`; a phase's serial time is its wall time minus that part, i.e. the
 * time with at most one thread busy (Amdahl's serial fraction, measured, not modelled). */
#ifndef GR_REF_PHASE_H
#define GR_REF_PHASE_H

enum { REF_PH_BEAMS, REF_PH_GRID, REF_PH_PILOT, REF_PH_MARCH, REF_PH_PROBE, REF_PH_STATS, REF_PH_OTHER, REF_PH_COUNT };

typedef struct gr_ref_phases {
    double wall_s[REF_PH_COUNT], cpu_s[REF_PH_COUNT], par_s[REF_PH_COUNT];
    double par_total;   /* time with >= 2 threads busy so far, summed by every parallel region */
    int cur, on;
    double w0, c0, p0;  /* the clocks at the last switch */
} gr_ref_phases;

/* The phases' names as the metadata spells them (godrays:phase.NAME.*): gr_ref_phase_names in
 * reference/integrator.h (GR_REF_PHASES = REF_PH_COUNT). */

/* Process CPU time (all threads), seconds. */
double gr_ref_cpu_s(void);
/* Zeroed, then in `phase`. */
void gr_ref_phases_start(gr_ref_phases *p, int phase);
/* Charges the time since the last switch to the current phase and enters `phase`; returns
 * the phase left (to switch back to). No-op (returns `phase`) when not started. */
int gr_ref_phases_switch(gr_ref_phases *p, int phase);
/* Moves wall, CPU and parallel time from one phase to another (a part measured inside
 * another phase's span, e.g. the lookup grid inside a beam build). */
void gr_ref_phases_move(gr_ref_phases *p, int from, int to, double wall, double cpu, double par);
/* The time during which at least two of the n intervals [t0[i], t1[i]) overlap. */
double gr_ref_overlap_s(const double *t0, const double *t1, int n);

#endif
