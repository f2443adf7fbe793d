/* The radial blur pass (radial_blur.frag.glsl) on injected light textures against the
 * geometric sums of seed 004's listing (GPU Gems 3 ch. 13):
 *   out(uv) = scale [L(uv) + weight sum_{i=1..N} decay^(i-1) L(uv - i delta)],
 *   delta = (uv - sun_uv) density / N.
 * - Uniform light L: every pixel is scale L (1 + weight (1 - decay^N) / (1 - decay)), for
 *   several N, decays (decay = 1: 1 + weight N) and with the dither on (it only moves taps).
 * - One bright texel at the light's position (texture = output size, so pixel and texel
 *   centres coincide): the pixel on the light gets the full sum; a pixel k texels away with
 *   density 1 and N taps gets exactly the taps that land on the texel centre, weight
 *   decay^(N-1) (k = N and k = 2N, along an axis and a diagonal); k = N/2 adds the tap
 *   half a texel off with bilinear weight 1/2; with density 1/2 no tap reaches the light (0).
 * - Taps that leave the texture read black (no edge smear): a light outside the texture. */
#include <math.h>

#include "gl/glctx.h"
#include "rb_test.h"

static void blur(void *st, const gr_image *light, double su, double sv, const gr_radial_blur_settings *s,
                 const double sc[3], gr_image *out)
{
    gr_error err;
    double uv[2] = {su, sv};
    if (gr_radial_blur_blur_image(st, light, uv, s, sc, out, &err) != GR_OK) {
        fprintf(stderr, "blur: %s\n", err.msg);
        exit(1);
    }
}

