/* Float images with named channels, and ordered metadata (docs/images.md). */
#include "image/image.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

gr_image *gr_image_create(int width, int height, int nchannels, const char *const *names)
{
    if (width <= 0 || height <= 0 || nchannels <= 0 || nchannels > GR_IMAGE_MAX_CHANNELS)
        return NULL;
    /* Guard the sample count against size_t overflow before multiplying. */
    size_t w = (size_t)width, h = (size_t)height, c = (size_t)nchannels;
    if (w > SIZE_MAX / h || w * h > SIZE_MAX / c || w * h * c > SIZE_MAX / sizeof(float))
        return NULL;
    if (names) {
        for (int i = 0; i < nchannels; i++) {
            if (!names[i] || names[i][0] == '\0' || strlen(names[i]) >= GR_CHANNEL_NAME_MAX)
                return NULL;
        }
    }
    gr_image *img = calloc(1, sizeof *img);
    if (!img) return NULL;
    img->pixels = calloc(w * h * c, sizeof(float));
    if (!img->pixels) {
        free(img);
        return NULL;
    }
    img->width = width;
    img->height = height;
    img->nchannels = nchannels;
    static const char *const rgba[4] = {"R", "G", "B", "A"};
    for (int i = 0; i < nchannels; i++) {
        if (names)
            snprintf(img->names[i], GR_CHANNEL_NAME_MAX, "%s", names[i]);
        else if (i < 4)
            snprintf(img->names[i], GR_CHANNEL_NAME_MAX, "%s", rgba[i]);
        else
            snprintf(img->names[i], GR_CHANNEL_NAME_MAX, "c%d", i);
    }
    return img;
}

void gr_image_destroy(gr_image *img)
{
    if (!img) return;
    free(img->pixels);
    free(img);
}

int gr_image_channel(const gr_image *img, const char *name)
{
    if (!img || !name) return -1;
    for (int i = 0; i < img->nchannels; i++)
        if (strcmp(img->names[i], name) == 0) return i;
    return -1;
}

gr_status gr_image_check_size(const char *path, long long width, long long height, int nchannels, gr_error *err)
{
    if (width <= 0 || height <= 0 || nchannels <= 0)
        return gr_fail(err, GR_E_INPUT, "%s: declares %lld x %lld pixels and %d channels: not an image", path, width,
                       height, nchannels);
    if (width > GR_IMAGE_READ_MAX_SIDE || height > GR_IMAGE_READ_MAX_SIDE || width * height > GR_IMAGE_READ_MAX_PIXELS)
        return gr_fail(err, GR_E_INPUT, "%s: declares %lld x %lld pixels, over the reader's limit (%d per side, %lld "
                       "in all)", path, width, height, GR_IMAGE_READ_MAX_SIDE, GR_IMAGE_READ_MAX_PIXELS);
    return GR_OK;
}

gr_status gr_image_check_finite(const gr_image *img, const char *what, gr_error *err)
{
    if (!what) what = "image";
    if (!img || !img->pixels)
        return gr_fail(err, GR_E_RUNTIME, "%s: no image", what);
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->nchannels;
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(img->pixels[i])) {
            if (bad == 0) first = i;
            bad++;
        }
    }
    if (bad == 0) return GR_OK;
    size_t nc = (size_t)img->nchannels, w = (size_t)img->width;
    size_t c = first % nc, px = first / nc;
    float v = img->pixels[first];
    return gr_fail(err, GR_E_RUNTIME, "%s: channel '%s' pixel (%zu, %zu) is %s (%zu non-finite samples)",
                   what, img->names[c], px % w, px / w, isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf"), bad);
}

/* ---- metadata ----------------------------------------------------------------- */

void gr_meta_init(gr_metadata *m)
{
    if (!m) return;
    m->count = 0;
    m->capacity = 0;
    m->items = NULL;
}

void gr_meta_free(gr_metadata *m)
{
    if (!m) return;
    for (int i = 0; i < m->count; i++) free(m->items[i].str);
    free(m->items);
    gr_meta_init(m);
}

const gr_meta_item *gr_meta_get(const gr_metadata *m, const char *key)
{
    if (!m || !key) return NULL;
    for (int i = 0; i < m->count; i++)
        if (strcmp(m->items[i].key, key) == 0) return &m->items[i];
    return NULL;
}

static int key_ok(const char *key)
{
    return key && key[0] != '\0' && strlen(key) < sizeof(((gr_meta_item *)0)->key);
}

/* The item called key: the existing one (its old string freed), or a new one appended.
 * NULL when growing the array fails. */
static gr_meta_item *slot_for(gr_metadata *m, const char *key)
{
    for (int i = 0; i < m->count; i++) {
        if (strcmp(m->items[i].key, key) == 0) {
            free(m->items[i].str);
            m->items[i].str = NULL;
            return &m->items[i];
        }
    }
    if (m->count == m->capacity) {
        int cap = m->capacity ? 2 * m->capacity : 8;
        gr_meta_item *items = realloc(m->items, (size_t)cap * sizeof *items);
        if (!items) return NULL;
        m->items = items;
        m->capacity = cap;
    }
    gr_meta_item *it = &m->items[m->count++];
    memset(it, 0, sizeof *it);
    snprintf(it->key, sizeof it->key, "%s", key);
    return it;
}

gr_status gr_meta_set_string(gr_metadata *m, const char *key, const char *value)
{
    if (!m || !key_ok(key) || !value) return GR_E_INPUT;
    /* Copy first: value may point into the item being replaced. */
    size_t n = strlen(value) + 1;
    char *copy = malloc(n);
    if (!copy) return GR_E_NOMEM;
    memcpy(copy, value, n);
    gr_meta_item *it = slot_for(m, key);
    if (!it) {
        free(copy);
        return GR_E_NOMEM;
    }
    it->type = GR_META_STRING;
    it->str = copy;
    it->num = 0.0;
    return GR_OK;
}

static gr_status set_number(gr_metadata *m, const char *key, gr_meta_type type, double value)
{
    if (!m || !key_ok(key)) return GR_E_INPUT;
    gr_meta_item *it = slot_for(m, key);
    if (!it) return GR_E_NOMEM;
    it->type = type;
    it->num = value;
    return GR_OK;
}

gr_status gr_meta_set_double(gr_metadata *m, const char *key, double value)
{
    return set_number(m, key, GR_META_DOUBLE, value);
}

gr_status gr_meta_set_int(gr_metadata *m, const char *key, long long value)
{
    return set_number(m, key, GR_META_INT, (double)value);
}

gr_status gr_meta_copy(gr_metadata *dst, const gr_metadata *src)
{
    if (!dst) return GR_E_INPUT;
    if (dst == src) return GR_OK;
    gr_meta_free(dst);
    if (!src) return GR_OK;
    for (int i = 0; i < src->count; i++) {
        const gr_meta_item *it = &src->items[i];
        gr_status st = it->type == GR_META_STRING ? gr_meta_set_string(dst, it->key, it->str)
                                                  : set_number(dst, it->key, it->type, it->num);
        if (st != GR_OK) {
            gr_meta_free(dst);
            return st;
        }
    }
    return GR_OK;
}
