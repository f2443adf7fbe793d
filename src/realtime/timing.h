/* Warm timing of a technique: the ONE way a command times renders (`render --repeat`, `run
 * --repeat`, `pareto`, the budget table of `pareto --suite --tune`). Warm-up render(s) first
 * (buffers made for a new size, shader JIT, llvmpipe's first timer query: none of it is the
 * frame's cost), then the median of n timed renders of the same settings in one context, with
 * their spread (min, max, quartiles) and the renderer (GL_RENDERER) that timed them. Per-pass
 * GPU times come from the GL timer queries where they exist (a hardware GPU: the cost that
 * stands for the frame; on llvmpipe the wall time does). docs/tuning.md "Warm timing". */
#ifndef GR_TIMING_H
#define GR_TIMING_H

#include "common/status.h"
#include "realtime/technique.h"

#define GR_TIMING_MAX_REPEAT 100000

typedef struct gr_timing {
    int warmup, n;                /* renders not timed, renders timed */
    gr_technique_stats median;    /* per-figure median of the timed renders (per-pass GPU ns, wall) */
    double wall_ms, wall_min_ms, wall_max_ms, wall_q1_ms, wall_q3_ms; /* median and spread */
    double gpu_ms, gpu_min_ms, gpu_max_ms; /* summed GL pass timers: median and spread; -1 unknown */
    int hardware;                 /* 1: a hardware GPU (not llvmpipe/softpipe): gpu_ms is the cost */
    double cost_ms;               /* what a frame costs: gpu_ms on a hardware GPU with timers, else wall_ms */
    char renderer[128];           /* GL_RENDERER */
} gr_timing;

/* 1 when the renderer string names a CPU rasterizer (llvmpipe, softpipe, swrast). */
int gr_timing_is_cpu_renderer(const char *renderer);

/* warmup renders, then n (>= 1) timed renders of t at (scene, settings: NULL = the scene's own)
 * into out; the timed renders' figures into *res (its median stats per pass). The image left in
 * out is the last render's. GR_E_INPUT for n out of [1, GR_TIMING_MAX_REPEAT]; the render's
 * status otherwise. */
gr_status gr_timing_measure(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out, int warmup,
                            int n, gr_timing *res, gr_error *err);

/* As gr_timing_measure, but the timed renders stop early, once they took cap_s seconds of wall
 * time together (cap_s <= 0: no cap): a render of several seconds on a CPU rasterizer is timed
 * once after its warm-up instead of n times. At least one render is timed; res->n states how
 * many were (docs/tuning.md "Warm timing"). A warm-up render that alone took
 * GR_TIMING_LONG_CAPS x cap_s or more is itself the one timed render (res->warmup = 0, res->n =
 * 1): the first-use costs a warm-up removes (shader compiles, allocations: milliseconds) are
 * then under a percent of it, and a 100 s render on a CPU rasterizer is not rendered twice. */
#define GR_TIMING_LONG_CAPS 5
gr_status gr_timing_measure_capped(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out,
                                   int warmup, int n, double cap_s, gr_timing *res, gr_error *err);

/* Median and spread of already measured stats (all[0..n)): what gr_timing_measure fills after
 * its renders, for callers that render themselves. */
void gr_timing_from_stats(const gr_technique_stats *all, int n, const char *renderer, gr_timing *res);

/* "12.3 ms (median of 5 after 1 warm-up; 11.9-13.0)" into buf: the cost and its spread. */
void gr_timing_text(const gr_timing *t, char *buf, size_t n);

#endif
