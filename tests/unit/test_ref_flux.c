/* Oracle 2 (../shared/notes/physics-oracles.md): flux conservation under waves.
 * With sigma_t = 0 and F_t = 1, the horizontal irradiance averaged over one period of a
 * periodic surface equals E_sun |I_y| at every depth, before and past the first focus.
 * With Fresnel on it equals the surface average of F_t |I . n| dA / dA_horizontal, which
 * this test integrates itself from finite-difference tangents of the surface and the
 * textbook Fresnel equations (independent of the integrator's code). The average is taken
 * over 65536 stratified points; tolerance 1% plus 3 standard errors of that sample. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include "core/gerstner.h"

static double fresnel_t(double cos_i, double n)
{
    /* unpolarized transmittance air -> water (Born & Wolf): 1 - (Rs + Rp) / 2 */
    double sin_t = sqrt(fmax(0.0, 1.0 - cos_i * cos_i)) / n, cos_t = sqrt(1.0 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

/* Surface average over one period (along z) of F_t |I . (dP/dx0 x dP/dz0)| per unit rest area. */
static double expected_fresnel_mean(const gr_scene *s, gr_dvec3 I)
{
    const int n = 20000;
    double lam = s->water.waves[0].wavelength_m, h = 1e-5, sum = 0.0;
    for (int i = 0; i < n; i++) {
        double z0 = lam * (i + 0.5) / n, x0 = 0.3;
        gr_dvec3 px = gr_d3_scale(gr_d3_sub(gr_gerstner_position(&s->water, x0 + h, z0, 0), gr_gerstner_position(&s->water, x0 - h, z0, 0)), 0.5 / h);
        gr_dvec3 pz = gr_d3_scale(gr_d3_sub(gr_gerstner_position(&s->water, x0, z0 + h, 0), gr_gerstner_position(&s->water, x0, z0 - h, 0)), 0.5 / h);
        gr_dvec3 a = gr_d3_cross(pz, px); /* upward area vector per unit rest area */
        double al = gr_d3_len(a), cos_i = -gr_d3_dot(I, a) / al;
        sum += fresnel_t(cos_i, s->medium.ior) * cos_i * al;
    }
    return sum / n;
}

static void run(double elev, double az, int fresnel, int passes)
{
    gr_scene *s = ref_scene(
        "{\"water\":{\"waves\":[{\"amplitude_m\":0.18,\"wavelength_m\":4,\"direction_deg\":0}]},"
        "\"sun\":{\"elevation_deg\":%g,\"azimuth_deg\":%g,\"angular_diameter_deg\":0.53},"
        "\"medium\":{\"absorption_per_m\":0,\"scattering_per_m\":0,\"g\":0},"
        "\"camera\":{\"position_m\":[0,-3,0],\"pitch_deg\":80,\"width\":4,\"height\":4},"
        "\"reference\":{\"surface_res\":256,\"sun_samples\":8,\"batches\":2}}", elev, az);
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    o.fresnel = fresnel;
    o.lit_box_valid = 1;
    double box[5] = {-6, 6, -6, 6, -25};
    memcpy(o.lit_box, box, sizeof box);
    gr_ref_renderer *r = NULL;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_ref_create(s, &o, &r, &err), err);
    if (!r) exit(1);
    /* 4.3 m lies just above the first focus (4.46 m below the rest level), 6 m just past it */
    const double depths[] = {1.0, 4.3, 6.0, 9.0, 18.0};
    for (int p = 0; p < passes; p++) {
        CHECK_OK(gr_ref_prepare_pass(r, p, &err), err);
        gr_dvec3 I = gr_ref_pass_sun_dir(r, p);
        double expect = fresnel ? expected_fresnel_mean(s, I) : fabs(I.y);
        for (size_t d = 0; d < sizeof depths / sizeof depths[0]; d++) {
            /* stratified, jittered points over x in [0, 1) m and one period z in [0, 4) m */
            const int nx = 8, nz = 8192;
            double sum = 0.0, sum2 = 0.0;
            unsigned long long st = 12345 + 7 * d + 1000 * p;
            int maxb = 0;
            for (int i = 0; i < nx; i++)
                for (int j = 0; j < nz; j++) {
                    st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                    double jx = (double)(st >> 40) / 16777216.0;
                    st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                    double jz = (double)(st >> 40) / 16777216.0;
                    gr_dvec3 q = gr_d3((i + jx) / nx, -depths[d], 4.0 * (j + jz) / nz);
                    double e = gr_ref_irradiance_h(r, q);
                    sum += e;
                    sum2 += e * e;
                    int nb = gr_ref_beam_count(r, q);
                    if (nb > maxb) maxb = nb;
                }
            double mean = sum / (nx * nz), se = sqrt(fmax(0.0, sum2 / (nx * nz) - mean * mean) / (nx * nz - 1));
            printf("elev %4.0f az %4.0f fresnel %d pass %d depth %5.2f m: mean E_h %.6f +- %.6f expected %.6f (%+.3f%%), up to %d beams\n",
                   elev, az, fresnel, p, depths[d], mean, se, expect, 100.0 * (mean / expect - 1.0), maxb);
            /* 1%, widened by the probe's own sampling error: a point that lands in a beam
             * collapsed near a focus reads a huge (integrable) irradiance, a rare spike that the
             * sample's standard error shows */
            CHECK_NEAR(mean, expect, 0.01 * expect + 3.0 * se);
            if (d == 4) CHECK_MSG(maxb >= 2, "past the focus some points must see several beams (folds), got %d", maxb);
        }
    }
    gr_ref_destroy(r);
    free(s);
}

int main(void)
{
    run(90, 0, 0, 2);
    run(60, 30, 0, 2);
    run(35, 200, 0, 1);
    run(60, 30, 1, 1);
    CHECK_DONE();
}
