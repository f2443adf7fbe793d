/* The sun-disc convolution against brute force (docs/reference.md, "The sun's disc").
 * One Gerstner wave (A = 0.05 m, lambda = 2 m) focuses about 5.5 m down; the sun is at
 * 50 deg elevation, 20 deg azimuth, so the disc's image in the water is an ellipse. On one
 * surface tessellation the horizontal irradiance is computed two ways:
 *  - convolved: the central sun direction, each beam's footprint convolved analytically
 *    with the disc's image (reference/beam_grid.c, first order in the disc radius);
 *  - brute force: point-sun beams built for N directions spread uniformly over the disc
 *    (a sunflower spiral), their irradiance averaged: the disc average of the same
 *    tessellation with no first-order assumption, converging as N grows (N and N/4 are
 *    compared to show how far it has converged).
 * Probes: a grid across the caustic sheets (z over one wavelength, 5 depths through the
 * focus, 3 x positions averaged). Checks, for the real 0.53 deg disc and a 4x wider one
 * (where the first-order error is 16x larger): the relative L1 difference between the two
 * fields, the difference of their peaks (mean of the top 1% of the probes), their means
 * (flux), each within a tolerance plus the brute force's own N/4-vs-N difference; and that
 * the disc really acts (its peak is far below the point-sun peak of the same tessellation).
 * Figures are quoted in docs/reference.md. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include <time.h>
#include "core/optics.h"
#include "reference/beams.h"
#include "reference/embree_scene.h"

enum { NZ = 200, ND = 5, NX = 3, NP = NZ * ND };

static gr_dvec3 probe(int i, int x)
{
    int iz = i % NZ, id = i / NZ;
    return gr_d3(-0.1 + 0.1 * x, -(4.5 + 0.5 * id), -1.0 + 2.0 * (iz + 0.5) / NZ);
}

typedef struct setup {
    gr_scene *s;
    gr_rtc *rtc;
    gr_beam_params bp;
    gr_dvec3 I0, e1, e2;
} setup;

static void make(setup *u, double res)
{
    u->s = ref_scene("{\"water\":{\"waves\":[{\"amplitude_m\":0.05,\"wavelength_m\":2,\"direction_deg\":0}]},"
                     "\"sun\":{\"elevation_deg\":50,\"azimuth_deg\":20},"
                     "\"camera\":{\"position_m\":[0,-1,0]}}");
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_rtc_create(0, &u->rtc, &err), err);
    if (!u->rtc) exit(1);
    u->I0 = gr_d3_norm(gr_d3(u->s->sun.dir[0], u->s->sun.dir[1], u->s->sun.dir[2]));
    u->e1 = gr_d3_norm(gr_d3_cross(u->I0, gr_d3(0, 1, 0)));
    u->e2 = gr_d3_cross(u->I0, u->e1);
    gr_dvec3 T0 = gr_refract_d(u->I0, gr_d3(0, 1, 0), 1.0 / u->s->medium.ior);
    gr_beam_params *p = &u->bp;
    memset(p, 0, sizeof *p);
    p->water = &u->s->water;
    p->origin = gr_d3(0, 0, 0);
    p->ior = u->s->medium.ior;
    p->fresnel = 1;
    p->shear_x = T0.x / T0.y;
    p->shear_z = T0.z / T0.y;
    /* sheared bounds of the probes */
    p->region.u0 = p->region.w0 = INFINITY;
    p->region.u1 = p->region.w1 = -INFINITY;
    for (int i = 0; i < NP; i++)
        for (int x = 0; x < NX; x++) {
            gr_dvec3 q = probe(i, x);
            double pu = q.x - p->shear_x * q.y, pw = q.z - p->shear_z * q.y;
            p->region.u0 = fmin(p->region.u0, pu); p->region.u1 = fmax(p->region.u1, pu);
            p->region.w0 = fmin(p->region.w0, pw); p->region.w1 = fmax(p->region.w1, pw);
        }
    p->region.y_min = -6.6;
    p->pad_m = 0.7; /* > amplitude + depth x the largest drift of a refracted ray (~0.05 / m) */
    p->res = (int)res;
    p->jitter[0] = p->jitter[1] = 0.5;
    p->max_prims = (size_t)1 << 24;
}

/* The irradiance field (mean over the x positions) for sun direction I; radius > 0:
 * convolved with the disc of that angular radius. */
static void field(setup *u, gr_dvec3 I, double radius, double *E)
{
    gr_error err = {GR_OK, ""};
    gr_beams *b = NULL;
    u->bp.sun_dir = I;
    u->bp.disc_radius = radius;
    u->bp.disc_e1 = u->e1;
    u->bp.disc_e2 = u->e2;
    CHECK_OK(gr_beams_build(u->rtc, &u->bp, &b, &err), err);
    if (!b) exit(1);
    gr_beam_hits hits = {NULL, 0, 0};
    for (int i = 0; i < NP; i++) {
        double e = 0.0;
        for (int x = 0; x < NX; x++) {
            int n = gr_beams_lookup(b, gr_d3_to_f(probe(i, x)), &hits);
            CHECK(n >= 0);
            for (int k = 0; k < n; k++) e += hits.h[k].e_h;
        }
        E[i] = e / NX;
    }
    gr_beam_hits_free(&hits);
    gr_beams_destroy(b);
}

