/* EXR files through OpenEXR's C API (OpenEXRCore 3.1). See docs/images.md for the layout,
 * the attribute mapping and the "nothing half-written" rule. */
#include "image/exr.h"
#include "common/outfile.h"

#include <errno.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>

/* ---- error capture ------------------------------------------------------------------
 * OpenEXRCore prints to stderr unless a handler is installed. Its handler receives no
 * user pointer we control (the default file I/O owns the context's user_data), so the
 * first message of the current call is kept per thread and folded into our gr_error. */
static _Thread_local char g_exr_msg[512];

static void exr_capture_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    if (g_exr_msg[0] != '\0') return; /* the first error is the cause; later ones are fallout */
    snprintf(g_exr_msg, sizeof g_exr_msg, "%s", msg ? msg : exr_get_default_error_message(code));
    for (char *p = g_exr_msg; *p; p++)
        if (*p == '\n' || *p == '\r') *p = ' '; /* one-line messages */
}

static exr_context_initializer_t exr_init_for(int reading)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_capture_error;
    /* A truncated file must be an error, not silently reconstructed data. */
    if (reading) init.flags |= EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    return init;
}

static gr_status status_of(exr_result_t rv, gr_status fallback)
{
    switch (rv) {
    case EXR_ERR_OUT_OF_MEMORY: return GR_E_NOMEM;
    case EXR_ERR_FILE_ACCESS:
    case EXR_ERR_READ_IO:
    case EXR_ERR_WRITE_IO: return GR_E_IO;
    default: return fallback;
    }
}

/* "PATH: WHAT: library message" with the status that rv maps to. */
static gr_status exr_fail(gr_error *err, const char *path, exr_result_t rv, gr_status fallback,
                          const char *what)
{
    const char *why = g_exr_msg[0] ? g_exr_msg : exr_get_default_error_message(rv);
    gr_status st = gr_fail(err, status_of(rv, fallback), "%s: %s: %s", path, what, why);
    /* one line: OpenEXR's text, and a file name or attribute it quotes, may hold line breaks
     * and other control bytes (found by fuzzing) */
    if (err)
        for (char *c = err->msg; *c; c++)
            if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = ' ';
    return st;
}

/* Attributes OpenEXR itself defines for the file structure: never metadata. */
static int is_structural_attr(const char *name)
{
    static const char *const names[] = {
        "channels", "compression", "dataWindow", "displayWindow", "lineOrder",
        "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "tiles", "name",
        "type", "version", "chunkCount", "maxSamplesPerPixel"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0) return 1;
    return 0;
}

/* ---- write ------------------------------------------------------------------------- */

static gr_status check_image(const char *path, const gr_image *img, gr_error *err)
{
    if (!img || !img->pixels || img->width <= 0 || img->height <= 0 || img->nchannels <= 0 ||
        img->nchannels > GR_IMAGE_MAX_CHANNELS)
        return gr_fail(err, GR_E_INPUT, "%s: no image or bad image size", path);
    for (int c = 0; c < img->nchannels; c++) {
        if (img->names[c][0] == '\0' || memchr(img->names[c], '\0', GR_CHANNEL_NAME_MAX) == NULL)
            return gr_fail(err, GR_E_INPUT, "%s: channel %d has no valid name", path, c);
        for (int d = 0; d < c; d++)
            if (strcmp(img->names[c], img->names[d]) == 0)
                return gr_fail(err, GR_E_INPUT, "%s: channel name '%s' appears twice", path,
                               img->names[c]);
    }
    /* Strides are int32 in OpenEXRCore. */
    if ((long long)img->width * img->nchannels * (long long)sizeof(float) > INT32_MAX)
        return gr_fail(err, GR_E_INPUT, "%s: image too wide for EXR strides (%d x %d channels)",
                       path, img->width, img->nchannels);
    return gr_image_check_finite(img, path, err);
}

