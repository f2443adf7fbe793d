/* EXR files through OpenEXR's C API (OpenEXRCore): float channels, named, plus metadata
 * attributes. Writes go to a temporary file renamed into place: nothing half-written. */
#ifndef GR_EXR_H
#define GR_EXR_H

#include "image/image.h"

/* Writes every channel of img as 32-bit float (ZIP compression) with meta as attributes. */
gr_status gr_exr_write(const char *path, const gr_image *img, const gr_metadata *meta, gr_error *err);
/* Reads every channel (converted to float) and every attribute that is a string, float,
 * double or int into meta (meta may be NULL). *out must be destroyed by the caller. */
/* The checks gr_exr_read makes before it allocates (a regular file, the magic number, the
 * header, the data window within the image size caps, the chunk table inside the file), without
 * reading pixels: for readers of EXR files other than gr_exr_read (OpenImageIO's). */
gr_status gr_exr_check(const char *path, gr_error *err);
gr_status gr_exr_read(const char *path, gr_image **out, gr_metadata *meta, gr_error *err);
/* gr_exr_read, and *bits (may be NULL) the file's widest sample: 16 (half) or 32 (float, uint). */
gr_status gr_exr_read_bits(const char *path, gr_image **out, gr_metadata *meta, int *bits, gr_error *err);

#endif
