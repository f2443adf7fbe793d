#include "realtime/readback.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"
#include "gl/glctx.h"

gr_status gr_readback_fbo(gr_readback *rb, unsigned fbo, int w, int h, const char *what, gr_error *err)
{
    size_t need = (size_t)w * (size_t)h * 4;
    if (need > rb->cap) {
        float *nb = realloc(rb->rgba, need * sizeof *nb);
        if (!nb) return gr_fail(err, GR_E_NOMEM, "%s: out of memory for the readback (%dx%d)", what, w, h);
        rb->rgba = nb;
        rb->cap = need;
    }
    rb->w = w;
    rb->h = h;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rb->rgba);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return gr_gl_check(what, err);
}

size_t gr_readback_to_rgb(const gr_readback *rb, gr_image *out)
{
    int ch[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
    size_t bad = 0;
    for (int y = 0; y < rb->h; y++) {
        const float *src = rb->rgba + (size_t)(rb->h - 1 - y) * (size_t)rb->w * 4;
        for (int x = 0; x < rb->w; x++) {
            float *px = gr_image_pixel(out, x, y);
            for (int c = 0; c < 3; c++) {
                float v = src[(size_t)x * 4 + (size_t)c];
                if (!isfinite(v)) bad++;
                px[ch[c]] = v; /* as read: the caller decides (the harness rejects NaN, Inf) */
            }
        }
    }
    return bad;
}

gr_image *gr_readback_image(const gr_readback *rb)
{
    gr_image *img = gr_image_create(rb->w, rb->h, 4, NULL);
    if (!img) return NULL;
    size_t row = (size_t)rb->w * 4;
    for (int y = 0; y < rb->h; y++)
        memcpy(img->pixels + (size_t)y * row, rb->rgba + (size_t)(rb->h - 1 - y) * row, row * sizeof *rb->rgba);
    return img;
}

gr_status gr_readback_rgb(gr_readback *rb, unsigned fbo, gr_image *out, size_t *bad, const char *what,
                          gr_error *err)
{
    gr_status st = gr_readback_fbo(rb, fbo, out->width, out->height, what, err);
    size_t n = st == GR_OK ? gr_readback_to_rgb(rb, out) : 0;
    if (bad) *bad = n;
    return st;
}

void gr_readback_free(gr_readback *rb)
{
    if (!rb) return;
    free(rb->rgba);
    memset(rb, 0, sizeof *rb);
}