static gr_status write_attrs(exr_context_t ctx, int part, const char *path, const gr_metadata *meta,
                             gr_error *err)
{
    if (!meta) return GR_OK;
    for (int i = 0; i < meta->count; i++) {
        const gr_meta_item *it = &meta->items[i];
        if (is_structural_attr(it->key))
            return gr_fail(err, GR_E_INPUT, "%s: metadata key '%s' is a reserved EXR attribute",
                           path, it->key);
        exr_result_t rv;
        if (it->type == GR_META_STRING)
            rv = exr_attr_set_string(ctx, part, it->key, it->str ? it->str : "");
        else if (it->type == GR_META_INT && it->num >= INT32_MIN && it->num <= INT32_MAX)
            rv = exr_attr_set_int(ctx, part, it->key, (int32_t)it->num);
        else /* doubles, and ints beyond EXR's 32-bit int attribute */
            rv = exr_attr_set_double(ctx, part, it->key, it->num);
        if (rv != EXR_ERR_SUCCESS) {
            char what[128];
            snprintf(what, sizeof what, "metadata key '%s'", it->key);
            return exr_fail(err, path, rv, GR_E_INPUT, what);
        }
    }
    return GR_OK;
}

/* OpenEXR 3.1's ZIP encoder keeps its zlib output when that output is exactly as long as the
 * raw chunk, but a reader takes a chunk of the raw length as stored uncompressed (the format's
 * rule), so such a chunk reads back as garbage (OpenEXR issue 2306, fixed upstream in 2026 by
 * testing >= instead of >). Deterministic and data-dependent: a 48 x 27 ground truth of a
 * level view hit it. This wrapper around the library's compressor stores the raw bytes then,
 * as the format says; tests/unit/test_exr.c case "equal sizes" sweeps data across the size. */
typedef struct exr_compress_guard {
    exr_result_t (*compress)(exr_encode_pipeline_t *enc);
} exr_compress_guard;

static exr_result_t compress_guarded(exr_encode_pipeline_t *enc)
{
    const exr_compress_guard *g = enc->encoding_user_data;
    exr_result_t rv = g->compress(enc);
    if (rv == EXR_ERR_SUCCESS && enc->compressed_buffer && enc->compressed_buffer != enc->packed_buffer &&
        enc->compressed_bytes >= enc->packed_bytes && enc->compressed_alloc_size >= enc->packed_bytes) {
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
        enc->compressed_bytes = enc->packed_bytes;
    }
    return rv;
}

/* Encodes every chunk of img into the open context (header already written). */
static gr_status write_chunks(exr_context_t ctx, int part, const char *path, const gr_image *img,
                              gr_error *err)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    if (rv != EXR_ERR_SUCCESS || lines <= 0) return exr_fail(err, path, rv, GR_E_RUNTIME, "scanlines per chunk");
    const size_t nc = (size_t)img->nchannels, w = (size_t)img->width;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_compress_guard guard = {NULL};
    gr_status st = GR_OK;
    int first = 1;
    for (int y = 0; y < img->height && st == GR_OK; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_IO, "chunk info"); break; }
        rv = first ? exr_encoding_initialize(ctx, part, &cinfo, &enc) : exr_encoding_update(ctx, part, &cinfo, &enc);
        if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_RUNTIME, "encoder setup"); break; }
        /* Channels are stored sorted by name: match by name, never by index. */
        for (int i = 0; i < enc.channel_count; i++) {
            exr_coding_channel_info_t *ch = &enc.channels[i];
            int c = gr_image_channel(img, ch->channel_name);
            if (c < 0) { st = gr_fail(err, GR_E_RUNTIME, "%s: encoder channel '%s' not in image", path, ch->channel_name); break; }
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_pixel_stride = (int32_t)(nc * sizeof(float));
            ch->user_line_stride = (int32_t)(w * nc * sizeof(float));
            ch->encode_from_ptr = (const uint8_t *)(img->pixels + (size_t)y * w * nc + (size_t)c);
        }
        if (st != GR_OK) break;
        if (first) {
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_RUNTIME, "encoder routines"); break; }
            if (enc.compress_fn) {
                guard.compress = enc.compress_fn;
                enc.encoding_user_data = &guard;
                enc.compress_fn = compress_guarded;
            }
            first = 0;
        }
        rv = exr_encoding_run(ctx, part, &enc);
        if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_IO, "writing pixels"); break; }
    }
    if (!first || enc.channels) exr_encoding_destroy(ctx, &enc);
    return st;
}

