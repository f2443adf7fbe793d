/* gr_image and gr_metadata: allocation, channel naming, pixel addressing, ordered metadata. */
#include "check.h"
#include "image/image.h"

#include <stdint.h>
#include <string.h>

static void test_create_default_names(void)
{
    gr_image *img = gr_image_create(5, 3, 4, NULL);
    CHECK(img != NULL);
    if (!img) return;
    CHECK(img->width == 5 && img->height == 3 && img->nchannels == 4);
    CHECK(strcmp(img->names[0], "R") == 0);
    CHECK(strcmp(img->names[1], "G") == 0);
    CHECK(strcmp(img->names[2], "B") == 0);
    CHECK(strcmp(img->names[3], "A") == 0);
    int nonzero = 0;
    for (int i = 0; i < 5 * 3 * 4; i++) nonzero += img->pixels[i] != 0.0f;
    CHECK_MSG(nonzero == 0, "%d samples not zeroed", nonzero);
    CHECK(gr_image_channel(img, "R") == 0);
    CHECK(gr_image_channel(img, "A") == 3);
    CHECK(gr_image_channel(img, "Z") == -1);
    CHECK(gr_image_channel(img, NULL) == -1);
    CHECK(gr_image_channel(NULL, "R") == -1);
    /* Interleaved row-major: (x=2, y=1) in a 5-wide, 4-channel image starts at (1*5+2)*4 = 28. */
    CHECK(gr_image_pixel(img, 2, 1) == img->pixels + 28);
    CHECK(gr_image_pixel(img, 4, 2) == img->pixels + 56);
    gr_image_destroy(img);

    gr_image *six = gr_image_create(2, 2, 6, NULL);
    CHECK(six != NULL);
    if (six) {
        CHECK(strcmp(six->names[4], "c4") == 0);
        CHECK(strcmp(six->names[5], "c5") == 0);
        CHECK(gr_image_channel(six, "c5") == 5);
    }
    gr_image_destroy(six);
    gr_image *one = gr_image_create(1, 1, 1, NULL);
    CHECK(one && strcmp(one->names[0], "R") == 0);
    gr_image_destroy(one);
}

static void test_create_named(void)
{
    const char *names[7] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "transmittance"};
    gr_image *img = gr_image_create(37, 19, 7, names);
    CHECK(img != NULL);
    if (!img) return;
    for (int c = 0; c < 7; c++) CHECK(gr_image_channel(img, names[c]) == c);
    CHECK(gr_image_channel(img, "stderr") == -1); /* no prefix matching */
    gr_image_destroy(img);
}

static void test_create_rejects(void)
{
    CHECK(gr_image_create(0, 4, 3, NULL) == NULL);
    CHECK(gr_image_create(4, 0, 3, NULL) == NULL);
    CHECK(gr_image_create(-1, 4, 3, NULL) == NULL);
    CHECK(gr_image_create(4, 4, 0, NULL) == NULL);
    CHECK(gr_image_create(4, 4, GR_IMAGE_MAX_CHANNELS + 1, NULL) == NULL);
    /* (2^31)^2 * 16 floats * 4 bytes = 2.9e20 > 2^64: the size guard must catch the overflow. */
    CHECK(gr_image_create(INT32_MAX, INT32_MAX, 16, NULL) == NULL);
    char longname[GR_CHANNEL_NAME_MAX + 1];
    memset(longname, 'x', sizeof longname - 1);
    longname[GR_CHANNEL_NAME_MAX] = '\0';
    const char *bad1[2] = {"R", longname};
    CHECK(gr_image_create(2, 2, 2, bad1) == NULL);
    const char *bad2[2] = {"R", ""};
    CHECK(gr_image_create(2, 2, 2, bad2) == NULL);
    const char *bad3[2] = {"R", NULL};
    CHECK(gr_image_create(2, 2, 2, bad3) == NULL);
    /* the longest name that fits */
    longname[GR_CHANNEL_NAME_MAX - 1] = '\0';
    const char *ok[1] = {longname};
    gr_image *img = gr_image_create(1, 1, 1, ok);
    CHECK(img && strlen(img->names[0]) == GR_CHANNEL_NAME_MAX - 1);
    gr_image_destroy(img);
    gr_image_destroy(NULL); /* accepted */
}

static void test_check_finite(void)
{
    gr_image *img = gr_image_create(4, 3, 3, NULL);
    CHECK(img != NULL);
    if (!img) return;
    gr_error err = {0};
    CHECK(gr_image_check_finite(img, "x", &err) == GR_OK);
    gr_image_pixel(img, 2, 1)[1] = NAN;
    gr_image_pixel(img, 3, 2)[0] = INFINITY;
    CHECK(gr_image_check_finite(img, "render.exr", &err) == GR_E_RUNTIME);
    CHECK_MSG(strstr(err.msg, "render.exr") && strstr(err.msg, "'G'") && strstr(err.msg, "(2, 1)") &&
              strstr(err.msg, "nan") && strstr(err.msg, "2 non-finite"), "message: %s", err.msg);
    gr_image_destroy(img);
}

