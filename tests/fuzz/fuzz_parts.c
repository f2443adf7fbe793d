/* libFuzzer target: the farm's part-file reader, through the merge of one part
 * (gr_parts_merge: header, sizes against the file and the memory limit, payload checksum,
 * coverage, the merged sums, then the assembly of a covering part). The payload checksum is
 * recomputed into the header before each run when the header names one, so that mutated
 * payloads reach the checks behind it (finite sums, counts) instead of stopping at the
 * checksum. GODRAYS_MAX_MEMORY is 256M: a header declaring a large render is refused by the
 * estimate, never allocated. Corpus: tests/fuzz/corpus/parts/ (tiny parts from
 * `godrays reference --tile/--batch-part`). Checks beyond the sanitizers: the message is one
 * terminated line; a merged image is finite. */
#include "fuzz_file.h" /* first: it defines _GNU_SOURCE (memfd_create) */

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "farm/parts.h"
#include "reference/cache.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes the FNV-1a 64 of the bytes after the header over the header's payload_fnv1a64. */
static void fix_checksum(uint8_t *d, size_t size)
{
    const uint8_t *nl1 = memchr(d, '\n', size);
    const uint8_t *nl2 = nl1 ? memchr(nl1 + 1, '\n', size - (size_t)(nl1 + 1 - d)) : NULL;
    if (!nl2) return;
    size_t hn = 0;
    for (const uint8_t *q = nl1 + 1; q < nl2 && *q >= '0' && *q <= '9' && hn < ((size_t)1 << 40); q++) hn = hn * 10 + (size_t)(*q - '0');
    const size_t h0 = (size_t)(nl2 + 1 - d);
    if (hn > size - h0) return;
    static const char key[] = "\"payload_fnv1a64\":\"";
    const size_t kl = sizeof key - 1;
    for (size_t i = h0; i + kl + 16 <= h0 + hn; i++)
        if (!memcmp(d + i, key, kl)) {
            char h[20];
            snprintf(h, sizeof h, "%016llx", gr_fnv1a64(GR_FNV_BASIS, d + h0 + hn, size - h0 - hn));
            memcpy(d + i + kl, h, 16);
            return;
        }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int init = 0;
    if (!init) {
        setenv("GODRAYS_MAX_MEMORY", "256M", 1);
        init = 1;
    }
    uint8_t *d = malloc(size + 1);
    gr_scene *scene = malloc(sizeof *scene);
    if (!d || !scene) {
        free(d);
        free(scene);
        return 0;
    }
    memcpy(d, data, size);
    fix_checksum(d, size);
    const char *path = gr_fuzz_file(d, size);
    gr_ref_result res;
    char key[80];
    gr_error err = {GR_OK, ""};
    if (gr_parts_merge(&path, 1, scene, &res, key, sizeof key, &err) == GR_OK) {
        const gr_image *im = res.image;
        for (size_t i = 0; im && i < (size_t)im->width * im->height * im->nchannels; i++)
            if (!(im->pixels[i] == im->pixels[i]) || im->pixels[i] > 3.0e38f || im->pixels[i] < -3.0e38f) abort();
        gr_ref_result_free(&res);
    } else if (!memchr(err.msg, '\0', sizeof err.msg) || strchr(err.msg, '\n')) {
        abort(); /* the promise: one terminated line */
    }
    free(scene);
    free(d);
    return 0;
}