gr_status gr_exr_write(const char *path, const gr_image *img, const gr_metadata *meta, gr_error *err)
{
    if (!path || !path[0]) return gr_fail(err, GR_E_USAGE, "EXR write: no output path");
    gr_status st = check_image(path, img, err);
    if (st != GR_OK) return st;

    /* Written to a temporary name and renamed (common/outfile): a reader never sees a
     * half-written file, a device node or symlink at path is refused or followed. */
    gr_outfile of;
    st = gr_outfile_begin(&of, path, err);
    if (st != GR_OK) return st;
    const char *tmp = of.tmp;

    g_exr_msg[0] = '\0';
    exr_context_initializer_t init = exr_init_for(0);
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        st = exr_fail(err, path, rv, GR_E_IO, "cannot create file");
        goto done;
    }
    /* EXR names are limited to 31 characters unless the file is flagged for long names
     * (OpenEXR 2.0+ readers): flag it only when a metadata key needs it. */
    for (int i = 0; meta && i < meta->count; i++) {
        if (strlen(meta->items[i].key) > 31) {
            rv = exr_set_longname_support(ctx, 1);
            if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_RUNTIME, "long names"); goto done; }
            break;
        }
    }
    int part = 0;
    rv = exr_add_part(ctx, "rgba", EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, img->width, img->height, EXR_COMPRESSION_ZIP);
    if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_RUNTIME, "header"); goto done; }
    for (int c = 0; c < img->nchannels; c++) {
        rv = exr_add_channel(ctx, part, img->names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
        if (rv != EXR_ERR_SUCCESS) {
            char what[80];
            snprintf(what, sizeof what, "channel '%s'", img->names[c]);
            st = exr_fail(err, path, rv, GR_E_INPUT, what);
            goto done;
        }
    }
    st = write_attrs(ctx, part, path, meta, err);
    if (st != GR_OK) goto done;
    rv = exr_write_header(ctx);
    if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_IO, "writing header"); goto done; }
    st = write_chunks(ctx, part, path, img, err);

done:
    if (ctx) {
        /* exr_finish writes the chunk offset table: its failure fails the write. */
        rv = exr_finish(&ctx);
        if (st == GR_OK && rv != EXR_ERR_SUCCESS) st = exr_fail(err, path, rv, GR_E_IO, "finishing file");
    }
    /* an EXR holds at least its magic number, version and header */
    if (st == GR_OK) return gr_outfile_commit(&of, 8, err);
    gr_outfile_abort(&of); /* nothing half-written stays behind */
    return st;
}

/* ---- read -------------------------------------------------------------------------- */

/* Canonical channel order on read: the default layer first, then layers by name; inside a
 * layer R, G, B, A, then the rest by name (the file itself stores channels sorted by name). */
static int suffix_rank(const char *name)
{
    const char *dot = strrchr(name, '.');
    const char *s = dot ? dot + 1 : name;
    static const char *const rgba[4] = {"R", "G", "B", "A"};
    for (int i = 0; i < 4; i++)
        if (strcmp(s, rgba[i]) == 0) return i;
    return 4;
}

static int channel_before(const char *a, const char *b)
{
    const char *da = strrchr(a, '.'), *db = strrchr(b, '.');
    size_t la = da ? (size_t)(da - a) : 0, lb = db ? (size_t)(db - b) : 0;
    if (la == 0 || lb == 0) {
        if (la != lb) return la == 0; /* default layer first */
    } else {
        size_t n = la < lb ? la : lb;
        int cmp = strncmp(a, b, n);
        if (cmp != 0) return cmp < 0;
        if (la != lb) return la < lb;
    }
    int ra = suffix_rank(a), rb = suffix_rank(b);
    if (ra != rb) return ra < rb;
    return strcmp(a, b) < 0;
}

/* Decoding goes through a planar scratch buffer (one plane per channel), copied into img by
 * name afterwards: OpenEXRCore 3.1's interleaved fast paths (e.g. four HALF channels decoded
 * to interleaved FLOAT) write the channels in the file's (alphabetical: A, B, G, R) order from
 * the first channel's pointer, which put A into R and ran past the pixel. */
