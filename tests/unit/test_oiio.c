/* OpenImageIO wrapper (src/image/oiio.cpp): 8-bit sRGB previews, reading any format,
 * float writing. Oracle for the preview: the sRGB OETF of IEC 61966-2-1 evaluated here in
 * double precision, independently of the code under test; for float files, the exact bits
 * read back by OpenEXRCore (gr_exr_read), a different library from the writer. */
#include "check.h"
#include "image/exr.h"
#include "image/oiio.h"
#include "image/png.h"

#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_dir[900];

static void path_of(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", g_dir, name);
}

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static int count_temp_files(void)
{
    DIR *d = opendir(g_dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".tmp-")) n++;
    closedir(d);
    return n;
}

/* IEC 61966-2-1 sRGB encoding of a linear value in [0, 1], as an 8-bit code. */
static int srgb_code(double linear)
{
    double v = linear < 0.0 ? 0.0 : (linear > 1.0 ? 1.0 : linear);
    double e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (int)floor(e * 255.0 + 0.5);
}

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static int code_of(float v)
{
    return (int)lround((double)v * 255.0);
}

/* A gradient through the whole encoding: channel "R" spans [0, 0.6] (x2 exposure: clamps
 * above 0.5), "G" spans [0, 0.004] (the linear toe below 0.0031308 and the power segment
 * just above), "B" goes from -0.04 (clamped to 0) to 0.46; "stderr.R" is huge and must not
 * be picked. */
static void test_preview_gradient(void)
{
    const int W = 256, H = 3;
    const char *names[4] = {"stderr.R", "R", "G", "B"};
    gr_image *img = gr_image_create(W, H, 4, names);
    CHECK(img != NULL);
    if (!img) return;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = gr_image_pixel(img, x, y);
            double t = (double)x / (double)(W - 1);
            p[0] = 1e6f;
            p[1] = (float)(0.6 * t);
            p[2] = (float)(0.004 * t * (1.0 + y));
            p[3] = (float)(0.5 * t - 0.04);
        }
    const double exposure = 2.0;
    const int rgb[3] = {1, 2, 3};
    char path[1024];
    path_of(path, sizeof path, "gradient.png");
    gr_error err = {0};
    gr_status st = gr_png_write_preview(path, img, rgb, exposure, &err);
    CHECK_OK(st, err);
    CHECK(count_temp_files() == 0);

    gr_image *back = NULL;
    st = gr_oiio_read(path, 0, &back, &err);
    CHECK_OK(st, err);
    if (back) {
        CHECK(back->width == W && back->height == H && back->nchannels == 3);
        int worst = 0, toe_differs = 0;
        for (int y = 0; y < H && back->nchannels == 3; y++)
            for (int x = 0; x < W; x++) {
                const float *p = gr_image_pixel(img, x, y);
                const float *q = gr_image_pixel(back, x, y);
                for (int k = 0; k < 3; k++) {
                    double lin = (double)p[rgb[k]] * exposure;
                    int want = srgb_code(lin), got = code_of(q[k]);
                    int d = abs(want - got);
                    if (d > worst) worst = d;
                    if (d > 1 && d == worst) fprintf(stderr, "  (%d, %d) ch %d: linear %g: code %d, want %d\n", x, y, k, lin, got, want);
                    /* Where a pure power law (no linear toe) would be off by more than 1 code. */
                    if (lin > 0.0 && lin < 0.0031308 && abs(want - (int)floor(255.0 * pow(lin, 1.0 / 2.4) + 0.5)) > 1)
                        toe_differs++;
                }
            }
        CHECK_MSG(worst <= 1, "worst code difference %d", worst);
        CHECK_MSG(toe_differs > 50, "the gradient does not exercise the linear toe (%d samples)", toe_differs);
        /* Fixed points of the encoding: 0 -> 0, >= 1 -> 255, 0.5 linear -> 188 (0.7354 * 255). */
        CHECK(code_of(gr_image_pixel(back, 0, 0)[0]) == 0);
        CHECK(code_of(gr_image_pixel(back, W - 1, 0)[0]) == 255);
        CHECK(code_of(gr_image_pixel(back, 0, 0)[2]) == 0); /* negative -> 0 */
    }
    gr_image_destroy(back);

    /* Linearized read: the decoded codes, i.e. srgb_to_linear(code / 255). */
    st = gr_oiio_read(path, 1, &back, &err);
    CHECK_OK(st, err);
    if (back && back->nchannels == 3) {
        double worst = 0.0;
        for (int x = 0; x < W; x++) {
            const float *p = gr_image_pixel(img, x, 1);
            const float *q = gr_image_pixel(back, x, 1);
            for (int k = 0; k < 3; k++) {
                double want = srgb_to_linear(srgb_code((double)p[rgb[k]] * exposure) / 255.0);
                double d = fabs((double)q[k] - want);
                if (d > worst) worst = d;
            }
        }
        CHECK_MSG(worst < 1e-5, "linearized read off by %g", worst);
    }
    gr_image_destroy(back);
    gr_image_destroy(img);
}

