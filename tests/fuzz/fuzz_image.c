/* libFuzzer target: the image reader behind `godrays compare` (image/oiio.cpp on OpenImageIO,
 * the reader of the file name's extension). The first byte of an input picks the extension
 * (exr, png, tif, hdr, jpg, bmp, ppm, tga, ...), the rest is the file. Corpus:
 * tests/fuzz/corpus/image/ (one byte of prefix, then a small file of each format). */
#include "fuzz_file.h"

#include <string.h>

#include "image/oiio.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const exts[] = {"exr", "png", "tif", "hdr", "jpg", "bmp", "ppm", "tga", "pgm", "tiff", "jpeg", "pnm"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    const char *path = gr_fuzz_named_file(data + 1, size - 1, exts[data[0] % (sizeof exts / sizeof exts[0])]);
    gr_image *img = NULL;
    gr_error err = {GR_OK, ""};
    if (gr_oiio_read(path, 1, &img, &err) == GR_OK) {
        if (!img || (long long)img->width * img->height > GR_IMAGE_READ_MAX_PIXELS) abort();
        if (gr_image_check_finite(img, "fuzz", &err) != GR_OK) abort();
    } else if (img || strchr(err.msg, '\n')) {
        abort();
    }
    gr_image_destroy(img);
    return 0;
}