typedef struct exr_scratch {
    float *buf;
    size_t cap; /* floats */
} exr_scratch;

/* Points every decoder channel at its plane of the scratch buffer for the chunk whose
 * top-left pixel is (x0, y0) relative to the data window. */
static gr_status aim_decoder(exr_decode_pipeline_t *dec, gr_image *img, int x0, int y0, exr_scratch *sc,
                             const char *path, gr_error *err)
{
    size_t total = 0;
    for (int i = 0; i < dec->channel_count; i++) {
        exr_coding_channel_info_t *ch = &dec->channels[i];
        if (gr_image_channel(img, ch->channel_name) < 0)
            return gr_fail(err, GR_E_INPUT, "%s: chunk channel '%s' is not in the channel list", path, ch->channel_name);
        if (ch->height == 0 || ch->width == 0) continue;
        if (x0 < 0 || y0 < 0 || x0 + ch->width > img->width || y0 + ch->height > img->height)
            return gr_fail(err, GR_E_INPUT, "%s: chunk at (%d, %d) of %d x %d pixels does not fit the %d x %d data window",
                           path, x0, y0, ch->width, ch->height, img->width, img->height);
        total += (size_t)ch->width * (size_t)ch->height;
    }
    if (total > sc->cap) {
        float *b = realloc(sc->buf, total * sizeof *b);
        if (!b) return gr_fail(err, GR_E_NOMEM, "%s: out of memory for a chunk of %zu samples", path, total);
        sc->buf = b;
        sc->cap = total;
    }
    size_t off = 0;
    for (int i = 0; i < dec->channel_count; i++) {
        exr_coding_channel_info_t *ch = &dec->channels[i];
        if (ch->height == 0 || ch->width == 0) { ch->decode_to_ptr = NULL; continue; }
        ch->user_bytes_per_element = (int16_t)sizeof(float);
        ch->user_data_type = EXR_PIXEL_FLOAT; /* HALF and UINT are converted by the decoder */
        ch->user_pixel_stride = (int32_t)sizeof(float);
        ch->user_line_stride = (int32_t)((size_t)ch->width * sizeof(float));
        ch->decode_to_ptr = (uint8_t *)(sc->buf + off);
        off += (size_t)ch->width * (size_t)ch->height;
    }
    return GR_OK;
}

/* Copies the decoded planes into img, each channel to its place by name. */
static void scatter_planes(const exr_decode_pipeline_t *dec, gr_image *img, int x0, int y0, const exr_scratch *sc)
{
    const size_t nc = (size_t)img->nchannels, w = (size_t)img->width;
    size_t off = 0;
    for (int i = 0; i < dec->channel_count; i++) {
        const exr_coding_channel_info_t *ch = &dec->channels[i];
        if (ch->height == 0 || ch->width == 0) continue;
        const size_t c = (size_t)gr_image_channel(img, ch->channel_name);
        for (int y = 0; y < ch->height; y++) {
            const float *src = sc->buf + off + (size_t)y * (size_t)ch->width;
            float *dst = img->pixels + ((size_t)(y0 + y) * w + (size_t)x0) * nc + c;
            for (int x = 0; x < ch->width; x++) dst[(size_t)x * nc] = src[x];
        }
        off += (size_t)ch->width * (size_t)ch->height;
    }
}

static gr_status decode_chunk(exr_const_context_t ctx, const exr_chunk_info_t *cinfo,
                              exr_decode_pipeline_t *dec, int *first, gr_image *img, int x0, int y0,
                              exr_scratch *sc, const char *path, gr_error *err)
{
    exr_result_t rv = *first ? exr_decoding_initialize(ctx, 0, cinfo, dec)
                             : exr_decoding_update(ctx, 0, cinfo, dec);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "decoder setup");
    gr_status st = aim_decoder(dec, img, x0, y0, sc, path, err);
    if (st != GR_OK) return st;
    if (*first) {
        rv = exr_decoding_choose_default_routines(ctx, 0, dec);
        if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "decoder routines");
        *first = 0;
    }
    rv = exr_decoding_run(ctx, 0, dec);
    if (rv != EXR_ERR_SUCCESS) {
        char what[96];
        snprintf(what, sizeof what, "decoding the chunk at (%d, %d)", x0, y0);
        return exr_fail(err, path, rv, GR_E_INPUT, what);
    }
    scatter_planes(dec, img, x0, y0, sc);
    return GR_OK;
}