static void test_preview_nonfinite(void)
{
    gr_image *img = gr_image_create(4, 1, 3, NULL);
    CHECK(img != NULL);
    if (!img) return;
    for (int i = 0; i < 12; i++) img->pixels[i] = 0.25f;
    gr_image_pixel(img, 0, 0)[0] = NAN;
    gr_image_pixel(img, 1, 0)[1] = INFINITY;
    gr_image_pixel(img, 2, 0)[2] = -INFINITY;
    gr_image_pixel(img, 3, 0)[0] = 0.5f;
    char path[1024];
    path_of(path, sizeof path, "nonfinite.png");
    gr_error err = {0};
    const int rgb[3] = {0, 1, 2};
    gr_status st = gr_png_write_preview(path, img, rgb, 1.0, &err);
    CHECK_OK(st, err);
    gr_image *back = NULL;
    st = gr_oiio_read(path, 0, &back, &err);
    CHECK_OK(st, err);
    if (back && back->nchannels == 3 && back->width == 4) {
        const int q = srgb_code(0.25);
        const int want[4][3] = {{0, q, q}, {q, 0, q}, {q, q, 0}, {srgb_code(0.5), q, q}};
        for (int x = 0; x < 4; x++)
            for (int k = 0; k < 3; k++)
                CHECK_MSG(code_of(gr_image_pixel(back, x, 0)[k]) == want[x][k], "pixel %d ch %d: %d != %d", x, k,
                          code_of(gr_image_pixel(back, x, 0)[k]), want[x][k]);
    }
    gr_image_destroy(back);
    gr_image_destroy(img);
}

/* gr_png_encode_display (watch's page): display values, code = floor(255 v + 0.5), clamped,
 * NaN and +-Inf as 0; the bytes written to a file read back through OpenImageIO's PNG reader
 * (an independent decoder) as those codes. */
static void test_encode_display(void)
{
    const int W = 7, H = 2;
    gr_image *img = gr_image_create(W, H, 4, NULL);
    CHECK(img != NULL);
    if (!img) return;
    const float v[7] = {0.0f, 0.1f, 0.5f, 1.0f, 1.5f, -0.2f, NAN};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 4; k++) gr_image_pixel(img, x, y)[k] = k == 3 ? 0.3f : v[(x + k + y) % W];
    unsigned char *buf = NULL;
    size_t len = 0;
    gr_error err = {0};
    gr_status st = gr_png_encode_display(img, &buf, &len, &err);
    CHECK_OK(st, err);
    CHECK(buf != NULL && len > 8 && buf && memcmp(buf, "\x89PNG\r\n\x1a\n", 8) == 0);
    char path[1024];
    path_of(path, sizeof path, "encoded.png");
    FILE *f = buf ? fopen(path, "wb") : NULL;
    CHECK(f != NULL);
    if (f) {
        CHECK(fwrite(buf, 1, len, f) == len);
        fclose(f);
        gr_image *back = NULL;
        st = gr_oiio_read(path, 0, &back, &err);
        CHECK_OK(st, err);
        if (back && back->nchannels == 3 && back->width == W && back->height == H)
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    for (int k = 0; k < 3; k++) {
                        float a = v[(x + k + y) % W];
                        int want = !isfinite(a) || a <= 0.0f ? 0 : a >= 1.0f ? 255 : (int)floor(255.0 * a + 0.5);
                        CHECK_MSG(code_of(gr_image_pixel(back, x, y)[k]) == want, "encoded (%d, %d) ch %d: %d != %d", x, y,
                                  k, code_of(gr_image_pixel(back, x, y)[k]), want);
                    }
        else
            CHECK_MSG(0, "encoded PNG read back as %d x %d x %d", back ? back->width : -1, back ? back->height : -1,
                      back ? back->nchannels : -1);
        gr_image_destroy(back);
    }
    free(buf);
    gr_image *two = gr_image_create(2, 2, 2, NULL); /* fewer than three channels: refused */
    CHECK(two != NULL);
    CHECK(two && gr_png_encode_display(two, &buf, &len, &err) == GR_E_INPUT && buf == NULL && len == 0);
    gr_image_destroy(two);
    gr_image_destroy(img);
}

