/* Acceptance (issue 12): `stable_grid` (P snapped to the grid spacing, S quantized with a
 * cross-fade, the shadow map's texels snapped too; docs/realtime-shafts.md) keeps the shafts
 * put in the world.
 * - The layer's own change ("swim", docs "stable_grid"), the issue's criterion: for a 0.3 m
 *   sideways move A -> B, the camera at B with the grid built for B against the camera at B
 *   with the grid built for A (shafts.grid_eye_m; same camera, so parallax cancels), mean
 *   |dY| / mean Y over 25 start positions that sample the snapping lattice evenly: with
 *   stable_grid at most 1/5 of the camera-locked grid's (seed variant, the issue's; path; flux);
 *   the moves that cross no snap boundary change nothing (below 1e-6; an unsnapped shadow map
 *   gives 2e-3), some but not all moves cross one.
 * - The raw image change for the same move (mean |dY| / mean Y between the renders at A and
 *   at B) is printed with the ground truth's own raw change: both are dominated by parallax
 *   (the truth changes ~27 %), so that reading cannot show the 5 x and is not asserted.
 * - The change against the truth's: dT = T(moved) - T(start) must follow the ground truth's
 *   own change dR (Embree, cached; oracle independent of the shafts): with world-fixed shafts
 *   (`path` variant, whose beams are the truth's model in the flat limit) the change error
 *   RMS(a dT - dR) / mean R, a the scale fit of T(start) to R(start), is below 0.6 x the
 *   camera-locked grid's and dT correlates with dR (> 0.5).
 * - Moving the camera by a whole grid spacing of both levels along x (4 m) draws the same world
 *   cells: the vertex capture shows every shaft vertex of the moved render that lies in the
 *   overlap of the two grids at the same world position (oracle: the original render's
 *   vertices), while the camera-locked grid shares none.
 * Slow (two ground truths): 160 x 90, reduced variant (GODRAYS_TEST_REDUCED=1) 64 x 36 with 48
 * march steps. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "realtime/shafts.h"
#include "scene_test.h"
#include "scene/scene.h"
#include "reference/truth.h"

static int reduced(void)
{
    const char *v = getenv("GODRAYS_TEST_REDUCED");
    return v && v[0] && strcmp(v, "0") != 0;
}

static double lum(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static int W = 160, H = 90;
static const char *variant = "shafts.variant=seed";

/* The default scene with the camera at (dx, -8, dz); the shafts' grid built for the eye
 * (ex, -8, ez) when eye is nonzero (shafts.grid_eye_m), else for the camera. */
static gr_scene *load_eye(int stable, double dx, double dz, int eye, double ex, double ez)
{
    char pos[128], ge[128];
    const char *sets[5] = {stable ? "shafts.stable_grid=true" : "shafts.stable_grid=false", pos, variant,
                           reduced() ? "reference.steps=48" : "reference.steps=128", ge};
    snprintf(pos, sizeof pos, "camera.position_m=[%.17g, -8, %.17g]", dx, dz);
    snprintf(ge, sizeof ge, "shafts.grid_eye_m=[%.17g, -8, %.17g]", ex, ez);
    return test_data_scene("default.json", W, H, sets, eye ? 5 : 4);
}

static gr_scene *load(int stable, double dx, double dz) { return load_eye(stable, dx, dz, 0, 0, 0); }

/* luminance (channels R, G, B by name) blurred by a box of (2 rad + 1)^2 pixels (clamped at
 * the edges) */
static void blur_lum(const gr_image *img, int rad, double *out)
{
    int ch[3] = {gr_image_channel(img, "R"), gr_image_channel(img, "G"), gr_image_channel(img, "B")};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double a = 0.0;
            int n = 0;
            for (int v = y - rad; v <= y + rad; v++)
                for (int u = x - rad; u <= x + rad; u++) {
                    if (u < 0 || v < 0 || u >= W || v >= H) continue;
                    const float *p = img->pixels + (size_t)img->nchannels * ((size_t)v * (size_t)W + (size_t)u);
                    float rgb[3] = {p[ch[0]], p[ch[1]], p[ch[2]]};
                    a += lum(rgb);
                    n++;
                }
            out[y * W + x] = a / n;
        }
}

/* The truth's own change for the move (from start to moved): Y maps of both truths. */
static void truth_pair(const double right[3], double *ra, double *rb)
{
    gr_error err = {0};
    gr_scene *a = load(0, 0, 0), *b = load(0, 0.3 * right[0], 0.3 * right[2]);
    gr_image *ta = NULL, *tb = NULL;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(a, NULL, &ta, &info, &err), err);
    CHECK_OK(gr_truth_image(b, NULL, &tb, &info, &err), err);
    if (!ta || !tb) exit(1);
    blur_lum(ta, 0, ra);
    blur_lum(tb, 0, rb);
    gr_image_destroy(ta), gr_image_destroy(tb);
    free(a), free(b);
}