static gr_status read_pixels(exr_const_context_t ctx, exr_storage_t storage, gr_image *img,
                             const char *path, gr_error *err)
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_attr_box2i_t dw;
    exr_result_t rv = exr_get_data_window(ctx, 0, &dw);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "data window");
    gr_status st = GR_OK;
    int first = 1;
    exr_scratch sc = {NULL, 0};
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        if (rv != EXR_ERR_SUCCESS || lines <= 0) return exr_fail(err, path, rv, GR_E_INPUT, "scanlines per chunk");
        for (int64_t y = dw.min.y; y <= dw.max.y && st == GR_OK; y += lines) {
            exr_chunk_info_t cinfo;
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &cinfo);
            if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_INPUT, "chunk table"); break; }
            st = decode_chunk(ctx, &cinfo, &dec, &first, img, 0, cinfo.start_y - dw.min.y, &sc, path, err);
        }
    } else {
        /* Tiled: level 0 (the full-resolution image) of any level mode. */
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t lm;
        exr_tile_round_mode_t rm;
        rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, &lm, &rm);
        if (rv != EXR_ERR_SUCCESS || tw == 0 || th == 0) return exr_fail(err, path, rv, GR_E_INPUT, "tile description");
        int ntx = (int)(((uint32_t)img->width + tw - 1) / tw), nty = (int)(((uint32_t)img->height + th - 1) / th);
        for (int ty = 0; ty < nty && st == GR_OK; ty++) {
            for (int tx = 0; tx < ntx && st == GR_OK; tx++) {
                exr_chunk_info_t cinfo;
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &cinfo);
                if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_INPUT, "tile table"); break; }
                st = decode_chunk(ctx, &cinfo, &dec, &first, img, (int)((uint32_t)tx * tw), (int)((uint32_t)ty * th), &sc, path, err);
            }
        }
    }
    if (!first || dec.channels) exr_decoding_destroy(ctx, &dec);
    free(sc.buf);
    return st;
}

/* The chunk table against the file, before the image is allocated: every chunk must lie
 * inside the file, and an uncompressed chunk must hold exactly the bytes its pixels need
 * (a shrunken chunk was decoded as invented samples). */
static gr_status check_one_chunk(const exr_chunk_info_t *c, long long file_size, const char *path, gr_error *err)
{
    if (file_size >= 0 && (c->data_offset > (uint64_t)file_size || c->packed_size > (uint64_t)file_size - c->data_offset))
        return gr_fail(err, GR_E_INPUT, "%s: chunk at line %d claims %llu bytes at offset %llu, past the end of the "
                       "%lld-byte file", path, c->start_y, (unsigned long long)c->packed_size,
                       (unsigned long long)c->data_offset, file_size);
    if (c->compression == EXR_COMPRESSION_NONE && c->packed_size != c->unpacked_size)
        return gr_fail(err, GR_E_INPUT, "%s: uncompressed chunk at line %d holds %llu bytes, its pixels need %llu", path,
                       c->start_y, (unsigned long long)c->packed_size, (unsigned long long)c->unpacked_size);
    return GR_OK;
}

