/* image/exr: crafted EXR files (issue 15, item 9; docs/reliability.md). The files are built
 * byte by byte here from the OpenEXR file layout (openexr.com, "OpenEXR File Layout"), not
 * with the project's writer, so that every field can be set to a lie:
 *  - an honest uncompressed 16 x 12 file reads back its 0.5 samples (the oracle: the bytes
 *    written), so the builder itself is right;
 *  - chunk 0's size field shrunk (192 -> 100 bytes): must be refused, not decoded as
 *    invented samples (today's main returned OK with -0.37 where 0.5 was stored);
 *  - a data window rewritten to 1000000 x 1: refused (main read a 1e6 x 1 image of zeros);
 *  - a data window of 8000 x 8000 in a 1 KB file: refused before the 768 MB image is
 *    allocated (the chunk table cannot fit the file); with the address space limited to
 *    512 MB (not under ASan, which reserves its shadow) main failed with "out of memory";
 *  - the chunk table pointing past the end of the file: refused. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "check.h"
#include "image/exr.h"

typedef struct buf { unsigned char b[1 << 16]; size_t n; } buf;

static void put(buf *o, const void *p, size_t n) { memcpy(o->b + o->n, p, n); o->n += n; }
static void put_i32(buf *o, int32_t v) { unsigned char c[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)((uint32_t)v >> 24)}; put(o, c, 4); }
static void put_u64(buf *o, uint64_t v) { for (int i = 0; i < 8; i++) { unsigned char c = (unsigned char)(v >> (8 * i)); put(o, &c, 1); } }
static void put_str(buf *o, const char *s) { put(o, s, strlen(s) + 1); }
static void attr(buf *o, const char *name, const char *type, int32_t size) { put_str(o, name); put_str(o, type); put_i32(o, size); }
static void put_f32(buf *o, float f) { uint32_t u; memcpy(&u, &f, 4); put_i32(o, (int32_t)u); }

/* An uncompressed scanline EXR, channels B, G, R (float), every sample 0.5, one line per
 * chunk. dw_w x dw_h is what the header declares; w x h the lines and samples written. */
static void build(buf *o, int w, int h, int dw_w, int dw_h)
{
    o->n = 0;
    const unsigned char magic[8] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
    put(o, magic, 8);
    attr(o, "channels", "chlist", 3 * (2 + 16) + 1);
    for (const char *c = "BGR"; *c; c++) {
        char name[2] = {*c, 0};
        put_str(o, name);
        put_i32(o, 2); /* FLOAT */
        const unsigned char lin[4] = {0, 0, 0, 0};
        put(o, lin, 4);
        put_i32(o, 1);
        put_i32(o, 1);
    }
    put(o, "", 1);
    attr(o, "compression", "compression", 1);
    put(o, "", 1); /* NO_COMPRESSION */
    attr(o, "dataWindow", "box2i", 16);
    put_i32(o, 0); put_i32(o, 0); put_i32(o, dw_w - 1); put_i32(o, dw_h - 1);
    attr(o, "displayWindow", "box2i", 16);
    put_i32(o, 0); put_i32(o, 0); put_i32(o, dw_w - 1); put_i32(o, dw_h - 1);
    attr(o, "lineOrder", "lineOrder", 1);
    put(o, "", 1); /* INCREASING_Y */
    attr(o, "pixelAspectRatio", "float", 4);
    put_f32(o, 1.0f);
    attr(o, "screenWindowCenter", "v2f", 8);
    put_f32(o, 0.0f); put_f32(o, 0.0f);
    attr(o, "screenWindowWidth", "float", 4);
    put_f32(o, 1.0f);
    put(o, "", 1); /* end of header */
    const size_t table = o->n, line = (size_t)w * 3 * 4;
    for (int y = 0; y < h; y++) put_u64(o, table + 8 * (size_t)h + (size_t)y * (8 + line));
    for (int y = 0; y < h; y++) {
        put_i32(o, y);
        put_i32(o, (int32_t)line);
        for (int i = 0; i < w * 3; i++) put_f32(o, 0.5f);
    }
}

static char dir[64];

static gr_status read_bytes(const buf *o, const char *name, gr_image **img, gr_error *err)
{
    char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(o->b, 1, o->n, f) != o->n || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    *img = NULL;
    gr_status st = gr_exr_read(path, img, NULL, err);
    printf("%s: status %d: %s\n", name, (int)st, st ? err->msg : "ok");
    return st;
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/gr_rel_exr_XXXXXX");
    if (!mkdtemp(dir)) return 1;
    static buf o;
    gr_error err = {GR_OK, ""};
    gr_image *img = NULL;

    /* honest file: the builder is right */
    build(&o, 16, 12, 16, 12);
    gr_status st = read_bytes(&o, "good.exr", &img, &err);
    CHECK_OK(st, err);
    if (img) {
        CHECK(img->width == 16 && img->height == 12 && img->nchannels == 3);
        int bad = 0;
        for (int i = 0; i < 16 * 12 * 3; i++) bad += img->pixels[i] != 0.5f;
        CHECK_MSG(bad == 0, "%d samples differ from the 0.5 written", bad);
    }
    gr_image_destroy(img);

    /* chunk 0's size shrunk from 192 to 100 bytes */
    build(&o, 16, 12, 16, 12);
    const size_t chunk0 = o.n - 12 * (8 + 192);
    o.b[chunk0 + 4] = 100;
    st = read_bytes(&o, "shrunk_chunk.exr", &img, &err);
    CHECK_MSG(st == GR_E_INPUT, "a shrunken uncompressed chunk was read (status %d)", (int)st);
    gr_image_destroy(img);

    /* data window rewritten to 1000000 x 1 */
    build(&o, 16, 12, 16, 12);
    buf wide;
    build(&wide, 16, 12, 1000000, 1);
    st = read_bytes(&wide, "wide_window.exr", &img, &err);
    CHECK_MSG(st == GR_E_INPUT, "a 1e6 x 1 data window was read (status %d)", (int)st);
    gr_image_destroy(img);

    /* 8000 x 8000 declared, 12 lines present: the chunk table cannot fit the file */
#if !defined(__SANITIZE_ADDRESS__)
    struct rlimit rl = {512ull << 20, 512ull << 20};
    setrlimit(RLIMIT_AS, &rl);
#endif
    build(&o, 16, 12, 8000, 8000);
    st = read_bytes(&o, "huge_window.exr", &img, &err);
    CHECK_MSG(st == GR_E_INPUT, "8000 x 8000 declared in a %zu-byte file: status %d (want bad input)", o.n, (int)st);
    gr_image_destroy(img);

    /* chunk offset past the end of the file */
    build(&o, 16, 12, 16, 12);
    const size_t table = chunk0 - 8 * 12;
    o.b[table + 7 * 8 + 3] = 0x7f; /* chunk 7 at 2 GB */
    st = read_bytes(&o, "offset_past_end.exr", &img, &err);
    CHECK_MSG(st == GR_E_INPUT, "a chunk past the end of the file was read (status %d)", (int)st);
    gr_image_destroy(img);

    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", dir);
    CHECK_DONE();
}