/* gr_oiio_write to PNG: values k/255 are exact 8-bit (and 16-bit: 65535 = 255 * 257) codes. */
static void test_write_png(void)
{
    const int W = 16, H = 5;
    gr_image *img = gr_image_create(W, H, 3, NULL);
    CHECK(img != NULL);
    if (!img) return;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++) gr_image_pixel(img, x, y)[k] = (float)((x * 16 + y * 3 + k * 50) % 256) / 255.0f;
    char path[1024];
    path_of(path, sizeof path, "plain.png");
    gr_error err = {0};
    gr_status st = gr_oiio_write(path, img, &err);
    CHECK_OK(st, err);
    gr_image *back = NULL;
    st = gr_oiio_read(path, 0, &back, &err);
    CHECK_OK(st, err);
    if (back) {
        CHECK(back->width == W && back->height == H && back->nchannels == 3);
        CHECK(strcmp(back->names[0], "R") == 0 && strcmp(back->names[1], "G") == 0 && strcmp(back->names[2], "B") == 0);
        double worst = 0.0;
        for (size_t i = 0; i < (size_t)W * H * 3 && back->nchannels == 3; i++) {
            double d = fabs((double)back->pixels[i] - (double)img->pixels[i]);
            if (d > worst) worst = d;
        }
        CHECK_MSG(worst < 1e-6, "PNG round trip off by %g", worst);
    }
    gr_image_destroy(back);
    gr_image_destroy(img);
}

/* gr_oiio_write to EXR: float channels with names, read back bit-exact by OpenEXRCore. */
static void test_write_exr_cross(void)
{
    const char *names[5] = {"R", "G", "B", "A", "transmittance"};
    gr_image *img = gr_image_create(13, 7, 5, names);
    CHECK(img != NULL);
    if (!img) return;
    for (size_t i = 0; i < (size_t)13 * 7 * 5; i++) img->pixels[i] = (float)sin((double)i * 0.37) * 1e3f + 1e-39f * (float)(i % 3);
    char path[1024];
    path_of(path, sizeof path, "via_oiio.exr");
    gr_error err = {0};
    gr_status st = gr_oiio_write(path, img, &err);
    CHECK_OK(st, err);
    gr_image *back = NULL;
    st = gr_exr_read(path, &back, NULL, &err);
    CHECK_OK(st, err);
    if (back) {
        CHECK(back->width == 13 && back->height == 7 && back->nchannels == 5);
        for (int c = 0; c < 5; c++) {
            int cb = gr_image_channel(back, names[c]);
            CHECK_MSG(cb >= 0, "channel %s missing", names[c]);
            if (cb < 0 || back->nchannels != 5) continue;
            int bad = 0;
            for (int p = 0; p < 13 * 7; p++)
                bad += memcmp(&img->pixels[p * 5 + c], &back->pixels[p * 5 + cb], sizeof(float)) != 0;
            CHECK_MSG(bad == 0, "channel %s: %d pixels differ", names[c], bad);
        }
    }
    gr_image_destroy(back);
    gr_image_destroy(img);
}