/* The technique's change for the move against the truth's: change error after the scale fit
 * of the start frame, and the correlation of the two changes. */
static void change_vs_truth(gr_shafts *r, int stable, const double right[3], const double *ra, const double *rb,
                            double *cerr, double *corr)
{
    gr_error err = {0};
    gr_scene *a = load(stable, 0, 0), *b = load(stable, 0.3 * right[0], 0.3 * right[2]);
    gr_image *ia = gr_image_create(W, H, 3, NULL), *ib = gr_image_create(W, H, 3, NULL);
    CHECK_OK(gr_shafts_render(r, a, NULL, ia, NULL, &err), err);
    CHECK_OK(gr_shafts_render(r, b, NULL, ib, NULL, &err), err);
    size_t n = (size_t)W * (size_t)H;
    double *la = malloc(n * sizeof *la), *lb = malloc(n * sizeof *lb);
    if (!la || !lb) exit(1);
    blur_lum(ia, 0, la);
    blur_lum(ib, 0, lb);
    double tr = 0, tt = 0, mr = 0, md = 0, mt = 0;
    for (size_t q = 0; q < n; q++) {
        tr += la[q] * ra[q], tt += la[q] * la[q], mr += ra[q];
        md += rb[q] - ra[q], mt += lb[q] - la[q];
    }
    double s = tt > 0 ? tr / tt : 0.0, se = 0, sxy = 0, sxx = 0, syy = 0;
    md /= (double)n, mt /= (double)n;
    for (size_t q = 0; q < n; q++) {
        double dt = lb[q] - la[q], dr = rb[q] - ra[q];
        se += (s * dt - dr) * (s * dt - dr);
        sxy += (dt - mt) * (dr - md), sxx += (dt - mt) * (dt - mt), syy += (dr - md) * (dr - md);
    }
    *cerr = sqrt(se / (double)n) / (mr / (double)n);
    *corr = sxx > 0 && syy > 0 ? sxy / sqrt(sxx * syy) : 0.0;
    free(la), free(lb);
    gr_image_destroy(ia), gr_image_destroy(ib);
    free(a), free(b);
}

static double change(gr_shafts *r, int stable, const double right[3], int rad)
{
    gr_error err;
    gr_scene *a = load(stable, 0, 0), *b = load(stable, 0.3 * right[0], 0.3 * right[2]);
    gr_image *ia = gr_image_create(W, H, 3, NULL), *ib = gr_image_create(W, H, 3, NULL);
    CHECK_OK(gr_shafts_render(r, a, NULL, ia, NULL, &err), err);
    CHECK_OK(gr_shafts_render(r, b, NULL, ib, NULL, &err), err);
    static double la[160 * 90], lb[160 * 90];
    blur_lum(ia, rad, la);
    blur_lum(ib, rad, lb);
    double d = 0.0, m = 0.0;
    for (size_t q = 0; q < (size_t)W * (size_t)H; q++) {
        d += fabs(la[q] - lb[q]);
        m += la[q];
    }
    gr_image_destroy(ia), gr_image_destroy(ib);
    free(a), free(b);
    return d / m;
}

/* The layer's own change ("swim") for a sideways move A -> B of 0.3 m (along the camera's
 * horizontal right vector): at camera B, the grid built for B (what the camera sees after the
 * move) against the grid built for A (shafts.grid_eye_m = A: the layer as it was before the
 * move, seen from B), mean |dY| / mean Y. Parallax is the same in both (same camera), so what
 * differs is the layer itself. Start positions: a GRID x GRID lattice of spacing STEP in world
 * x and z, GRID STEP = 2 m = the coarser level's spacing, so P's offset within the snapping
 * lattice of both levels is sampled evenly (stratified) and the share of moves that cross a
 * snap boundary is the expected one. *crossed counts the moves for which a snapped P of either
 * level changed (2^l <= S < 2^(l+1), from the placement the renderer reports); *quiet is the
 * largest swim of the others (0 for world-fixed cells and a world-fixed shadow map). */