static gr_status check_chunks(exr_const_context_t ctx, exr_storage_t storage, const exr_attr_box2i_t *dw,
                              long long file_size, const char *path, gr_error *err)
{
    int32_t count = 0;
    exr_result_t rv = exr_get_chunk_count(ctx, 0, &count);
    if (rv != EXR_ERR_SUCCESS || count <= 0) return exr_fail(err, path, rv, GR_E_INPUT, "chunk count");
    if (file_size >= 0 && (long long)count * 8 > file_size)
        return gr_fail(err, GR_E_INPUT, "%s: %d chunks need a %lld-byte offset table, the file has %lld bytes", path,
                       count, (long long)count * 8, file_size);
    gr_status st = GR_OK;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        if (rv != EXR_ERR_SUCCESS || lines <= 0) return exr_fail(err, path, rv, GR_E_INPUT, "scanlines per chunk");
        for (int64_t y = dw->min.y; y <= dw->max.y && st == GR_OK; y += lines) {
            exr_chunk_info_t c;
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &c);
            if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "chunk table");
            st = check_one_chunk(&c, file_size, path, err);
        }
    } else {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t lm;
        exr_tile_round_mode_t rm;
        rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, &lm, &rm);
        if (rv != EXR_ERR_SUCCESS || tw == 0 || th == 0) return exr_fail(err, path, rv, GR_E_INPUT, "tile description");
        const int64_t W = (int64_t)dw->max.x - dw->min.x + 1, H = (int64_t)dw->max.y - dw->min.y + 1;
        const int ntx = (int)((W + tw - 1) / tw), nty = (int)((H + th - 1) / th);
        for (int ty = 0; ty < nty && st == GR_OK; ty++)
            for (int tx = 0; tx < ntx && st == GR_OK; tx++) {
                exr_chunk_info_t c;
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &c);
                if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "tile table");
                st = check_one_chunk(&c, file_size, path, err);
            }
    }
    return st;
}

/* Collects string/float/double/int attributes that are not file structure. */
static gr_status read_attrs(exr_const_context_t ctx, gr_metadata *meta, const char *path, gr_error *err)
{
    int32_t n = 0;
    exr_result_t rv = exr_get_attribute_count(ctx, 0, &n);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "attributes");
    for (int32_t i = 0; i < n; i++) {
        const exr_attribute_t *a = NULL;
        rv = exr_get_attribute_by_index(ctx, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a);
        if (rv != EXR_ERR_SUCCESS || !a) return exr_fail(err, path, rv, GR_E_INPUT, "attributes");
        /* Keys longer than gr_meta_item.key holds are skipped rather than truncated. */
        if (is_structural_attr(a->name) || strlen(a->name) >= sizeof(((gr_meta_item *)0)->key)) continue;
        gr_status st = GR_OK;
        switch (a->type) {
        case EXR_ATTR_STRING: {
            const exr_attr_string_t *s = a->string;
            size_t len = (s && s->str && s->length > 0) ? (size_t)s->length : 0;
            char *copy = malloc(len + 1);
            if (!copy) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
            if (len) memcpy(copy, s->str, len);
            copy[len] = '\0';
            st = gr_meta_set_string(meta, a->name, copy);
            free(copy);
            break;
        }
        case EXR_ATTR_FLOAT: st = gr_meta_set_double(meta, a->name, (double)a->f); break;
        case EXR_ATTR_DOUBLE: st = gr_meta_set_double(meta, a->name, a->d); break;
        case EXR_ATTR_INT: st = gr_meta_set_int(meta, a->name, a->i); break;
        default: break; /* vectors, matrices, ...: not metadata we carry */
        }
        if (st == GR_E_NOMEM) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    return GR_OK;
}

/* Checks the file is there and starts with the EXR magic number, for a clear message. */
static gr_status probe_file(const char *path, gr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return gr_fail(err, GR_E_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char magic[4] = {0, 0, 0, 0};
    errno = 0;
    size_t got = fread(magic, 1, sizeof magic, f);
    int read_err = ferror(f), read_errno = errno;
    fclose(f);
    if (read_err) return gr_fail(err, GR_E_IO, "%s: cannot read: %s", path, strerror(read_errno));
    /* OpenEXR magic number 20000630 = 0x01312f76, little-endian. */
    if (got < 4 || magic[0] != 0x76 || magic[1] != 0x2f || magic[2] != 0x31 || magic[3] != 0x01)
        return gr_fail(err, GR_E_INPUT, "%s: not an OpenEXR file (bad magic number)", path);
    return GR_OK;
}

/* One part only: a multi-part file's first part was read without a word (issue 31), though
 * the others may hold what was meant (another view, layer or frame). Refused, naming the parts. */
static gr_status check_single_part(exr_const_context_t ctx, const char *path, gr_error *err)
{
    int n = 0;
    exr_result_t rv = exr_get_count(ctx, &n);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, path, rv, GR_E_INPUT, "part count");
    if (n == 1) return GR_OK;
    char names[160] = "";
    for (int i = 0; i < n && i < 4; i++) {
        const char *nm = NULL;
        if (exr_get_name(ctx, i, &nm) != EXR_ERR_SUCCESS || !nm) nm = "?";
        size_t l = strlen(names);
        snprintf(names + l, sizeof names - l, "%s'%.24s'", i ? ", " : "", nm);
    }
    return gr_fail(err, GR_E_INPUT, "%s: a multi-part EXR file of %d parts (%s%s); godrays reads single-part files: "
                   "extract the one meant first, e.g. oiiotool %s --subimage NAME -o ONE.exr", path, n, names,
                   n > 4 ? ", ..." : "", path);
}

