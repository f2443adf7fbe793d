/* Oracle 1 (../shared/notes/physics-oracles.md): flat water, closed form.
 * L = sigma_s p(T.-w) E_w exp(-sigma_t z0 / mu_t) (1 - exp(-sigma_t k D)) / (sigma_t k),
 * k = 1 - w_y / mu_t, E_w = F_t E_sun cos(theta_i) / cos(theta_t), per RGB channel, with
 * D the distance to the ray's end (surface, seabed, or reference.max_distance_m): the physical
 * value, not the renderer's transmittance cutoff, which may drop at most its own fraction of
 * a channel (1e-4 by default; docs/reference.md 1). Until 2026-11-29 the oracle ended its rays at the cutoff as the
 * renderer did, D_cut = -ln(cutoff) / sigma_t, which hid that a ray rising toward the sun
 * (k = 0: an integrand that does not fall) lost everything past it: 31 % of the light
 * looking up the refracted sun from 5 m with sigma_t 2 /m, 8-10 % from 100 m with 0.07 /m.
 * The deep cases below (camera at 100 m) check that.
 * The oracle is evaluated here from Snell's law, the Fresnel equations and the HG formula
 * written out independently. Each case renders one pixel with a 0.01 deg field of view
 * through the whole pipeline (Embree ends, march, batches), with a point sun. Tolerance
 * 0.5% relative. A second sweep forces the beam-prism path on the same flat water. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>

static double fresnel_t(double cos_i, double n)
{
    double sin_t = sqrt(fmax(0.0, 1.0 - cos_i * cos_i)) / n, cos_t = sqrt(1.0 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

static double hg(double c, double g)
{
    return (1.0 - g * g) / (4.0 * 3.14159265358979323846 * pow(1.0 + g * g - 2.0 * g * c, 1.5));
}

static int cases = 0, failures_before = 0;

static void one_at(double elev, int view, double g, double sig_t, int seabed, int beams, double z0)
{
    const double deg = 3.14159265358979323846 / 180.0, n = 1.333, H = z0 + 15.0, az = 30.0;
    const double Esun[3] = {1.0, 0.8, 0.6};
    double sin_t = cos(elev * deg) / n, theta_t = asin(sin_t), mu_t = cos(theta_t);
    double yaw = 0, pitch = 0;
    switch (view) {
    case 0: yaw = 10; pitch = 89; break;                                /* up */
    case 1: yaw = az + 90; pitch = 0; break;                            /* horizontal */
    case 2: yaw = az; pitch = 90.0 - theta_t / deg; break;              /* toward the sun */
    case 3: yaw = az + 180; pitch = -(90.0 - theta_t / deg); break;     /* away */
    default: yaw = az; pitch = 0.5 * (90.0 - theta_t / deg); break;     /* rising, half as steep as the sun */
    }
    char bed[64] = "";
    if (seabed) snprintf(bed, sizeof bed, ",\"seabed\":{\"depth_m\":%g}", H);
    gr_scene *s = ref_scene(
        "{\"water\":{\"waves\":[]},"
        "\"sun\":{\"elevation_deg\":%g,\"azimuth_deg\":%g,\"angular_diameter_deg\":0,\"irradiance\":[%g,%g,%g]},"
        "\"medium\":{\"absorption_per_m\":%.17g,\"scattering_per_m\":%.17g,\"g\":%g,\"ior\":%g},"
        "\"camera\":{\"position_m\":[3,%g,-2],\"yaw_deg\":%.17g,\"pitch_deg\":%.17g,\"fov_deg\":0.01,\"width\":1,\"height\":1},"
        "\"reference\":{\"spp\":1,\"steps\":64,\"batches\":2,\"sun_samples\":2,\"surface_res\":64}%s}",
        elev, az, Esun[0], Esun[1], Esun[2], 0.4 * sig_t, 0.6 * sig_t, g, n, -z0, yaw, pitch, bed);
    double w[3] = {s->camera.forward[0], s->camera.forward[1], s->camera.forward[2]};
    /* refracted sun direction T: horizontal part away from the sun's azimuth */
    double T[3] = {-sin_t * sin(az * deg), -mu_t, -sin_t * cos(az * deg)};
    double D = s->reference.max_distance_m;
    if (w[1] > 0.0) D = fmin(D, z0 / w[1]);
    if (seabed && w[1] < 0.0) D = fmin(D, (H - z0) / -w[1]);
    double k = 1.0 - w[1] / mu_t, cos_i = sin(elev * deg);
    double Ew = fresnel_t(cos_i, n) * cos_i / mu_t;
    double ph = hg(-(T[0] * w[0] + T[1] * w[1] + T[2] * w[2]), g);
    double x = sig_t * k * D;
    double integral = fabs(x) > 1e-9 ? -expm1(-x) / (sig_t * k) : D;
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.force_beams = beams;
    gr_ref_result res;
    ref_render(s, &o, &res);
    const gr_meta_item *flat = gr_meta_get(&res.meta, "godrays:flat_water_closed_form");
    CHECK_MSG(flat && (int)flat->num == !beams, "flat water must take the closed form (and beams only when forced)");
    for (int c = 0; c < 3; c++) {
        double expect = 0.6 * sig_t * ph * Esun[c] * Ew * exp(-sig_t * z0 / mu_t) * integral;
        double got = res.image->pixels[c];
        int before = gr_check_failures;
        CHECK_REL(got, expect, 0.005);
        if (gr_check_failures != before)
            fprintf(stderr, "  case: elev %g view %d g %g sigma_t %g seabed %d beams %d depth %g channel %d (D %g)\n", elev,
                    view, g, sig_t, seabed, beams, z0, c, D);
    }
    cases++;
    gr_ref_result_free(&res);
    free(s);
}

static void one(double elev, int view, double g, double sig_t, int seabed, int beams)
{
    one_at(elev, view, g, sig_t, seabed, beams, 5.0);
}

int main(void)
{
    const double elevs[] = {5, 30, 60, 90}, gs[] = {0, 0.5, 0.9}, sigs[] = {0.01, 0.3, 2.0};
    for (int e = 0; e < 4; e++)
        for (int v = 0; v < 4; v++)
            for (int gi = 0; gi < 3; gi++)
                for (int si = 0; si < 3; si++)
                    for (int b = 0; b < 2; b++) one(elevs[e], v, gs[gi], sigs[si], b, 0);
    printf("closed-form path: %d cases\n", cases);
    failures_before = gr_check_failures;
    /* the beam-prism path on flat water must give the same closed form */
    for (int e = 0; e < 4; e++)
        for (int v = 0; v < 4; v++) one(elevs[e], v, 0.5, 0.3, v & 1, 1);
    printf("beam path: %d cases\n", cases);
    /* deep cameras (100 m) looking toward the sun, rising at half its slope, horizontally:
     * rays of 100-1000 m whose integrand falls slowly or not at all */
    for (int e = 1; e < 4; e++)
        for (int v = 0; v < 3; v++) {
            static const int views[3] = {2, 4, 1};
            one_at(elevs[e], views[v], 0.9, 0.07, 0, 0, 100.0);
            one_at(elevs[e], views[v], 0.5, 0.01, 1, 0, 100.0);
        }
    printf("deep cameras: %d cases\n", cases);
    CHECK_DONE();
}