enum { GRID = 5 };
static const double STEP = 0.4; /* m */
static double swim(gr_shafts *r, int stable, const double right[3], int *crossed, double *quiet)
{
    gr_error err = {0};
    size_t n = (size_t)W * (size_t)H;
    double *la = malloc(n * sizeof *la), *lb = malloc(n * sizeof *lb), sum = 0.0;
    if (!la || !lb) exit(1);
    *crossed = 0, *quiet = 0.0;
    for (int i = 0; i < GRID * GRID; i++) {
        const double ax = (i % GRID) * STEP, az = (i / GRID) * STEP;
        const double bx = ax + 0.3 * right[0], bz = az + 0.3 * right[2];
        gr_scene *sb = load(stable, bx, bz), *sa = load_eye(stable, bx, bz, 1, ax, az);
        gr_image *ib = gr_image_create(W, H, 3, NULL), *ia = gr_image_create(W, H, 3, NULL);
        gr_shafts_stats stb, sta;
        CHECK_OK(gr_shafts_render(r, sb, NULL, ib, &stb, &err), err);
        CHECK_OK(gr_shafts_render(r, sa, NULL, ia, &sta, &err), err);
        blur_lum(ib, 0, lb);
        blur_lum(ia, 0, la);
        double d = 0.0, m = 0.0;
        for (size_t q = 0; q < n; q++) d += fabs(lb[q] - la[q]), m += lb[q];
        sum += d / m;
        int cross = 0;
        for (int k = 0; k < 2; k++) {
            double Sk = exp2(floor(log2(stb.spacing_m)) + k);
            for (int c = 0; c < 3; c += 2)
                cross |= floor(stb.center[c] / Sk + 0.5) != floor(sta.center[c] / Sk + 0.5);
        }
        *crossed += cross;
        if (!cross && d / m > *quiet) *quiet = d / m;
        if (getenv("SWIM_DEBUG"))
            printf("    move %d: swim %.5f crossed %d P %.3f %.3f -> %.3f %.3f S %.4f\n", i, d / m, cross,
                   sta.center[0], sta.center[2], stb.center[0], stb.center[2], stb.spacing_m);
        gr_image_destroy(ia), gr_image_destroy(ib);
        free(sa), free(sb);
    }
    free(la), free(lb);
    return sum / (GRID * GRID);
}

