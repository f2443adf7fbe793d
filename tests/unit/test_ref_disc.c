/* The sun-disc convolution against brute force (docs/reference.md, "The sun's disc").
 * One Gerstner wave (A = 0.05 m, lambda = 2 m) focuses about 5.5 m down; the sun is at
 * 50 deg elevation, so the disc's image in the water is an ellipse. On one fixed surface
 * tessellation (fixed_grid) the horizontal irradiance is computed two ways:
 *  - convolve: the central sun direction, each beam's footprint convolved analytically
 *    with the disc's image (first order in the disc radius);
 *  - sample: the plain point-sun beams averaged over many directions drawn inside the disc
 *    (stratified in solid angle), which converges to the exact disc average of the same
 *    tessellation, with no first-order assumption.
 * Probes: a 2-D grid across the caustic sheets (z over one wavelength, at depths through
 * the focus), three x positions averaged. Checks, for the real 0.53 deg disc and a 4x
 * wider one: the relative L1 difference of the two fields and the difference of their
 * peaks stay within the bound the first-order error allows plus 3 standard errors of the
 * sampled field; and the disc's convolution really acts (the peak is far below the
 * point-sun peak of the same tessellation). */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>

enum { NZ = 160, ND = 5, NX = 3, NP = NZ * ND };

static gr_ref_renderer *make(double diam, const char *mode, int passes)
{
    gr_scene *s = ref_scene(
        "{\"water\":{\"waves\":[{\"amplitude_m\":0.05,\"wavelength_m\":2,\"direction_deg\":0}]},"
        "\"sun\":{\"elevation_deg\":50,\"azimuth_deg\":20,\"angular_diameter_deg\":%g},"
        "\"medium\":{\"absorption_per_m\":0,\"scattering_per_m\":0,\"g\":0},"
        "\"camera\":{\"position_m\":[0,-1,0],\"pitch_deg\":80,\"width\":4,\"height\":4},"
        "\"reference\":{\"surface_res\":%d,\"sun_samples\":%d,\"batches\":2,\"sun_disc\":\"%s\"}}",
        diam, ref_reduced() ? 96 : 128, passes, mode);
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    o.fixed_grid = 1;
    o.lit_box_valid = 1;
    const double box[5] = {-0.3, 0.3, -1.2, 1.2, -8.0};
    memcpy(o.lit_box, box, sizeof box);
    gr_ref_renderer *r = NULL;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_ref_create(s, &o, &r, &err), err);
    free(s);
    if (!r) exit(1);
    return r;
}

static gr_dvec3 probe(int i, int x)
{
    int iz = i % NZ, id = i / NZ;
    return gr_d3(-0.1 + 0.1 * x, -(4.5 + 0.5 * id), -1.0 + 2.0 * (iz + 0.5) / NZ);
}

/* E[i]: the mean over passes of the irradiance at probe i (averaged over the x positions);
 * se[i] its standard error from the spread of the passes (NULL: not wanted). */
static void field(gr_ref_renderer *r, int passes, double *E, double *se)
{
    gr_error err = {GR_OK, ""};
    static double s1[NP], s2[NP];
    memset(s1, 0, sizeof s1);
    memset(s2, 0, sizeof s2);
    for (int p = 0; p < passes; p++) {
        CHECK_OK(gr_ref_prepare_pass(r, p, &err), err);
        for (int i = 0; i < NP; i++) {
            double e = 0.0;
            for (int x = 0; x < NX; x++) e += gr_ref_irradiance_h(r, probe(i, x)) / NX;
            s1[i] += e;
            s2[i] += e * e;
        }
    }
    for (int i = 0; i < NP; i++) {
        E[i] = s1[i] / passes;
        if (se) se[i] = passes > 1 ? sqrt(fmax(0.0, s2[i] / passes - E[i] * E[i]) / (passes - 1)) : 0.0;
    }
}

static double peak(const double *E)
{
    double m = 0.0;
    for (int i = 0; i < NP; i++) m = fmax(m, E[i]);
    return m;
}

static void run(double diam, int passes, double tol_l1, double tol_peak)
{
    static double Ec[NP], Eb[NP], Sb[NP], E0[NP];
    gr_ref_renderer *rc = make(diam, "convolve", 2), *rb = make(diam, "sample", passes), *r0 = make(0.0, "convolve", 2);
    field(rc, 1, Ec, NULL);
    field(rb, passes, Eb, Sb);
    field(r0, 1, E0, NULL);
    double l1 = 0.0, sum = 0.0, noise2 = 0.0, mean_c = 0.0, mean_b = 0.0;
    for (int i = 0; i < NP; i++) {
        l1 += fabs(Ec[i] - Eb[i]);
        sum += Eb[i];
        noise2 += Sb[i] * Sb[i];
        mean_c += Ec[i] / NP;
        mean_b += Eb[i] / NP;
    }
    /* the sampled field's own noise in the L1 figure: E|noise| ~ 0.8 sigma per probe */
    double l1_rel = l1 / sum, noise_rel = 0.8 * sqrt(noise2 / NP) * NP / sum;
    int ib = 0;
    for (int i = 1; i < NP; i++)
        if (Eb[i] > Eb[ib]) ib = i;
    double pc = peak(Ec), pb = peak(Eb), p0 = peak(E0);
    printf("disc %.2f deg, %d directions: relative L1 difference %.4f (noise of the sampled field ~%.4f); "
           "peak convolved %.3f, sampled %.3f +- %.3f (%+.2f%%), point sun %.3f; means %.5f vs %.5f\n",
           diam, passes, l1_rel, noise_rel, pc, pb, Sb[ib], 100.0 * (pc / pb - 1.0), p0, mean_c, mean_b);
    CHECK_MSG(l1_rel <= tol_l1 + 3.0 * noise_rel, "L1 difference %g over %g + 3 x %g", l1_rel, tol_l1, noise_rel);
    CHECK_MSG(fabs(pc - pb) <= tol_peak * pb + 3.0 * Sb[ib], "peaks %g vs %g", pc, pb);
    /* flux: both fields average the same irradiance over the probe grid (one period) */
    CHECK_REL(mean_c, mean_b, 0.002 + 3.0 * sqrt(noise2) / NP / mean_b);
    CHECK_MSG(pc < 0.8 * p0, "the disc must lower the tessellation's point-sun peak: %g vs %g", pc, p0);
    gr_ref_destroy(rc);
    gr_ref_destroy(rb);
    gr_ref_destroy(r0);
}

int main(void)
{
    int passes = ref_reduced() ? 256 : 1024;
    run(0.53, passes, 0.01, 0.02);
    run(2.12, passes, 0.02, 0.04);
    CHECK_DONE();
}
