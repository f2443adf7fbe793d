/* The sun-disc kernel's geometry (reference/beams.h): in the kernel's own units the disc of
 * directions is the unit disc; the fraction of it inside a triangle (the beam's
 * cross-section) is computed in closed form (segments and sectors). Checked here against
 * values computed independently:
 *  - a half-plane at signed distance s from the centre: the circular segment from the
 *    angle 2 acos(s) (textbook form, written differently: (t - sin t) / (2 pi)), and the
 *    same line as a triangle whose other two edges lie far outside the disc;
 *  - triangles around, across and inside the disc, and one containing the whole disc:
 *    a 2000 x 2000 point grid over the disc's bounding square, counting the points inside
 *    the disc and the triangle (written here: sign of three cross products);
 *  - a cross-section collapsed to a sliver inside the disc: its own area / pi, to rounding.
 * The sectors use float atan2: fractions are exact to ~1e-8.
 * The lookups' libm-free versions (polynomial acos and atan2) against these and libm: atan2
 * over 4 M directions, the half-plane over 2 M distances, the triangle over 200 k random
 * triangles: errors bounded far below the 1 % error budget (docs/reference.md 2.4). */
#include "check.h"

#include <math.h>
#include <time.h>
#include "reference/beams.h"

static const double PI = 3.14159265358979323846;

static double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

static int in_triangle(const double v[6], double x, double y)
{
    double c0 = cross(v[2] - v[0], v[3] - v[1], x - v[0], y - v[1]);
    double c1 = cross(v[4] - v[2], v[5] - v[3], x - v[2], y - v[3]);
    double c2 = cross(v[0] - v[4], v[1] - v[5], x - v[4], y - v[5]);
    return (c0 >= 0 && c1 >= 0 && c2 >= 0) || (c0 <= 0 && c1 <= 0 && c2 <= 0);
}

/* Fraction of the unit disc's grid points inside the triangle. */
static double raster(const double v[6], int n)
{
    double step = 2.0 / n;
    long in = 0, tot = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = -1.0 + (i + 0.5) * step, y = -1.0 + (j + 0.5) * step;
            if (x * x + y * y > 1.0) continue;
            tot++;
            in += in_triangle(v, x, y);
        }
    return (double)in / (double)tot;
}

static unsigned long long lcg = 77;
static double urand(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg >> 11) * 0x1p-53;
}

