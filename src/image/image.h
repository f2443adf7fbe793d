/* Float images with named channels, and the metadata that travels with them in EXR files. */
#ifndef GR_IMAGE_H
#define GR_IMAGE_H

#include <stddef.h>
#include "common/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GR_IMAGE_MAX_CHANNELS 16
#define GR_CHANNEL_NAME_MAX 32

/* Pixels are interleaved, row-major, top row first: pixel (x, y) channel c is
 * pixels[(y * width + x) * nchannels + c]. Channel names follow EXR usage: "R", "G", "B",
 * "A", and extra channels such as "stderr.R" or "transmittance". */
typedef struct gr_image {
    int width, height, nchannels;
    char names[GR_IMAGE_MAX_CHANNELS][GR_CHANNEL_NAME_MAX];
    float *pixels;
} gr_image;

/* Allocates a zeroed image; names may be NULL (then "R","G","B","A" for up to 4 channels,
 * "c4", "c5", ... after). Returns NULL on bad sizes, on a NULL, empty or too long
 * (>= GR_CHANNEL_NAME_MAX) name, or on allocation failure. */
gr_image *gr_image_create(int width, int height, int nchannels, const char *const *names);
void gr_image_destroy(gr_image *img); /* accepts NULL */
/* Index of the channel called name, or -1. */
int gr_image_channel(const gr_image *img, const char *name);
static inline float *gr_image_pixel(gr_image *img, int x, int y)
{
    return img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->nchannels;
}
/* GR_OK if every sample of img is finite; otherwise GR_E_RUNTIME with a message
 * "WHAT: channel 'NAME' pixel (x, y) is nan|inf|-inf (N non-finite samples)". The project
 * rule "no NaN or Inf reaches an image" is enforced with it by every image writer. */
gr_status gr_image_check_finite(const gr_image *img, const char *what, gr_error *err);

/* Images read from files (EXR, PNG, any format compare reads) are bounded before anything is
 * allocated: at most GR_IMAGE_READ_MAX_SIDE pixels per side and GR_IMAGE_READ_MAX_PIXELS
 * pixels (8192 x 8192), so that a crafted header of a few bytes cannot make a reader allocate
 * gigabytes (docs/reliability.md). GR_E_INPUT "PATH: declares W x H pixels, over ..." when
 * width x height x nchannels is over them or not positive. */
#define GR_IMAGE_READ_MAX_SIDE 16384
#define GR_IMAGE_READ_MAX_PIXELS (8192LL * 8192LL)
gr_status gr_image_check_size(const char *path, long long width, long long height, int nchannels, gr_error *err);

/* Metadata: ordered key -> value pairs, each a string or a double (EXR attributes). */
typedef enum gr_meta_type { GR_META_STRING = 0, GR_META_DOUBLE = 1, GR_META_INT = 2 } gr_meta_type;
typedef struct gr_meta_item {
    char key[64];
    gr_meta_type type;
    char *str;      /* GR_META_STRING (owned) */
    double num;     /* GR_META_DOUBLE / GR_META_INT */
} gr_meta_item;
typedef struct gr_metadata {
    int count, capacity;
    gr_meta_item *items;
} gr_metadata;

void gr_meta_init(gr_metadata *m);
void gr_meta_free(gr_metadata *m); /* accepts NULL; leaves m empty */
/* Adds or replaces (a replaced item keeps its position, and may change type). Return GR_OK,
 * GR_E_NOMEM, or GR_E_INPUT for a NULL/empty key, a key of 64 chars or more, or a NULL value. */
gr_status gr_meta_set_string(gr_metadata *m, const char *key, const char *value);
gr_status gr_meta_set_double(gr_metadata *m, const char *key, double value);
gr_status gr_meta_set_int(gr_metadata *m, const char *key, long long value);
const gr_meta_item *gr_meta_get(const gr_metadata *m, const char *key); /* NULL if absent */
/* Replaces dst's content by a deep copy of src (dst must be initialized). GR_OK or GR_E_NOMEM
 * (then dst is left empty). */
gr_status gr_meta_copy(gr_metadata *dst, const gr_metadata *src);

#ifdef __cplusplus
}
#endif

#endif