int main(void)
{
    gr_gl *gl = NULL;
    void *st = rb_test_create(&gr_radial_blur_class, &gl);
    gr_radial_blur_settings s;
    gr_param_defaults(&gr_radial_blur_param_table, &s);
    const double sc[3] = {1.0, 0.5, 0.25};

    /* Uniform light pass. */
    {
        const int W = 64, H = 48;
        gr_image *L = gr_image_create(W, H, 3, NULL), *out = gr_image_create(W, H, 3, NULL);
        for (int i = 0; i < W * H; i++) {
            L->pixels[i * 3] = 1.0f;
            L->pixels[i * 3 + 1] = 2.0f;
            L->pixels[i * 3 + 2] = 3.0f;
        }
        struct { int n; double decay; int dither; } cases[] = {{100, 0.96815, 0}, {100, 0.96815, 1}, {1, 0.5, 0},
                                                               {7, 1.0, 1}, {37, 0.9, 0}};
        for (int k = 0; k < 5; k++) {
            s.samples = cases[k].n;
            s.decay = cases[k].decay;
            s.dither = cases[k].dither;
            blur(st, L, 0.3, 0.6, &s, sc, out);
            double G = cases[k].decay == 1.0 ? 1.0 + s.weight * cases[k].n
                                             : 1.0 + s.weight * (1.0 - pow(cases[k].decay, cases[k].n)) / (1.0 - cases[k].decay);
            CHECK_REL(gr_radial_blur_gain(cases[k].n, cases[k].decay, s.weight), G, 1e-12);
            double worst = 0.0;
            for (int i = 0; i < W * H; i++)
                for (int c = 0; c < 3; c++) {
                    double want = sc[c] * (c + 1.0) * G;
                    worst = fmax(worst, fabs(out->pixels[i * 3 + c] - want) / want);
                }
            printf("uniform N %d decay %g dither %d: G %.6f, worst rel error %.2e\n", cases[k].n, cases[k].decay,
                   cases[k].dither, G, worst);
            CHECK(worst < 2e-5 * (1 + cases[k].n / 10.0));
        }
        gr_image_destroy(L);
        gr_image_destroy(out);
    }

    /* One bright texel. */
    {
        const int W = 64, H = 64, bx = 40, by = 24; /* image coordinates, top row first */
        gr_image *L = gr_image_create(W, H, 3, NULL), *out = gr_image_create(W, H, 3, NULL);
        float *b = gr_image_pixel(L, bx, by);
        b[0] = 1.0f;
        b[1] = 1.0f;
        b[2] = 1.0f;
        double su = (bx + 0.5) / W, sv = 1.0 - (by + 0.5) / H;
        s.dither = 0;
        s.decay = 0.9;
        s.weight = 0.58767;
        /* the light's own pixel: every tap on the texel */
        s.samples = 100;
        s.density = 0.926;
        blur(st, L, su, sv, &s, sc, out);
        double G = gr_radial_blur_gain(100, 0.9, s.weight);
        CHECK_REL(gr_image_pixel(out, bx, by)[0], G, 1e-5);
        CHECK_REL(gr_image_pixel(out, bx, by)[2], 0.25 * G, 1e-5);
        /* density 1, N = 8 */
        s.samples = 8;
        s.density = 1.0;
        blur(st, L, su, sv, &s, sc, out);
        double last = s.weight * pow(0.9, 7);
        struct { int dx, dy; double want; } px[] = {
            {-8, 0, last}, {-16, 0, last}, {8, 8, last}, {0, 16, last}, {-4, 0, last + 0.5 * s.weight * pow(0.9, 6)},
            {-5, 3, -1} /* taps off texel centres: checked only to be finite and >= 0 */};
        for (int k = 0; k < 6; k++) {
            float v = gr_image_pixel(out, bx + px[k].dx, by + px[k].dy)[0];
            printf("texel (%+d, %+d): %.6f want %.6f\n", px[k].dx, px[k].dy, v, px[k].want);
            if (px[k].want >= 0) CHECK_NEAR(v, px[k].want, 2e-3 * px[k].want + 1e-6);
            else CHECK(v >= 0 && isfinite(v));
        }
        /* density 1/2: the taps stop half way, nothing reaches the light 8 texels away */
        s.density = 0.5;
        blur(st, L, su, sv, &s, sc, out);
        CHECK_NEAR(gr_image_pixel(out, bx - 8, by)[0], 0.0, 0);
        CHECK_NEAR(gr_image_pixel(out, bx + 12, by - 12)[0], 0.0, 0);
        /* every pixel's value is a sum of taps weighted at most 1: bounded by G, never negative */
        double worst = 0;
        for (int i = 0; i < W * H; i++) worst = fmax(worst, out->pixels[i * 3]);
        CHECK(worst <= gr_radial_blur_gain(8, 0.9, s.weight) + 1e-6);
        gr_image_destroy(L);
        gr_image_destroy(out);
    }

    /* Light outside the texture, uniform light pass: taps that leave it read black, so a pixel
     * at distance r from the edge toward the light keeps the taps inside only:
     * sum over i with uv - i delta inside. Checked on a pixel row toward a light to the right. */
    {
        const int W = 32, H = 8;
        gr_image *L = gr_image_create(W, H, 3, NULL), *out = gr_image_create(W, H, 3, NULL);
        for (int i = 0; i < W * H * 3; i++) L->pixels[i] = 1.0f;
        s.samples = 16;
        s.density = 1.0;
        s.decay = 1.0;
        s.dither = 0;
        /* light at uv x = 2 (one texture width beyond the right edge), same row as the pixel:
         * pixel x0 = (0.5)/32: taps at x0 + i (2 - x0)/16 inside while < 1 - 0.5/32 exactly
         * (texel-centre spacing: 63/32 / 16 per tap = 3.9375 texels); from the last texel
         * centre outward bilinear blends with the black border over one texel (tent). */
        double sv = 1.0 - 3.5 / H;
        blur(st, L, 2.0, sv, &s, sc, out);
        double x0 = 0.5 / W, step = (2.0 - x0) / 16.0, sum = 1.0; /* centre tap */
        for (int i = 1; i <= 16; i++) {
            double x = (x0 + i * step) * W - 0.5; /* continuous texel coordinate */
            double wgt = x <= W - 1 ? 1.0 : (x < W ? 1.0 - (x - (W - 1)) : 0.0); /* tent to the black border */
            sum += s.weight * wgt;
        }
        float v = gr_image_pixel(out, 0, 3)[0];
        printf("light off the texture: %.6f want %.6f\n", v, sum);
        CHECK_NEAR(v, sum, 5e-3 * sum);
        gr_image_destroy(L);
        gr_image_destroy(out);
    }
    gr_radial_blur_class.destroy(st);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