static void test_version(void)
{
    const char *v = gr_oiio_version();
    CHECK(v != NULL && v[0] != '\0');
    int major = -1, minor = -1, patch = -1;
    CHECK_MSG(v && sscanf(v, "%d.%d.%d", &major, &minor, &patch) == 3 && major >= 2, "version '%s'", v ? v : "(null)");
}

static void test_errors(void)
{
    gr_error err = {0};
    char path[1024];
    gr_image *img = gr_image_create(8, 4, 3, NULL);
    CHECK(img != NULL);
    if (!img) return;
    const int rgb[3] = {0, 1, 2};

    path_of(path, sizeof path, "missing.png");
    gr_image *back = (gr_image *)(uintptr_t)1;
    gr_status st = gr_oiio_read(path, 0, &back, &err);
    CHECK_MSG(st == GR_E_IO && strstr(err.msg, path) && back == NULL, "missing: %d %s", (int)st, err.msg);

    path_of(path, sizeof path, "garbage.png");
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        fputs("definitely not a PNG file\n", f);
        fclose(f);
    }
    st = gr_oiio_read(path, 0, &back, &err);
    CHECK_MSG(st == GR_E_INPUT && strstr(err.msg, path) && strchr(err.msg, '\n') == NULL, "garbage: %d %s", (int)st, err.msg);

    path_of(path, sizeof path, "no_such_dir/p.png");
    st = gr_png_write_preview(path, img, rgb, 1.0, &err);
    CHECK_MSG(st == GR_E_IO && strstr(err.msg, path), "missing dir: %d %s", (int)st, err.msg);
    CHECK(!file_exists(path));

    path_of(path, sizeof path, "bad.png");
    const int bad_rgb[3] = {0, 1, 3};
    st = gr_png_write_preview(path, img, bad_rgb, 1.0, &err);
    CHECK_MSG(st == GR_E_INPUT && strstr(err.msg, path), "bad channel: %d %s", (int)st, err.msg);
    st = gr_png_write_preview(path, img, rgb, -1.0, &err);
    CHECK_MSG(st == GR_E_INPUT && strstr(err.msg, "exposure"), "bad exposure: %d %s", (int)st, err.msg);
    st = gr_png_write_preview(path, img, rgb, NAN, &err);
    CHECK(st == GR_E_INPUT);
    CHECK(!file_exists(path));

    path_of(path, sizeof path, "unknown.notaformat");
    st = gr_oiio_write(path, img, &err);
    CHECK_MSG(st == GR_E_INPUT && strstr(err.msg, path), "unknown format: %d %s", (int)st, err.msg);
    CHECK(!file_exists(path));

    /* Non-finite samples never reach a float file. */
    path_of(path, sizeof path, "nan.exr");
    gr_image_pixel(img, 5, 2)[1] = NAN;
    st = gr_oiio_write(path, img, &err);
    CHECK_MSG(st != GR_OK && strstr(err.msg, "'G'") && strstr(err.msg, "(5, 2)"), "nan: %d %s", (int)st, err.msg);
    CHECK(!file_exists(path));

    CHECK(gr_oiio_read(NULL, 0, &back, &err) == GR_E_USAGE);
    CHECK(gr_png_write_preview(path, NULL, rgb, 1.0, NULL) == GR_E_INPUT); /* err may be NULL */
    CHECK(count_temp_files() == 0);
    gr_image_destroy(img);
}

int main(void)
{
    const char *out = getenv("GODRAYS_TEST_OUT");
    snprintf(g_dir, sizeof g_dir, "%s/test_oiio", out && out[0] ? out : "/tmp");
    if (mkdir(g_dir, 0755) != 0 && errno != EEXIST) {
        fprintf(stderr, "cannot create %s\n", g_dir);
        return 1;
    }
    test_version();
    test_preview_gradient();
    test_preview_nonfinite();
    test_encode_display();
    test_write_png();
    test_write_exr_cross();
    test_errors();
    CHECK_DONE();
}
