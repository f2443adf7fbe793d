/* Warm timing (timing.h). */
#include "realtime/timing.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int gr_timing_is_cpu_renderer(const char *r)
{
    return !r || strstr(r, "llvmpipe") || strstr(r, "softpipe") || strstr(r, "swrast");
}

/* The q-quantile of sorted v[0..n) by linear interpolation between order statistics. */
static double quantile(const double *v, int n, double q)
{
    double pos = q * (double)(n - 1);
    int i = (int)pos;
    if (i >= n - 1) return v[n - 1];
    return v[i] + (pos - (double)i) * (v[i + 1] - v[i]);
}

void gr_timing_from_stats(const gr_technique_stats *all, int n, const char *renderer, gr_timing *res)
{
    memset(res, 0, sizeof *res);
    res->n = n;
    snprintf(res->renderer, sizeof res->renderer, "%s", renderer ? renderer : "unknown");
    res->hardware = !gr_timing_is_cpu_renderer(renderer);
    gr_technique_stats_median(all, n, &res->median);
    double *w = malloc((size_t)n * sizeof *w), *g = malloc((size_t)n * sizeof *g);
    res->wall_ms = res->wall_min_ms = res->wall_max_ms = res->wall_q1_ms = res->wall_q3_ms = res->median.wall_ms;
    res->gpu_ms = res->gpu_min_ms = res->gpu_max_ms = -1;
    if (w && g) {
        int ng = 0;
        for (int i = 0; i < n; i++) {
            w[i] = all[i].wall_ms;
            double s = gr_technique_stats_gpu_ms(&all[i]);
            if (s >= 0) g[ng++] = s;
        }
        qsort(w, (size_t)n, sizeof *w, cmp_double);
        res->wall_ms = w[n / 2]; /* the upper middle, as gr_technique_stats_median */
        res->wall_min_ms = w[0];
        res->wall_max_ms = w[n - 1];
        res->wall_q1_ms = quantile(w, n, 0.25);
        res->wall_q3_ms = quantile(w, n, 0.75);
        if (ng == n) { /* every render timed: else a sum of some passes would read as the frame's */
            qsort(g, (size_t)ng, sizeof *g, cmp_double);
            res->gpu_ms = g[ng / 2];
            res->gpu_min_ms = g[0];
            res->gpu_max_ms = g[ng - 1];
        }
    }
    free(w);
    free(g);
    res->cost_ms = res->hardware && res->gpu_ms >= 0 ? res->gpu_ms : res->wall_ms;
}

gr_status gr_timing_measure(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out, int warmup,
                            int n, gr_timing *res, gr_error *err)
{
    return gr_timing_measure_capped(t, scene, settings, out, warmup, n, 0, res, err);
}

gr_status gr_timing_measure_capped(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out,
                                   int warmup, int n, double cap_s, gr_timing *res, gr_error *err)
{
    if (n < 1 || n > GR_TIMING_MAX_REPEAT || warmup < 0 || warmup > GR_TIMING_MAX_REPEAT)
        return gr_fail(err, GR_E_INPUT, "timing: %d renders after %d warm-ups (1..%d timed)", n, warmup,
                       GR_TIMING_MAX_REPEAT);
    gr_technique_stats *all = malloc((size_t)n * sizeof *all);
    if (!all) return gr_fail(err, GR_E_NOMEM, "timing: out of memory");
    gr_status st = GR_OK;
    int done = 0;
    double spent_ms = 0;
    for (int k = 0; st == GR_OK && k < warmup; k++) {
        st = gr_technique_render(t, scene, settings, out, &all[0], err);
        if (st == GR_OK && cap_s > 0 && all[0].wall_ms >= 1e3 * cap_s * GR_TIMING_LONG_CAPS) {
            done = n = 1; /* a long warm-up is the measurement (timing.h) */
            warmup = 0;
        }
    }
    for (; st == GR_OK && done < n; done++) {
        if (cap_s > 0 && done > 0 && spent_ms >= 1e3 * cap_s) break;
        st = gr_technique_render(t, scene, settings, out, &all[done], err);
        spent_ms += all[done].wall_ms;
    }
    if (st == GR_OK) {
        gr_timing_from_stats(all, done, gr_gl_renderer(gr_technique_gl(t)), res);
        res->warmup = warmup;
    }
    free(all);
    return st;
}

void gr_timing_text(const gr_timing *t, char *buf, size_t n)
{
    const int gpu = t->hardware && t->gpu_ms >= 0;
    snprintf(buf, n, "%.3f ms %s (median of %d after %d warm-up%s; %.3f-%.3f)", t->cost_ms,
             gpu ? "GPU" : "wall", t->n, t->warmup, t->warmup == 1 ? "" : "s", gpu ? t->gpu_min_ms : t->wall_min_ms,
             gpu ? t->gpu_max_ms : t->wall_max_ms);
}
