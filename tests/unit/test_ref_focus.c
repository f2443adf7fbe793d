/* Oracle 3 (../shared/notes/physics-oracles.md): depth of the first focus under a crest.
 * One Gerstner wave (A = 0.18 m, lambda = 4 m), sun at the zenith, no extinction: paraxial
 * rays under the crest (curvature kappa = A k^2 / (1 - A k)^2) converge at
 * z_c = n (1 - A k)^2 / ((n - 1) A k^2) below the crest (4.63 m here). With a point sun
 * the horizontal irradiance on the vertical line under the crest must peak within 5% of
 * z_c; so for a gentler wave (A = 0.1 m, z_c = 11.5 m). With the real sun's disc
 * (0.53 deg) the cusp is blurred: the peak must be lower and no shallower (the folds just
 * beyond the cusp lie within the blur), the trend the oracle states. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>

static void run(double A, double lambda, int res, double diam, int passes, double *peak_z, double *peak_e)
{
    const double n = 1.333, k = 2.0 * 3.14159265358979323846 / lambda;
    double zc = n * (1.0 - A * k) * (1.0 - A * k) / ((n - 1.0) * A * k * k);
    gr_scene *s = ref_scene(
        "{\"water\":{\"waves\":[{\"amplitude_m\":%g,\"wavelength_m\":%g,\"direction_deg\":0}]},"
        "\"sun\":{\"elevation_deg\":90,\"angular_diameter_deg\":%g},"
        "\"medium\":{\"absorption_per_m\":0,\"scattering_per_m\":0,\"g\":0,\"ior\":%g},"
        "\"camera\":{\"position_m\":[0,-1,0],\"pitch_deg\":80,\"width\":4,\"height\":4},"
        "\"reference\":{\"surface_res\":%d,\"sun_samples\":%d,\"batches\":2}}", A, lambda, diam, n, res,
        passes < 2 ? 2 : passes);
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    o.lit_box_valid = 1;
    double half = 0.6 * lambda, box[5] = {-half, half, -half, half, A - 1.45 * zc};
    memcpy(o.lit_box, box, sizeof box);
    gr_ref_renderer *r = NULL;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_ref_create(s, &o, &r, &err), err);
    if (!r) exit(1);
    enum { NZ = 600 };
    static double E[NZ];
    memset(E, 0, sizeof E);
    double z_lo = 0.6 * zc, z_hi = 1.4 * zc;
    for (int p = 0; p < passes; p++) {
        CHECK_OK(gr_ref_prepare_pass(r, p, &err), err);
        for (int i = 0; i < NZ; i++) {
            double z = z_lo + (z_hi - z_lo) * (i + 0.5) / NZ;
            for (int j = 0; j < 4; j++) E[i] += gr_ref_irradiance_h(r, gr_d3(0.1 + 0.07 * j, A - z, 0.0));
        }
    }
    int best = 0;
    for (int i = 1; i < NZ; i++)
        if (E[i] > E[best]) best = i;
    double z_peak = z_lo + (z_hi - z_lo) * (best + 0.5) / NZ;
    *peak_z = z_peak;
    *peak_e = E[best] / (4.0 * passes);
    printf("sun disc %g deg: A %g m, lambda %g m: irradiance peak %.3f m below the crest (E_h %.2f), predicted %.3f m (%+.2f%%)\n", diam, A,
           lambda, z_peak, E[best] / (4.0 * passes), zc, 100.0 * (z_peak / zc - 1.0));
    if (diam < 0.1) CHECK_REL(z_peak, zc, 0.05);
    /* it is a real focus: much brighter than the mean (1 per unit E_sun) */
    CHECK(E[best] / (4.0 * passes) > 3.0);
    gr_ref_destroy(r);
    free(s);
}

int main(void)
{
    double z0, e0, z1, e1, z2, e2;
    run(0.18, 4.0, 384, 0.0, 1, &z0, &e0);
    run(0.10, 4.0, 256, 0.0, 1, &z1, &e1);
    run(0.18, 4.0, 256, 0.53, 4, &z2, &e2);
    CHECK_MSG(e2 < e0, "the sun's disc must lower the focus peak: %g vs point sun %g", e2, e0);
    CHECK_MSG(z2 >= z0 - 0.02, "the disc-blurred peak must not be shallower: %g vs %g m", z2, z0);
    CHECK_DONE();
}