static void test_metadata(void)
{
    gr_metadata m;
    gr_meta_init(&m);
    CHECK(m.count == 0);
    CHECK(gr_meta_get(&m, "godrays:renderer") == NULL);
    CHECK(gr_meta_set_string(&m, "godrays:renderer", "reference") == GR_OK);
    CHECK(gr_meta_set_double(&m, "godrays:exposure", 1.5) == GR_OK);
    CHECK(gr_meta_set_int(&m, "godrays:spp", 64) == GR_OK);
    CHECK(m.count == 3);
    const gr_meta_item *it = gr_meta_get(&m, "godrays:renderer");
    CHECK(it && it->type == GR_META_STRING && strcmp(it->str, "reference") == 0);
    it = gr_meta_get(&m, "godrays:exposure");
    CHECK(it && it->type == GR_META_DOUBLE && it->num == 1.5);
    it = gr_meta_get(&m, "godrays:spp");
    CHECK(it && it->type == GR_META_INT && it->num == 64.0);

    /* Replace keeps the position and the count, and may change the type. */
    CHECK(gr_meta_set_string(&m, "godrays:renderer", "realtime") == GR_OK);
    CHECK(m.count == 3);
    CHECK(strcmp(m.items[0].key, "godrays:renderer") == 0 && strcmp(m.items[0].str, "realtime") == 0);
    CHECK(gr_meta_set_double(&m, "godrays:renderer", 2.0) == GR_OK);
    CHECK(m.count == 3 && m.items[0].type == GR_META_DOUBLE && m.items[0].num == 2.0 && m.items[0].str == NULL);
    CHECK(gr_meta_set_string(&m, "godrays:spp", "sixty-four") == GR_OK);
    CHECK(m.count == 3 && m.items[2].type == GR_META_STRING && strcmp(m.items[2].str, "sixty-four") == 0);
    /* Setting a value from the item's own string (aliasing) must not read freed memory. */
    CHECK(gr_meta_set_string(&m, "godrays:spp", m.items[2].str) == GR_OK);
    CHECK(strcmp(gr_meta_get(&m, "godrays:spp")->str, "sixty-four") == 0);
    CHECK(gr_meta_set_int(&m, "big", 1LL << 40) == GR_OK);
    CHECK(gr_meta_get(&m, "big")->num == 1099511627776.0);

    /* Growth past any initial capacity keeps insertion order. */
    char key[32];
    for (int i = 0; i < 100; i++) {
        snprintf(key, sizeof key, "k%03d", i);
        CHECK(gr_meta_set_int(&m, key, i) == GR_OK);
    }
    CHECK(m.count == 104);
    for (int i = 0; i < 100; i++) {
        snprintf(key, sizeof key, "k%03d", i);
        CHECK(strcmp(m.items[4 + i].key, key) == 0 && m.items[4 + i].num == (double)i);
    }

    /* Bad keys and values. */
    char longkey[80];
    memset(longkey, 'k', 64);
    longkey[64] = '\0';
    CHECK(gr_meta_set_string(&m, longkey, "v") == GR_E_INPUT);
    longkey[63] = '\0';
    CHECK(gr_meta_set_string(&m, longkey, "v") == GR_OK); /* 63 chars fit */
    CHECK(gr_meta_set_string(&m, "", "v") == GR_E_INPUT);
    CHECK(gr_meta_set_string(&m, NULL, "v") == GR_E_INPUT);
    CHECK(gr_meta_set_string(&m, "x", NULL) == GR_E_INPUT);
    CHECK(gr_meta_set_double(NULL, "x", 1.0) == GR_E_INPUT);

    /* Deep copy. */
    gr_metadata c;
    gr_meta_init(&c);
    CHECK(gr_meta_set_string(&c, "old", "gone") == GR_OK);
    CHECK(gr_meta_copy(&c, &m) == GR_OK);
    CHECK(c.count == m.count && gr_meta_get(&c, "old") == NULL);
    CHECK(gr_meta_get(&c, "godrays:spp")->str != gr_meta_get(&m, "godrays:spp")->str);
    CHECK(strcmp(gr_meta_get(&c, "godrays:spp")->str, "sixty-four") == 0);
    gr_meta_free(&c);

    gr_meta_free(&m);
    CHECK(m.count == 0 && m.items == NULL);
    gr_meta_free(&m);  /* twice is fine */
    gr_meta_free(NULL);
}

int main(void)
{
    test_create_default_names();
    test_create_named();
    test_create_rejects();
    test_check_finite();
    test_metadata();
    CHECK_DONE();
}