int main(void)
{
    gr_error err = {0};
    gr_shafts *r = NULL;
    (void)gr_technique_count(); /* registers the built-in techniques' scene sections */
    CHECK_OK(gr_shafts_create(NULL, &r, &err), err);
    if (!r) CHECK_DONE();
    gr_scene *s = load(0, 0, 0);
    double right[3] = {s->camera.right[0], 0.0, s->camera.right[2]};
    double n = hypot(right[0], right[2]);
    right[0] /= n, right[2] /= n;
    free(s);
    if (reduced()) W = 64, H = 36;
    /* The raw image change (mean |dY| / mean Y between the renders at A and B) is printed with
     * the ground truth's own change for the same move (parallax; docs "stable_grid"), not
     * asserted: the issue's criterion is asserted on the layer's own change below. */
    size_t npx = (size_t)W * (size_t)H;
    double *ra = malloc(npx * sizeof *ra), *rb = malloc(npx * sizeof *rb);
    if (!ra || !rb) exit(1);
    truth_pair(right, ra, rb);
    double dr = 0.0, mr = 0.0;
    for (size_t q = 0; q < npx; q++) dr += fabs(rb[q] - ra[q]), mr += ra[q];
    printf("%dx%d, 0.3 m sideways move: ground truth's own image change %.4f (mean |dY| / mean Y)\n", W, H, dr / mr);
    for (int rad = 0; rad <= 2; rad += 2) {
        double c0 = change(r, 0, right, rad), c1 = change(r, 1, right, rad);
        printf("  seed variant, %dx%d box blur: image change %.4f (camera-locked grid), %.4f (stable_grid)\n",
               2 * rad + 1, 2 * rad + 1, c0, c1);
        CHECK(c0 > 0.0 && c1 > 0.0);
    }
    variant = "shafts.variant=path";
    double e0, k0, e1, k1;
    change_vs_truth(r, 0, right, ra, rb, &e0, &k0);
    change_vs_truth(r, 1, right, ra, rb, &e1, &k1);
    printf("  path variant against the truth's change: change error %.4f, correlation %+.3f (camera-locked grid); "
           "%.4f, %+.3f (stable_grid)\n", e0, k0, e1, k1);
    CHECK_MSG(e1 <= 0.6 * e0, "stable_grid change error %.4f is not below 0.6 x the locked grid's %.4f", e1, e0);
    CHECK_MSG(k1 > 0.5 && k1 > k0, "stable_grid change correlation %.3f (locked %.3f)", k1, k0);
    variant = "shafts.variant=seed";
    free(ra), free(rb);

    /* The layer's own change (docs "stable_grid"): stable_grid's at most 1/5 of the locked
     * grid's (the issue's criterion, read as the layer's change, not parallax): seed, path, flux. */
    {
        /* grid_eye_m given as the camera's own position is the default, bit for bit */
        gr_scene *sd = load(0, 0.7, -0.4), *se = load_eye(0, 0.7, -0.4, 1, 0.7, -0.4);
        gr_image *id = gr_image_create(W, H, 3, NULL), *ie = gr_image_create(W, H, 3, NULL);
        CHECK_OK(gr_shafts_render(r, sd, NULL, id, NULL, &err), err);
        CHECK_OK(gr_shafts_render(r, se, NULL, ie, NULL, &err), err);
        CHECK_MSG(memcmp(id->pixels, ie->pixels, (size_t)W * (size_t)H * 3 * sizeof(float)) == 0,
                  "grid_eye_m = the camera's position changes the image");
        gr_image_destroy(id), gr_image_destroy(ie);
        free(sd), free(se);
    }
    const char *variants[3] = {"shafts.variant=seed", "shafts.variant=path", "shafts.variant=flux"};
    for (int v = 0; v < 3; v++) {
        variant = variants[v];
        int c0, c1;
        double q0, q1, s0 = swim(r, 0, right, &c0, &q0), s1 = swim(r, 1, right, &c1, &q1);
        printf("  %s, %dx%d, swim (the layer's own change; mean of %d moves of 0.3 m): %.4f camera-locked, %.4f "
               "stable_grid, ratio %.1f (%d of %d moves crossed a snap boundary; the others' largest swim %.2g)\n",
               variant + 7, W, H, GRID * GRID, s0, s1, s1 > 0 ? s0 / s1 : INFINITY, c1, GRID * GRID, q1);
        CHECK_MSG(s0 > 0.0, "%s: the locked grid's swim is 0", variant);
        CHECK_MSG(s1 <= s0 / 5.0, "%s: stable_grid swim %.4f is not at most 1/5 of the locked grid's %.4f", variant,
                  s1, s0);
        CHECK_MSG(c1 > 0 && c1 < GRID * GRID, "%s: %d of %d moves crossed a snap boundary (want some, not all)",
                  variant, c1, GRID * GRID);
        /* a move that crosses no snap boundary leaves the layer as it was: world-fixed cells, wave
         * phases and shadow-map texels (seed: bit for bit; path: float rounding of the shadow
         * depths, 7e-8, the map being drawn relative to a centre a whole number of texels away;
         * an unsnapped map: 2e-3) */
        CHECK_MSG(q1 <= 1e-6, "%s: stable_grid swim %.3g for a move that crossed no snap boundary", variant, q1);
    }
    variant = "shafts.variant=seed";
    W = 160, H = 90;

    /* a move by a power of two along x (a whole cell of both levels): same world vertices */
    gr_scene *a = load(1, 0, 0), *b = load(1, 4.0, 0);
    gr_shafts_vertex *va = NULL, *vb = NULL;
    int na = 0, nb = 0;
    gr_shafts_stats st;
    CHECK_OK(gr_shafts_capture(r, a, NULL, &va, &na, &st, &err), err);
    CHECK_OK(gr_shafts_capture(r, b, NULL, &vb, &nb, &st, &err), err);
    int matched = 0, shared = 0;
    for (int i = 0; i < nb; i++) {
        int found = 0;
        for (int j = 0; j < na && !found; j++)
            found = fabs(va[j].pos[0] - vb[i].pos[0]) < 1e-3 && fabs(va[j].pos[1] - vb[i].pos[1]) < 1e-3 &&
                    fabs(va[j].pos[2] - vb[i].pos[2]) < 1e-3;
        matched += found;
        shared++;
    }
    printf("after a 4 m move: %d of %d shaft vertices at the same world positions\n", matched, shared);
    /* 10 x 10 cells of 1 m (N = 11, S = 1.008 m -> level 1 m): 6 of 10 columns stay in the grid */
    CHECK_MSG(matched == shared * 6 / 10, "stable_grid: %d of %d vertices stayed (want 60 %%)", matched, shared);
    free(va), free(vb), free(a), free(b);
    /* the camera-locked grid moves with the camera: no vertex stays */
    a = load(0, 0, 0), b = load(0, 4.0, 0);
    CHECK_OK(gr_shafts_capture(r, a, NULL, &va, &na, &st, &err), err);
    CHECK_OK(gr_shafts_capture(r, b, NULL, &vb, &nb, &st, &err), err);
    matched = 0;
    for (int i = 0; i < nb; i++)
        for (int j = 0; j < na; j++)
            if (fabs(va[j].pos[0] - vb[i].pos[0]) < 1e-3 && fabs(va[j].pos[1] - vb[i].pos[1]) < 1e-3 &&
                fabs(va[j].pos[2] - vb[i].pos[2]) < 1e-3) {
                matched++;
                break;
            }
    printf("camera-locked grid after a 4 m move: %d of %d vertices at the same world positions\n", matched, nb);
    CHECK(matched < nb / 10);
    free(va), free(vb), free(a), free(b);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