int main(void)
{
    /* half-planes: segment of half-angle acos(s) cut off on the far side */
    double worst_hp = 0.0;
    for (int k = 0; k <= 40; k++) {
        double s = -1.2 + 2.4 * k / 40.0, expect;
        if (s >= 1.0) expect = 1.0;
        else if (s <= -1.0) expect = 0.0;
        else {
            double th = 2.0 * acos(s); /* the angle of the cut-off segment */
            expect = 1.0 - (th - sin(th)) / (2.0 * PI);
        }
        double got = gr_beam_disc_halfplane(s);
        worst_hp = fmax(worst_hp, fabs(got - expect));
        CHECK_NEAR(got, expect, 1e-12);
        /* the same half-plane as a huge triangle: the line y = -s, the apex far above */
        double v[6] = {-50.0, -s, 50.0, -s, 0.0, 80.0};
        CHECK_NEAR(gr_beam_disc_triangle(v), expect, 1e-7); /* float sectors */
        /* reversed orientation gives the same fraction */
        double w[6] = {0.0, 80.0, 50.0, -s, -50.0, -s};
        CHECK_NEAR(gr_beam_disc_triangle(w), expect, 1e-7);
    }
    printf("half-planes: largest deviation from the segment formula %.2e\n", worst_hp);

    /* a triangle containing the disc, one far outside, a sliver inside */
    double big[6] = {-3.0, -2.0, 3.0, -2.0, 0.0, 4.0}, far[6] = {5.0, 5.0, 6.0, 5.0, 5.0, 7.0};
    CHECK_NEAR(gr_beam_disc_triangle(big), 1.0, 1e-7);
    CHECK_NEAR(gr_beam_disc_triangle(far), 0.0, 1e-7);
    double sl[6] = {-0.3, 0.1, 0.4, 0.1000001, 0.2, 0.1000003};
    double sl_area = 0.5 * fabs(cross(sl[2] - sl[0], sl[3] - sl[1], sl[4] - sl[0], sl[5] - sl[1]));
    CHECK_REL(gr_beam_disc_triangle(sl), sl_area / PI, 1e-6);

    /* random triangles against the raster count (its error ~ perimeter x step / area) */
    const int n = 2000;
    double worst = 0.0;
    for (int k = 0; k < 30; k++) {
        double v[6];
        for (int i = 0; i < 3; i++) {
            double r = 2.0 * urand(), t = 2.0 * PI * urand();
            v[2 * i] = r * cos(t);
            v[2 * i + 1] = r * sin(t);
        }
        if (fabs(cross(v[2] - v[0], v[3] - v[1], v[4] - v[0], v[5] - v[1])) < 0.05) { k--; continue; }
        double c = gr_beam_disc_triangle(v), ref = raster(v, n);
        worst = fmax(worst, fabs(c - ref));
        CHECK_NEAR(c, ref, 3e-4);
        CHECK(c >= 0.0 && c <= 1.0 + 1e-12);
    }
    printf("30 random triangles: largest |closed form - raster| = %.2e\n", worst);

    /* the libm-free versions the lookups use */
    double werr = 0.0;
    for (int k = 0; k < 4000000; k++) {
        double ang = 2.0 * PI * urand() - PI, rad = pow(10.0, 6.0 * urand() - 3.0);
        float y = (float)(rad * sin(ang)), x = (float)(rad * cos(ang));
        if (k % 1000 == 0) { x = k % 2000 ? 0.0f : -(float)rad; } /* the axes */
        werr = fmax(werr, fabs((double)gr_beam_atan2_fast(y, x) - atan2((double)y, (double)x)));
    }
    printf("atan2 (fast) vs libm over 4 M directions: largest error %.2e rad\n", werr);
    CHECK(werr < 4e-7);
    double herr = 0.0;
    for (int k = 0; k <= 2000000; k++) {
        double sd = -1.0 + 2.0 * k / 2000000.0;
        herr = fmax(herr, fabs(gr_beam_disc_halfplane_fast(sd) - gr_beam_disc_halfplane(sd)));
    }
    printf("half-plane (fast) vs exact over 2 M distances: largest error %.2e\n", herr);
    CHECK(herr < 2e-8);
    double terr = 0.0;
    for (int k = 0; k < 200000; k++) {
        double v[6], sc = pow(10.0, 2.0 * urand() - 1.0);
        for (int i = 0; i < 6; i++) v[i] = sc * (2.0 * urand() - 1.0) + (k % 3 ? 0.0 : 0.5 * (2.0 * urand() - 1.0));
        terr = fmax(terr, fabs(gr_beam_disc_triangle_fast(v) - gr_beam_disc_triangle(v)));
    }
    printf("triangle (fast) vs exact over 200 k triangles: largest error %.2e of the disc\n", terr);
    CHECK(terr < 3e-7);

    /* where the fast triangle's shortcuts meet their limits (an arc near 0 or 2 pi, from which
     * it falls back to the wedge sum; a root at a tangent; the centre on an edge; vertices far
     * out): a vertex at radius 1 +- 10^-k, an edge at distance 1 +- 10^-k or 10^-k from the
     * centre, with the other vertices inside, outside or far out, both orientations */
    double aerr = 0.0;
    for (int k = 1; k <= 16; k++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double e = sgn * pow(10.0, -k);
            for (int rep = 0; rep < 60; rep++) {
                double t = 2.0 * PI * urand(), ct = cos(t), st = sin(t), v[6], w[6];
                double reach = rep % 3 == 0 ? 0.9 : rep % 3 == 1 ? 5.0 : 1e5;
                if (rep % 2 == 0) {
                    /* a vertex at radius 1 + e (a corner just poking out or just inside) */
                    v[0] = (1.0 + e) * ct; v[1] = (1.0 + e) * st;
                } else {
                    /* an edge at distance 1 + e (near a tangent) or e (near the centre) */
                    double d = rep % 4 == 1 ? 1.0 + e : e, L = 0.5 + reach * urand();
                    v[0] = d * ct - L * st; v[1] = d * st + L * ct;
                    v[2] = d * ct + L * st; v[3] = d * st - L * ct;
                }
                for (int i = rep % 2 == 0 ? 1 : 2; i < 3; i++) {
                    double r = reach * urand(), a = 2.0 * PI * urand();
                    v[2 * i] = r * cos(a); v[2 * i + 1] = r * sin(a);
                }
                for (int i = 0; i < 3; i++) { w[2 * i] = v[4 - 2 * i]; w[2 * i + 1] = v[5 - 2 * i]; }
                aerr = fmax(aerr, fabs(gr_beam_disc_triangle_fast(v) - gr_beam_disc_triangle(v)));
                aerr = fmax(aerr, fabs(gr_beam_disc_triangle_fast(w) - gr_beam_disc_triangle(w)));
            }
        }
    }
    printf("triangle (fast) vs exact at tangents, the centre and far out: largest error %.2e\n", aerr);
    CHECK(aerr < 3e-7);

    /* a mix like the lookups' (beam_test asks for the triangle where at least two edges'
     * lines cross the kernel and none leaves it wholly outside): vertices in squares of 2.5
     * to 32 disc radii, which gives about the default scene's shares of 0/1/2/3 vertices in
     * the disc (34/59/6/0.3 %, sampled from its lookups). Accuracy, and the time per call
     * (printed only: the machine may be loaded) */
    enum { NMIX = 100000 };
    static double mix[NMIX][6];
    int nmix = 0, nin_hist[4] = {0, 0, 0, 0};
    while (nmix < NMIX) {
        double L = pow(10.0, 0.4 + 1.1 * urand()), cx = 0.6 * L * (2.0 * urand() - 1.0), cy = 0.6 * L * (2.0 * urand() - 1.0);
        double *v = mix[nmix];
        for (int i = 0; i < 3; i++) {
            v[2 * i] = cx + L * (urand() - 0.5);
            v[2 * i + 1] = cy + L * (urand() - 0.5);
        }
        double o = cross(v[2] - v[0], v[3] - v[1], v[4] - v[0], v[5] - v[1]) > 0.0 ? 1.0 : -1.0;
        int ncut = 0, out = 0;
        for (int i = 0; i < 3; i++) {
            int j = (i + 1) % 3;
            double ex = v[2 * j] - v[2 * i], ey = v[2 * j + 1] - v[2 * i + 1];
            double dist = o * cross(ex, ey, -v[2 * i], -v[2 * i + 1]) / hypot(ex, ey); /* the centre's */
            out |= dist < -1.0;
            ncut += fabs(dist) < 1.0;
        }
        if (out || ncut < 2) continue;
        int nin = 0;
        for (int i = 0; i < 3; i++) nin += v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1] <= 1.0;
        nin_hist[nin]++;
        nmix++;
    }
    double merr = 0.0;
    for (int k = 0; k < NMIX; k++) merr = fmax(merr, fabs(gr_beam_disc_triangle_fast(mix[k]) - gr_beam_disc_triangle(mix[k])));
    printf("triangle (fast) vs exact over %d lookup-like triangles (%.0f/%.0f/%.0f/%.0f %% with 0/1/2/3 vertices in the disc): largest error %.2e\n",
           NMIX, 100.0 * nin_hist[0] / NMIX, 100.0 * nin_hist[1] / NMIX, 100.0 * nin_hist[2] / NMIX, 100.0 * nin_hist[3] / NMIX, merr);
    CHECK(merr < 3e-7);
    double best[2] = {1e30, 1e30}, sink = 0.0;
    for (int rep = 0; rep < 5; rep++) {
        for (int f = 0; f < 2; f++) {
            struct timespec t0, t1;
            clock_gettime(CLOCK_MONOTONIC, &t0);
            for (int k = 0; k < NMIX; k++) sink += f ? gr_beam_disc_triangle(mix[k]) : gr_beam_disc_triangle_fast(mix[k]);
            clock_gettime(CLOCK_MONOTONIC, &t1);
            best[f] = fmin(best[f], (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
        }
    }
    printf("time per call over them (best of 5): fast %.1f ns, exact %.1f ns (checksum %.6g)\n",
           1e9 * best[0] / NMIX, 1e9 * best[1] / NMIX, sink);
    CHECK_DONE();
}