/* Brute force: the mean over n sunflower directions in the disc of angular radius R
 * (uniform in the tangent plane; uniform in solid angle to O(R^2)). */
static void brute(setup *u, double R, int n, double *E)
{
    static double tmp[NP];
    const double golden = 3.14159265358979323846 * (3.0 - sqrt(5.0));
    memset(E, 0, NP * sizeof *E);
    for (int k = 0; k < n; k++) {
        double r = R * sqrt((k + 0.5) / n), t = golden * k;
        gr_dvec3 I = gr_d3_norm(gr_d3_madd(gr_d3_madd(u->I0, u->e1, r * cos(t)), u->e2, r * sin(t)));
        field(u, I, 0.0, tmp);
        for (int i = 0; i < NP; i++) E[i] += tmp[i] / n;
    }
}

static double l1_rel(const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (int i = 0; i < NP; i++) { d += fabs(a[i] - b[i]); s += b[i]; }
    return d / s;
}

/* The mean of the 1% largest values: the peak, robust to one noisy probe. */
static double peak(const double *E)
{
    static double tmp[NP];
    memcpy(tmp, E, sizeof tmp);
    double m = 0.0;
    for (int k = 0; k < NP / 100; k++) {
        int best = k;
        for (int i = k + 1; i < NP; i++)
            if (tmp[i] > tmp[best]) best = i;
        double x = tmp[k];
        tmp[k] = tmp[best];
        tmp[best] = x;
        m += tmp[k] / (NP / 100);
    }
    return m;
}

static double maxv(const double *E)
{
    double m = 0.0;
    for (int i = 0; i < NP; i++) m = fmax(m, E[i]);
    return m;
}

static double mean(const double *E)
{
    double m = 0.0;
    for (int i = 0; i < NP; i++) m += E[i] / NP;
    return m;
}

static void run(setup *u, double diam_deg, int n, double tol_l1, double tol_peak)
{
    static double Ec[NP], Eb[NP], Eq[NP], E0[NP];
    double R = 0.5 * diam_deg * 3.14159265358979323846 / 180.0;
    clock_t c0 = clock();
    field(u, u->I0, R, Ec);
    field(u, u->I0, 0.0, E0);
    brute(u, R, n / 4, Eq);
    brute(u, R, n, Eb);
    double l1 = l1_rel(Ec, Eb), conv = l1_rel(Eq, Eb);
    double pc = peak(Ec), pb = peak(Eb), pq = peak(Eq), p0 = peak(E0);
    double mc = mean(Ec), mb = mean(Eb), mq = mean(Eq);
    printf("disc %.2f deg: convolved vs %d directions: relative L1 difference %.4f (brute force %d vs %d "
           "directions: %.4f); peaks (top 1%%) %.3f vs %.3f (%+.2f%%; brute force %d vs %d: %+.2f%%), point sun %.3f; "
           "maxima: convolved %.3f, point sun %.3f; means %.6f vs %.6f (%.2f s)\n",
           diam_deg, n, l1, n / 4, n, conv, pc, pb, 100.0 * (pc / pb - 1.0), n / 4, n, 100.0 * (pq / pb - 1.0), p0, maxv(Ec), maxv(E0), mc, mb,
           (double)(clock() - c0) / CLOCKS_PER_SEC);
    /* the brute force's own quadrature error is at most about its N/4-vs-N difference */
    CHECK_MSG(l1 <= tol_l1 + conv, "L1 difference %g over %g + %g", l1, tol_l1, conv);
    CHECK_MSG(fabs(pc / pb - 1.0) <= tol_peak + fabs(pq / pb - 1.0), "peaks %g vs %g", pc, pb);
    /* flux: the convolution conserves it exactly; the probe means differ by sampling only */
    CHECK_MSG(fabs(mc - mb) <= 2e-3 * mb + fabs(mq - mb), "means %g vs %g", mc, mb);
    CHECK_MSG(maxv(Ec) < 0.6 * maxv(E0), "the disc must lower the point-sun maximum: %g vs %g", maxv(Ec), maxv(E0));
}

int main(void)
{
    setup u;
    make(&u, ref_reduced() ? 40 : 48);
    int n = ref_reduced() ? 128 : 512;
    /* tolerances: the first-order error grows as the square of the disc's radius */
    run(&u, 0.53, n, 0.01, 0.02);
    run(&u, 2.12, n, 0.02, 0.08);
    gr_rtc_destroy(u.rtc);
    free(u.s);
    CHECK_DONE();
}