gr_status gr_exr_check(const char *path, gr_error *err)
{
    if (!path || !path[0]) return gr_fail(err, GR_E_USAGE, "EXR check: no input path");
    gr_status st = gr_check_regular_input(path, err);
    if (st == GR_OK) st = probe_file(path, err);
    if (st != GR_OK) return st;
    struct stat fsb;
    const long long file_size = stat(path, &fsb) == 0 ? (long long)fsb.st_size : -1;
    g_exr_msg[0] = '\0';
    exr_context_initializer_t init = exr_init_for(1);
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    if (rv != EXR_ERR_SUCCESS) {
        st = exr_fail(err, path, rv, GR_E_INPUT, "bad header");
    } else if ((st = check_single_part(ctx, path, err)) != GR_OK) {
        /* the message is set */
    } else if ((rv = exr_get_storage(ctx, 0, &storage)) != EXR_ERR_SUCCESS) {
        st = exr_fail(err, path, rv, GR_E_INPUT, "storage type");
    } else if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        st = gr_fail(err, GR_E_INPUT, "%s: deep or unknown EXR storage (%d) is not supported", path, (int)storage);
    } else if ((rv = exr_get_data_window(ctx, 0, &dw)) != EXR_ERR_SUCCESS) {
        st = exr_fail(err, path, rv, GR_E_INPUT, "data window");
    } else {
        st = gr_image_check_size(path, (int64_t)dw.max.x - dw.min.x + 1, (int64_t)dw.max.y - dw.min.y + 1, 1, err);
        if (st == GR_OK) st = check_chunks(ctx, storage, &dw, file_size, path, err);
    }
    if (ctx) exr_finish(&ctx);
    return st;
}

gr_status gr_exr_read(const char *path, gr_image **out, gr_metadata *meta, gr_error *err)
{
    return gr_exr_read_bits(path, out, meta, NULL, err);
}

