/* FLIP (src/compare/flip.c) against the published FLIP tool v1.6 (NVlabs), whose outputs on
 * these images are in tests/data/flip/README.md (copied from ../shared/oracles/flip/): the
 * means within 1e-4, min/max within 1e-3, the LDR per-pixel map within 1/255 of the tool's
 * 8-bit map; plus closed-form properties (identical images give 0, exposures of a uniform
 * image). A prepared reference (gr_flip_reference_create) must give every row's results and map
 * bit for bit, made on 1 or 3 threads, and refuse another image or other settings. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/flip.h"
#include "image/oiio.h"

static char dir[4096];

static gr_image *load(const char *name)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    gr_image *img = NULL;
    gr_error err = {0};
    gr_status st = gr_oiio_read(path, 1, &img, &err);
    CHECK_OK(st, err);
    return img;
}

typedef struct row {
    const char *ref, *test;
    gr_flip_mode mode;
    double ppd;
    gr_flip_tonemapper tm;
    int given;
    double start, stop;
    int count;
    double mean, min, max; /* min/max < 0: not given */
    double exp_start, exp_stop; /* expected automatic exposures (0 0: not checked) */
} row;

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    snprintf(dir, sizeof dir, "%s/tests/data/flip", src ? src : ".");
    const row rows[] = {
        {"ref_ldr.png", "shafts_ldr.png", GR_FLIP_LDR, 0, 0, 0, 0, 0, 0, 0.178733, 0.013860, 0.774375, 0, 0},
        {"noise_a.png", "noise_b.png", GR_FLIP_LDR, 0, 0, 0, 0, 0, 0, 0.331711, 0.022135, 0.880564, 0, 0},
        {"ref_ldr.png", "shafts_ldr.png", GR_FLIP_LDR, 30, 0, 0, 0, 0, 0, 0.175024, 0.012909, 0.853288, 0, 0},
        {"ref_hdr.exr", "shafts_scaled_hdr.exr", GR_FLIP_HDR, 0, GR_FLIP_TM_ACES, 0, 0, 0, 0, 0.764852, 0.534972,
         0.900520, -0.7027, 7.3805},
        {"ref_hdr.exr", "shafts_raw_hdr.exr", GR_FLIP_HDR, 0, GR_FLIP_TM_ACES, 0, 0, 0, 0, 0.971739, 0.892309, 0.976408,
         -0.7027, 7.3805},
        {"ref_hdr.exr", "ref_x125_hdr.exr", GR_FLIP_HDR, 0, GR_FLIP_TM_ACES, 0, 0, 0, 0, 0.292590, 0.172747, 0.316149,
         -0.7027, 7.3805},
        {"ref_hdr.exr", "shafts_scaled_hdr.exr", GR_FLIP_HDR, 30, GR_FLIP_TM_ACES, 0, 0, 0, 0, 0.757416, 0.461965,
         0.900841, 0, 0},
        {"ref_hdr.exr", "shafts_scaled_hdr.exr", GR_FLIP_HDR, 0, GR_FLIP_TM_REINHARD, 0, 0, 0, 0, 0.628543, -1, -1,
         0.7165, 8.7997},
        {"ref_hdr.exr", "shafts_scaled_hdr.exr", GR_FLIP_HDR, 0, GR_FLIP_TM_ACES, 1, -1, 3, 5, 0.508269, -1, -1, 0, 0},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const row *r = &rows[i];
        gr_image *a = load(r->ref), *b = load(r->test);
        if (!a || !b) continue;
        gr_flip_options o = {.mode = r->mode, .ppd = r->ppd, .tonemapper = r->tm, .exposures_given = r->given,
                             .start_exposure = r->start, .stop_exposure = r->stop, .n_exposures = r->count};
        gr_flip_result res;
        gr_error err = {0};
        float *map = malloc((size_t)a->width * (size_t)a->height * sizeof(float));
        gr_status st = gr_flip_compute(a, b, &o, map, &res, &err);
        CHECK_OK(st, err);
        printf("%s vs %s (%s, ppd %g, %s): mean %.6f (tool %.6f, diff %.2e) min %.6f max %.6f exposures %.4f..%.4f x%d\n",
               r->ref, r->test, gr_flip_mode_name(r->mode), res.ppd, gr_flip_tonemapper_name(r->tm), res.mean, r->mean,
               res.mean - r->mean, res.min, res.max, res.start_exposure, res.stop_exposure, res.n_exposures);
        CHECK_NEAR(res.mean, r->mean, 1e-4);
        if (r->min >= 0) {
            CHECK_NEAR(res.min, r->min, 1e-3);
            CHECK_NEAR(res.max, r->max, 1e-3);
        }
        if (r->exp_start != 0.0 || r->exp_stop != 0.0) {
            CHECK_NEAR(res.start_exposure, r->exp_start, 1e-4);
            CHECK_NEAR(res.stop_exposure, r->exp_stop, 1e-4);
            CHECK(res.n_exposures == 9);
        }
        if (i == 0) {
            /* the tool's per-pixel map, 8-bit gray: round(255 FLIP) */
            gr_image *g = NULL;
            char path[4400];
            snprintf(path, sizeof path, "%s/ref_ldr_vs_shafts_ldr_flipmap_gray8.png", dir);
            st = gr_oiio_read(path, 0, &g, &err);
            CHECK_OK(st, err);
            if (g) {
                double worst = 0.0;
                int wx = 0, wy = 0;
                for (int y = 0; y < g->height; y++)
                    for (int x = 0; x < g->width; x++) {
                        const size_t p = (size_t)y * (size_t)g->width + (size_t)x;
                        const double d = fabs((double)map[p] - (double)g->pixels[p * (size_t)g->nchannels]);
                        if (d > worst) worst = d, wx = x, wy = y;
                    }
                /* the tool's value was rounded to 8 bits: allow 1/255 plus that half step */
                printf("per-pixel LDR map: max |ours - tool's 8-bit| = %.5f (= %.3f / 255) at (%d, %d)\n", worst,
                       255.0 * worst, wx, wy);
                CHECK(worst <= 1.5 / 255.0);
                gr_image_destroy(g);
            }
        }
        /* the reference's half prepared once (on 1 thread for even rows, 3 for odd ones: the
         * same bytes either way): the same results and map, bit for bit, for the test as given
         * and scaled, through gr_flip_compute and (scaled) gr_flip_compute_defined */
        {
            gr_flip_reference *fr = NULL;
            CHECK_OK(gr_flip_reference_create(a, &o, (size_t)1 << 30, i % 2 ? 3 : 1, &fr, &err), err);
            CHECK(fr != NULL && gr_flip_reference_has_planes(fr) && gr_flip_reference_matches(fr, a, &o) &&
                  !gr_flip_reference_matches(fr, b, &o));
            CHECK(gr_flip_reference_bytes(fr) >= (size_t)a->width * (size_t)a->height * 40);
            float *m2 = malloc((size_t)a->width * (size_t)a->height * sizeof(float));
            for (int sc = 0; sc < 2; sc++) {
                gr_flip_options o1 = o, o2 = o;
                o1.test_scale = o2.test_scale = sc ? 1.7 : 0.0;
                o2.reference = fr;
                gr_flip_result r1, r2;
                if (sc == 0) {
                    CHECK_OK(gr_flip_compute(a, b, &o1, map, &r1, &err), err);
                    CHECK_OK(gr_flip_compute(a, b, &o2, m2, &r2, &err), err);
                } else {
                    int u1 = 0, u2 = 0;
                    CHECK_OK(gr_flip_compute_defined(a, b, &o1, map, &r1, &u1, NULL, 0, &err), err);
                    CHECK_OK(gr_flip_compute_defined(a, b, &o2, m2, &r2, &u2, NULL, 0, &err), err);
                    CHECK(!u1 && !u2);
                }
                CHECK(memcmp(&r1, &r2, sizeof r1) == 0);
                CHECK(memcmp(map, m2, (size_t)a->width * (size_t)a->height * sizeof(float)) == 0);
            }
            free(m2);
            /* another test image as the reference, or other settings: refused */
            gr_flip_options o3 = o;
            o3.reference = fr;
            CHECK(gr_flip_compute(b, a, &o3, NULL, &res, &err) == GR_E_INPUT && strstr(err.msg, "prepared reference"));
            o3.ppd = 12.0;
            CHECK(!gr_flip_reference_matches(fr, a, &o3));
            CHECK(gr_flip_compute(a, b, &o3, NULL, &res, &err) == GR_E_INPUT && strstr(err.msg, "prepared reference"));
            gr_flip_reference_destroy(fr);
        }
        /* over its memory bound: no planes, and FLIP given it computes as without (the same
         * bytes); it still matches, so that a kept one is not remade */
        {
            gr_flip_reference *np = NULL;
            CHECK_OK(gr_flip_reference_create(a, &o, 1000, 1, &np, &err), err);
            CHECK(np != NULL && !gr_flip_reference_has_planes(np) && gr_flip_reference_matches(np, a, &o));
            CHECK(gr_flip_reference_bytes(np) < 1000);
            gr_flip_options o2 = o;
            o2.reference = np;
            gr_flip_result r1, r2;
            float *m2 = malloc((size_t)a->width * (size_t)a->height * sizeof(float));
            CHECK_OK(gr_flip_compute(a, b, &o, map, &r1, &err), err);
            CHECK_OK(gr_flip_compute(a, b, &o2, m2, &r2, &err), err);
            CHECK(memcmp(&r1, &r2, sizeof r1) == 0);
            CHECK(memcmp(map, m2, (size_t)a->width * (size_t)a->height * sizeof(float)) == 0);
            free(m2);
            gr_flip_reference_destroy(np);
        }
        /* identical images: FLIP 0 everywhere (closed form: zero colour and feature error) */
        st = gr_flip_compute(a, a, &o, map, &res, &err);
        CHECK_OK(st, err);
        CHECK(res.max == 0.0 && res.mean == 0.0);
        free(map);
        gr_image_destroy(a);
        gr_image_destroy(b);
    }
    /* exposures of a uniform luminance-1 image under Reinhard: x_0.85 = 0.85 / 0.15, so
     * start = stop = log2(5.667), count 2 */
    gr_image *u = gr_image_create(8, 8, 3, NULL);
    for (int i = 0; i < 8 * 8 * 3; i++) u->pixels[i] = 1.0f;
    double s0, s1;
    int cnt;
    gr_error err = {0};
    CHECK_OK(gr_flip_exposures(u, GR_FLIP_TM_REINHARD, &s0, &s1, &cnt, &err), err);
    CHECK_NEAR(s0, log2(0.85 / 0.15), 1e-12);
    CHECK_NEAR(s1, log2(0.85 / 0.15), 1e-12);
    CHECK(cnt == 2);
    /* a black truth: no HDR exposure range; prepared as such, gr_flip_compute_defined says
     * undefined through it as without it */
    {
        gr_image *k = gr_image_create(8, 8, 3, NULL);
        gr_flip_options ho = {.mode = GR_FLIP_HDR};
        gr_flip_reference *fr = NULL;
        CHECK_OK(gr_flip_reference_create(k, &ho, (size_t)1 << 30, 2, &fr, &err), err);
        CHECK(fr != NULL);
        ho.reference = fr;
        int und = 0;
        char why[256] = "";
        gr_flip_result rr;
        CHECK_OK(gr_flip_compute_defined(k, u, &ho, NULL, &rr, &und, why, sizeof why, &err), err);
        CHECK(und == 1 && isnan(rr.mean) && strstr(why, "not > 0"));
        gr_flip_reference_destroy(fr);
        gr_image_destroy(k);
    }
    /* bad input: size mismatch, ppd <= 0 */
    gr_image *v = gr_image_create(4, 8, 3, NULL);
    gr_flip_result res;
    CHECK(gr_flip_compute(u, v, NULL, NULL, &res, &err) == GR_E_INPUT && strstr(err.msg, "size mismatch"));
    gr_flip_options bad = {.ppd = -1};
    CHECK(gr_flip_compute(u, u, &bad, NULL, &res, &err) == GR_E_INPUT && strstr(err.msg, "pixels per degree"));
    gr_image_destroy(u);
    gr_image_destroy(v);
    CHECK_DONE();
}
