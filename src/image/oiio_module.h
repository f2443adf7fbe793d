/* The boundary between oiio.c (the C interface of oiio.h) and oiio.cpp (OpenImageIO itself),
 * which is built as a module loaded on first use (libgodrays_oiio.so beside the binary):
 * Debian's OpenImageIO links about 270 shared libraries, and resolving them cost every
 * godrays process 0.3-0.4 s of CPU at start, image I/O or not (docs/images.md, "Loading
 * OpenImageIO"). The module calls back into the program only through the host table, so it
 * has no undefined symbols of its own (built with -z defs) and sees the program's state
 * (memory limit, outputs pending on a signal), not a copy of it. */
#ifndef GR_OIIO_MODULE_H
#define GR_OIIO_MODULE_H

#include "common/outfile.h"
#include "common/status.h"
#include "image/oiio.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Raised whenever either struct below changes: a stale module is refused, not called. */
#define GR_OIIO_MODULE_ABI 2
#define GR_OIIO_MODULE_FILE "libgodrays_oiio.so"
#define GR_OIIO_MODULE_ENTRY "gr_oiio_module_open"

/* What the module calls in the program (the functions of the same names). */
typedef struct gr_oiio_host {
    gr_status (*fail)(gr_error *err, gr_status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
    gr_image *(*image_create)(int width, int height, int nchannels, const char *const *names);
    void (*image_destroy)(gr_image *img);
    gr_status (*image_check_finite)(const gr_image *img, const char *what, gr_error *err);
    gr_status (*image_check_size)(const char *path, long long width, long long height, int nchannels,
                                  gr_error *err);
    gr_status (*memlimit_check)(const char *what, double need_bytes, const char *detail, gr_error *err);
    gr_status (*check_regular_input)(const char *path, gr_error *err);
    gr_status (*exr_check)(const char *path, gr_error *err);
    gr_status (*outfile_begin)(gr_outfile *o, const char *path, gr_error *err);
    gr_status (*outfile_commit)(gr_outfile *o, long long min_size, gr_error *err);
    void (*outfile_abort)(gr_outfile *o);
} gr_oiio_host;

/* What the module does: the functions of oiio.h, one for one. */
typedef struct gr_oiio_api {
    const char *(*version)(void);
    gr_status (*read_info)(const char *path, int linearize, gr_image **out, gr_oiio_info *info, gr_error *err);
    gr_status (*write)(const char *path, const gr_image *img, gr_error *err);
    gr_status (*color_map)(const gr_image *src, int channel, const char *map, gr_image **out, gr_error *err);
    gr_status (*render_text)(gr_image *img, int x, int y, const char *text, int size_px, const float rgb[3],
                             int align, gr_error *err);
    gr_status (*write_animation)(const char *path, const gr_image *const *frames, int n, double fps,
                                 gr_error *err);
} gr_oiio_api;

/* The module's one exported function: keeps host (which must outlive every call) and returns
 * its table, or NULL when abi is not GR_OIIO_MODULE_ABI. */
const gr_oiio_api *gr_oiio_module_open(const gr_oiio_host *host, int abi);
typedef const gr_oiio_api *(*gr_oiio_module_open_fn)(const gr_oiio_host *host, int abi);

#ifdef __cplusplus
}
#endif
#endif