gr_status gr_exr_read_bits(const char *path, gr_image **out, gr_metadata *meta, int *bits, gr_error *err)
{
    if (out) *out = NULL;
    if (!path || !path[0] || !out) return gr_fail(err, GR_E_USAGE, "EXR read: no input path or output");
    gr_status st = gr_check_regular_input(path, err); /* a FIFO would block the open */
    if (st == GR_OK) st = probe_file(path, err);
    if (st != GR_OK) return st;
    struct stat fsb;
    const long long file_size = stat(path, &fsb) == 0 ? (long long)fsb.st_size : -1;

    g_exr_msg[0] = '\0';
    exr_context_initializer_t init = exr_init_for(1);
    exr_context_t ctx = NULL;
    gr_image *img = NULL;
    int widest = 0; /* bits of the widest sample */
    gr_metadata attrs;
    gr_meta_init(&attrs);
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_INPUT, "bad header"); goto done; }
    if ((st = check_single_part(ctx, path, err)) != GR_OK) goto done;

    exr_storage_t storage;
    rv = exr_get_storage(ctx, 0, &storage);
    if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_INPUT, "storage type"); goto done; }
    if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED) {
        st = gr_fail(err, GR_E_INPUT, "%s: deep EXR files are not supported", path);
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        st = gr_fail(err, GR_E_INPUT, "%s: unknown EXR storage type %d", path, (int)storage);
        goto done;
    }
    exr_attr_box2i_t dw;
    rv = exr_get_data_window(ctx, 0, &dw);
    if (rv != EXR_ERR_SUCCESS) { st = exr_fail(err, path, rv, GR_E_INPUT, "data window"); goto done; }
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT32_MAX || h > INT32_MAX) {
        st = gr_fail(err, GR_E_INPUT, "%s: bad data window (%d, %d) - (%d, %d)", path, dw.min.x, dw.min.y, dw.max.x, dw.max.y);
        goto done;
    }
    /* Bounded before anything is allocated (image.h), then the chunk table checked against
     * the file: a header of a few bytes may not claim gigabytes. */
    st = gr_image_check_size(path, w, h, 1, err);
    if (st != GR_OK) goto done;
    st = check_chunks(ctx, storage, &dw, file_size, path, err);
    if (st != GR_OK) goto done;

    const exr_attr_chlist_t *chl = NULL;
    rv = exr_get_channels(ctx, 0, &chl);
    if (rv != EXR_ERR_SUCCESS || !chl) { st = exr_fail(err, path, rv, GR_E_INPUT, "channel list"); goto done; }
    int nc = chl->num_channels;
    if (nc <= 0 || nc > GR_IMAGE_MAX_CHANNELS) {
        st = gr_fail(err, GR_E_INPUT, "%s: %d channels (1 to %d supported)", path, nc, GR_IMAGE_MAX_CHANNELS);
        goto done;
    }
    const char *names[GR_IMAGE_MAX_CHANNELS];
    for (int i = 0; i < nc; i++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[i];
        if (e->name.length <= 0 || e->name.length >= GR_CHANNEL_NAME_MAX) {
            st = gr_fail(err, GR_E_INPUT, "%s: channel %d name is empty or longer than %d characters", path, i, GR_CHANNEL_NAME_MAX - 1);
            goto done;
        }
        if (e->x_sampling != 1 || e->y_sampling != 1) {
            st = gr_fail(err, GR_E_INPUT, "%s: channel '%s' is subsampled (%d x %d): not supported", path, e->name.str, e->x_sampling, e->y_sampling);
            goto done;
        }
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT && e->pixel_type != EXR_PIXEL_UINT) {
            st = gr_fail(err, GR_E_INPUT, "%s: channel '%s' has unknown pixel type %d", path, e->name.str, (int)e->pixel_type);
            goto done;
        }
        const int b = e->pixel_type == EXR_PIXEL_HALF ? 16 : 32;
        if (b > widest) widest = b;
        /* insertion sort into the canonical order */
        int j = i;
        while (j > 0 && channel_before(e->name.str, names[j - 1])) {
            names[j] = names[j - 1];
            j--;
        }
        names[j] = e->name.str;
    }
    img = gr_image_create((int)w, (int)h, nc, names);
    if (!img) { st = gr_fail(err, GR_E_NOMEM, "%s: cannot allocate %lld x %lld x %d image", path, (long long)w, (long long)h, nc); goto done; }
    if ((long long)img->width * nc * (long long)sizeof(float) > INT32_MAX) {
        st = gr_fail(err, GR_E_INPUT, "%s: image too wide (%d pixels)", path, img->width);
        goto done;
    }
    st = read_pixels(ctx, storage, img, path, err);
    if (st != GR_OK) goto done;
    /* The project rule: no NaN or Inf reaches an image, also from outside files. */
    st = gr_image_check_finite(img, path, err);
    if (st != GR_OK) { st = err ? (err->status = GR_E_INPUT) : GR_E_INPUT; goto done; }
    if (meta) st = read_attrs(ctx, &attrs, path, err);

done:
    if (ctx) exr_finish(&ctx);
    if (st == GR_OK && meta) {
        for (int i = 0; i < attrs.count && st == GR_OK; i++) {
            const gr_meta_item *it = &attrs.items[i];
            st = it->type == GR_META_STRING ? gr_meta_set_string(meta, it->key, it->str)
               : it->type == GR_META_INT ? gr_meta_set_int(meta, it->key, (long long)it->num)
                                         : gr_meta_set_double(meta, it->key, it->num);
        }
        if (st != GR_OK) st = gr_fail(err, st, "%s: out of memory", path);
    }
    gr_meta_free(&attrs);
    if (st != GR_OK) {
        gr_image_destroy(img);
        return st;
    }
    *out = img;
    if (bits) *bits = widest;
    return GR_OK;
}
