/* libFuzzer target: the project's EXR reader (image/exr.c on OpenEXRCore), metadata included.
 * Corpus: tests/fuzz/corpus/exr/ (small files the project writes, and crafted ones). */
#include "fuzz_file.h"

#include <string.h>

#include "image/exr.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = gr_fuzz_file(data, size);
    gr_image *img = NULL;
    gr_metadata meta;
    gr_meta_init(&meta);
    gr_error err = {GR_OK, ""};
    if (gr_exr_read(path, &img, &meta, &err) == GR_OK) {
        /* the promises of a successful read: a bounded size, finite samples */
        if (!img || (long long)img->width * img->height > GR_IMAGE_READ_MAX_PIXELS) abort();
        if (gr_image_check_finite(img, "fuzz", &err) != GR_OK) abort();
    } else if (img || strchr(err.msg, '\n')) {
        abort();
    }
    gr_image_destroy(img);
    gr_meta_free(&meta);
    return 0;
}
