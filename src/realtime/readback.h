/* Reading a float colour target back from GL, the one way every technique does it: RGBA
 * floats into a growable buffer (GL rows, bottom-up), then either the RGB into a layer's R, G,
 * B channels or a whole RGBA image, rows flipped so that the top row comes first as in every
 * gr_image. Needs the context that owns the framebuffer to be current. */
#ifndef GR_READBACK_H
#define GR_READBACK_H

#include <stddef.h>

#include "common/status.h"
#include "image/image.h"

typedef struct gr_readback {
    float *rgba;      /* w * h * 4 floats, GL row order (row 0 = bottom) */
    size_t cap;       /* floats allocated */
    int w, h;         /* size of the last read */
} gr_readback;        /* zero-initialize; gr_readback_free releases it */

/* Reads colour attachment 0 of framebuffer fbo (w x h, RGBA float); leaves framebuffer 0
 * bound. `what` names the target in errors (out of memory, a GL error). */
gr_status gr_readback_fbo(gr_readback *rb, unsigned fbo, int w, int h, const char *what, gr_error *err);
/* The RGB of the last read into channels R, G, B of out (same size), top row first, values
 * as read. Returns how many of them are NaN or infinite. */
size_t gr_readback_to_rgb(const gr_readback *rb, gr_image *out);
/* The last read as a new 4-channel image, top row first; NULL if out of memory. */
gr_image *gr_readback_image(const gr_readback *rb);
/* gr_readback_fbo of out's size, then gr_readback_to_rgb into out: a technique's final layer.
 * *bad (may be NULL) receives the count of NaN or infinite values read. */
gr_status gr_readback_rgb(gr_readback *rb, unsigned fbo, gr_image *out, size_t *bad, const char *what,
                          gr_error *err);
void gr_readback_free(gr_readback *rb); /* accepts NULL */

#endif
