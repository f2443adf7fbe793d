/* The technique toolkit (toolkit.h). */
#include "realtime/toolkit.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "gl/gl.h"
#include "gl/glctx.h"

double gr_clock_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* ---- render targets ---------------------------------------------------------------------- */

void gr_target_release(gr_target *t)
{
    if (!t) return;
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    if (t->tex) glDeleteTextures(1, &t->tex);
    memset(t, 0, sizeof *t);
}

gr_status gr_target_ensure(gr_target *t, unsigned ifmt, int w, int h, int flags, const char *what, gr_error *err)
{
    if (t->tex && t->w == w && t->h == h && t->ifmt == ifmt) return GR_OK;
    gr_target_release(t);
    const int depth = (flags & GR_TARGET_DEPTH) != 0;
    const GLint filter = (flags & GR_TARGET_LINEAR) ? GL_LINEAR : GL_NEAREST;
    glGenTextures(1, &t->tex);
    glBindTexture(GL_TEXTURE_2D, t->tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, (GLenum)ifmt, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    if (depth || (flags & GR_TARGET_BLACK_BORDER)) {
        /* A shadow map stores nothing outside: border depth 1 = no caster = lit. A light pass
         * reads black outside the screen: taps that leave it add nothing (an edge clamp would
         * smear the border texels into streaks). */
        static const float one[4] = {1.0f, 1.0f, 1.0f, 1.0f}, black[4] = {0, 0, 0, 0};
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
        glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, depth ? one : black);
    } else {
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    if (depth) glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &t->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    if (depth) {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t->tex, 0);
        glDrawBuffer(GL_NONE);
        glReadBuffer(GL_NONE);
    } else {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->tex, 0);
    }
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    gr_status st = fs == GL_FRAMEBUFFER_COMPLETE
                       ? gr_gl_check(what, err)
                       : gr_fail(err, GR_E_GL, "%s (%dx%d): framebuffer incomplete (0x%04x)", what, w, h, (unsigned)fs);
    if (st != GR_OK) {
        gr_target_release(t);
        return st;
    }
    t->w = w;
    t->h = h;
    t->ifmt = ifmt;
    return GR_OK;
}

void gr_target_accumulate(const gr_target *t)
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->w, t->h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
}

/* ---- GPU pass timers --------------------------------------------------------------------- */

void gr_gl_timer_init(gr_gl_timer *t)
{
    memset(t, 0, sizeof *t);
    glGenQueries(GR_GL_TIMER_PASSES, t->queries);
    glGenQueries(GR_GL_TIMER_PASSES, t->prims);
    t->have_timer = 1; /* GL_TIME_ELAPSED is core since 3.3 */
}

void gr_gl_timer_reset(gr_gl_timer *t)
{
    t->used = 0;
    t->n = 0;
}

void gr_gl_timer_begin(gr_gl_timer *t, int pass)
{
    if (pass < 0 || pass >= GR_GL_TIMER_PASSES || !t->have_timer) return;
    glBeginQuery(GL_TIME_ELAPSED, t->queries[pass]);
    glBeginQuery(GL_PRIMITIVES_GENERATED, t->prims[pass]);
    if (pass + 1 > t->n) t->n = pass + 1;
    t->used |= 1u << pass;
}

void gr_gl_timer_end(gr_gl_timer *t)
{
    if (!t->have_timer) return;
    glEndQuery(GL_PRIMITIVES_GENERATED);
    glEndQuery(GL_TIME_ELAPSED);
}

long long gr_gl_timer_primitives(gr_gl_timer *t, int pass)
{
    if (!t->have_timer || pass < 0 || pass >= t->n || !(t->used & (1u << pass))) return -1;
    return gr_gl_query_result(t->prims[pass]);
}

long long gr_gl_query_result(unsigned query)
{
    GLuint64 v = 0;
    glGetQueryObjectui64v(query, GL_QUERY_RESULT, &v);
    return (long long)v;
}

long long gr_gl_timer_ns(gr_gl_timer *t, int pass)
{
    if (!t->have_timer || pass < 0 || pass >= t->n || !(t->used & (1u << pass))) return -1;
    return gr_gl_query_result(t->queries[pass]);
}

long long gr_gl_timer_ns_within(gr_gl_timer *t, int pass, double wall_ns)
{
    long long ns = gr_gl_timer_ns(t, pass);
    return (ns >= 0 && (double)ns <= wall_ns) ? ns : -1;
}

void gr_gl_timer_free(gr_gl_timer *t)
{
    if (t->queries[0]) glDeleteQueries(GR_GL_TIMER_PASSES, t->queries);
    if (t->prims[0]) glDeleteQueries(GR_GL_TIMER_PASSES, t->prims);
    memset(t, 0, sizeof *t);
}

void gr_gl_timer_stats(gr_technique_stats *stats, gr_gl_timer *t, const char *const *names, int n, double t0_ms)
{
    memset(stats, 0, sizeof *stats);
    const double wall_ns = (gr_clock_ms() - t0_ms) * 1e6;
    if (n > GR_TECH_MAX_PASSES) n = GR_TECH_MAX_PASSES;
    stats->n_passes = n;
    for (int p = 0; p < n; p++) {
        snprintf(stats->pass_names[p], sizeof stats->pass_names[p], "%s", names[p]);
        stats->gpu_ns[p] = gr_gl_timer_ns_within(t, p, wall_ns);
    }
    for (int p = 0; p < GR_TECH_MAX_PASSES; p++) gr_pass_cost_clear(&stats->cost[p]);
    for (int p = 0; p < n; p++) {
        long long prims = gr_gl_timer_primitives(t, p);
        if (prims >= 0) gr_technique_cost_set(stats, p, GR_COST_PRIMITIVES, prims, 1);
    }
    stats->fragments = -1;
    stats->wall_ms = gr_clock_ms() - t0_ms;
}
