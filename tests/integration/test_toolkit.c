/* The technique toolkit (src/realtime/toolkit.c, readback.c) against what GL itself reports:
 * - a render target is made once per size and format (the same texture name while they stay),
 *   remade on a change, left empty with GR_E_GL when its framebuffer cannot be complete (a
 *   depth format on the colour attachment);
 * - its sampling state is the one asked for (depth: border depth 1, compare off; black
 *   border; edge clamp), read back from GL;
 * - gr_target_accumulate leaves the target bound with its viewport, cleared to zero, and
 *   additive blending on (GL's own state queries are the oracle);
 * - gr_readback_rgb puts GL row 0 (the bottom) last in the image, values as cleared, and
 *   counts non-finite values;
 * - timers: an untimed pass and a figure longer than the wall time read -1; stats copy the
 *   names, leave fragments -1 and a non-negative wall time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gl/gl.h"
#include "realtime/readback.h"
#include "realtime/toolkit.h"

static void check_wrap(unsigned tex, GLint wrap, float border)
{
    GLint ws = 0, wt = 0;
    float bc[4] = {-1, -1, -1, -1};
    glBindTexture(GL_TEXTURE_2D, tex);
    glGetTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, &ws);
    glGetTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, &wt);
    glGetTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, bc);
    glBindTexture(GL_TEXTURE_2D, 0);
    CHECK(ws == wrap && wt == wrap);
    if (wrap == GL_CLAMP_TO_BORDER)
        for (int c = 0; c < 4; c++) CHECK(bc[c] == border);
}

int main(void)
{
    gr_error err;
    gr_gl *gl = NULL;
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    if (!gl) CHECK_DONE();
    double c0 = gr_clock_ms(), c1 = gr_clock_ms();
    CHECK(c1 >= c0);

    /* ---- targets: made once, remade on a change ---- */
    gr_target t = {0};
    CHECK_OK(gr_target_ensure(&t, GL_RGBA32F, 7, 5, 0, "test target", &err), err);
    CHECK(t.tex != 0 && t.fbo != 0 && t.w == 7 && t.h == 5 && t.ifmt == GL_RGBA32F);
    unsigned first = t.tex;
    CHECK_OK(gr_target_ensure(&t, GL_RGBA32F, 7, 5, 0, "test target", &err), err);
    CHECK(t.tex == first); /* nothing changed: the same texture */
    CHECK_OK(gr_target_ensure(&t, GL_RGBA16F, 7, 5, 0, "test target", &err), err);
    CHECK(t.ifmt == GL_RGBA16F && t.tex != 0);
    CHECK_OK(gr_target_ensure(&t, GL_RGBA32F, 6, 4, 0, "test target", &err), err);
    CHECK(t.w == 6 && t.h == 4 && t.ifmt == GL_RGBA32F);
    check_wrap(t.tex, GL_CLAMP_TO_EDGE, 0);
    GLint filt = 0;
    glBindTexture(GL_TEXTURE_2D, t.tex);
    glGetTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, &filt);
    glBindTexture(GL_TEXTURE_2D, 0);
    CHECK(filt == GL_NEAREST);

    gr_target d = {0}, lb = {0}, bad = {0};
    CHECK_OK(gr_target_ensure(&d, GL_DEPTH_COMPONENT32F, 8, 8, GR_TARGET_DEPTH, "depth", &err), err);
    check_wrap(d.tex, GL_CLAMP_TO_BORDER, 1.0f);
    GLint cmp = -1;
    glBindTexture(GL_TEXTURE_2D, d.tex);
    glGetTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, &cmp);
    glBindTexture(GL_TEXTURE_2D, 0);
    CHECK(cmp == GL_NONE);
    CHECK_OK(gr_target_ensure(&lb, GL_RGBA16F, 4, 4, GR_TARGET_LINEAR | GR_TARGET_BLACK_BORDER, "light", &err), err);
    check_wrap(lb.tex, GL_CLAMP_TO_BORDER, 0.0f);
    glBindTexture(GL_TEXTURE_2D, lb.tex);
    glGetTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, &filt);
    glBindTexture(GL_TEXTURE_2D, 0);
    CHECK(filt == GL_LINEAR);
    /* a depth format on the colour attachment: never complete */
    gr_status st = gr_target_ensure(&bad, GL_DEPTH_COMPONENT32F, 4, 4, 0, "bad target", &err);
    CHECK(st == GR_E_GL);
    CHECK_MSG(st != GR_OK && strstr(err.msg, "bad target") != NULL, "%s", err.msg);
    CHECK(bad.tex == 0 && bad.fbo == 0 && bad.w == 0);
    while (glGetError() != GL_NO_ERROR) {
    }

    /* ---- accumulate: bound, its viewport, zero, additive ---- */
    gr_target_accumulate(&t);
    GLint fb = 0, vp[4] = {0}, src = 0, dst = 0, eq = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fb);
    glGetIntegerv(GL_VIEWPORT, vp);
    glGetIntegerv(GL_BLEND_SRC_RGB, &src);
    glGetIntegerv(GL_BLEND_DST_RGB, &dst);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &eq);
    CHECK((unsigned)fb == t.fbo);
    CHECK(vp[0] == 0 && vp[1] == 0 && vp[2] == 6 && vp[3] == 4);
    CHECK(glIsEnabled(GL_BLEND) && src == GL_ONE && dst == GL_ONE && eq == GL_FUNC_ADD);
    glDisable(GL_BLEND);
    gr_readback rb = {0};
    static const char *const rgb[3] = {"R", "G", "B"};
    gr_image *img = gr_image_create(6, 4, 3, rgb);
    size_t nbad = 99;
    CHECK_OK(gr_readback_rgb(&rb, t.fbo, img, &nbad, "zero", &err), err);
    CHECK(nbad == 0);
    int zero = 1;
    for (size_t i = 0; i < 6 * 4 * 3; i++) zero &= img->pixels[i] == 0.0f;
    CHECK(zero);

    /* ---- readback: GL row 0 is the image's last row ---- */
    static const float all[4] = {1.5f, -2.0f, 3.25f, 1.0f}, bottom[4] = {7.0f, 8.0f, 9.0f, 1.0f};
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    glClearBufferfv(GL_COLOR, 0, all);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, 6, 1);
    glClearBufferfv(GL_COLOR, 0, bottom);
    glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    CHECK_OK(gr_readback_rgb(&rb, t.fbo, img, &nbad, "rows", &err), err);
    CHECK(nbad == 0);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++) {
            const float *px = gr_image_pixel(img, x, y);
            const float *want = y == 3 ? bottom : all;
            for (int c = 0; c < 3; c++) CHECK(px[c] == want[c]);
        }
    static const float inf[4] = {INFINITY, 0.0f, 0.0f, 1.0f};
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    glClearBufferfv(GL_COLOR, 0, inf);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    CHECK_OK(gr_readback_rgb(&rb, t.fbo, img, &nbad, "inf", &err), err);
    CHECK_MSG(nbad == 6 * 4, "%zu non-finite values, expected %d", nbad, 6 * 4);

    /* ---- timers ---- */
    gr_gl_timer tm;
    gr_gl_timer_init(&tm);
    double t0 = gr_clock_ms();
    gr_gl_timer_begin(&tm, 1);
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    glClearBufferfv(GL_COLOR, 0, all);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    gr_gl_timer_end(&tm);
    long long ns = gr_gl_timer_ns(&tm, 1);
    CHECK(ns >= 0);
    CHECK(gr_gl_timer_ns(&tm, 0) == -1);                 /* not timed */
    CHECK(gr_gl_timer_ns_within(&tm, 1, 1e18) == ns);    /* within any wall time */
    CHECK(gr_gl_timer_ns_within(&tm, 1, -1.0) == -1);    /* longer than the wall time */
    static const char *const names[2] = {"first", "second"};
    gr_technique_stats stats;
    gr_gl_timer_stats(&stats, &tm, names, 2, t0);
    CHECK(stats.n_passes == 2 && !strcmp(stats.pass_names[0], "first") && !strcmp(stats.pass_names[1], "second"));
    CHECK(stats.gpu_ns[0] == -1 && stats.fragments == -1 && stats.wall_ms >= 0);
    CHECK(stats.gpu_ns[1] == -1 || stats.gpu_ns[1] == ns);
    gr_gl_timer_reset(&tm);
    CHECK(gr_gl_timer_ns(&tm, 1) == -1); /* a new frame: nothing timed yet */
    gr_gl_timer_free(&tm);

    gr_image_destroy(img);
    gr_readback_free(&rb);
    gr_target_release(&t);
    gr_target_release(&d);
    gr_target_release(&lb);
    gr_target_release(NULL);
    CHECK(t.tex == 0 && t.fbo == 0);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
