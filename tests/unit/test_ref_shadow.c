/* Validation 4: shadows. Flat water, a box and a sphere under water, a horizontal camera
 * ray passing through their shadows. The oracle integrates the closed-form integrand of
 * Oracle 1 numerically (200k midpoints) over [0, D], dropping every point whose sun ray
 * (along -T up to the surface) hits an occluder, with its own slab and sphere tests.
 * Also checks that a scene without occluders traces no shadow rays. Fixed 256 steps (not
 * adaptive, whose target of about 1 % noise is looser than the 0.5 % this oracle checks). */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>

static const double PI = 3.14159265358979323846;

static int hits_box(const double o[3], const double d[3], double tmax, const double c[3], const double sz[3])
{
    double t0 = 0.0, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        double lo = c[k] - 0.5 * sz[k], hi = c[k] + 0.5 * sz[k];
        if (fabs(d[k]) < 1e-15) {
            if (o[k] < lo || o[k] > hi) return 0;
            continue;
        }
        double a = (lo - o[k]) / d[k], b = (hi - o[k]) / d[k];
        if (a > b) { double tmp = a; a = b; b = tmp; }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
        if (t0 > t1) return 0;
    }
    return 1;
}

static int hits_sphere(const double o[3], const double d[3], double tmax, const double c[3], double r)
{
    double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
    double disc = b * b - cc;
    if (disc < 0.0) return 0;
    double s = sqrt(disc), ta = -b - s, tb = -b + s;
    return (ta > 0.0 && ta < tmax) || (tb > 0.0 && tb < tmax) || (ta < 0.0 && tb > 0.0);
}

static double fresnel_t(double cos_i, double n)
{
    double sin_t = sqrt(fmax(0.0, 1.0 - cos_i * cos_i)) / n, cos_t = sqrt(1.0 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

int main(void)
{
    const double elev = 60.0, n = 1.333, sig = 0.2, g = 0.5, z0 = 6.0;
    const double box_c[3] = {5.0, -3.0, 1.2}, box_s[3] = {2.0, 1.0, 1.0};
    const double sph_c[3] = {11.0, -2.5, 1.4}, sph_r = 0.7;
    for (int with_occ = 0; with_occ < 2; with_occ++) {
        char occ[512] = "";
        if (with_occ)
            snprintf(occ, sizeof occ,
                     ",\"occluders\":[{\"type\":\"box\",\"center_m\":[%g,%g,%g],\"size_m\":[%g,%g,%g]},"
                     "{\"type\":\"sphere\",\"center_m\":[%g,%g,%g],\"radius_m\":%g}]",
                     box_c[0], box_c[1], box_c[2], box_s[0], box_s[1], box_s[2], sph_c[0], sph_c[1], sph_c[2], sph_r);
        gr_scene *s = ref_scene(
            "{\"water\":{\"waves\":[]},\"sun\":{\"elevation_deg\":%g,\"azimuth_deg\":0,\"angular_diameter_deg\":0},"
            "\"medium\":{\"absorption_per_m\":%g,\"scattering_per_m\":%g,\"g\":%g,\"ior\":%g},"
            "\"camera\":{\"position_m\":[0,%g,0],\"yaw_deg\":90,\"pitch_deg\":0,\"fov_deg\":0.01,\"width\":1,\"height\":1},"
            "\"reference\":{\"spp\":4,\"steps\":256,\"adaptive_steps\":false,\"batches\":4,\"sun_samples\":4}%s}",
            elev, 0.5 * sig, 0.5 * sig, g, n, -z0, occ);
        gr_ref_result res;
        ref_render(s, NULL, &res);
        const gr_meta_item *sr = gr_meta_get(&res.meta, "godrays:shadow_rays_per_s");
        CHECK_MSG(sr && (with_occ ? sr->num > 0.0 : sr->num == 0.0), "shadow rays must be traced iff there are occluders");
        /* oracle */
        double cos_i = sin(elev * PI / 180.0), sin_t = cos(elev * PI / 180.0) / n, mu = sqrt(1.0 - sin_t * sin_t);
        double T[3] = {0.0, -mu, -sin_t}, w[3] = {s->camera.forward[0], s->camera.forward[1], s->camera.forward[2]};
        /* the physical ray, to max_distance_m: not the renderer's cutoff, which may drop at
         * most the cutoff's fraction (docs/reference.md 1) */
        double D = s->reference.max_distance_m;
        double Ew = fresnel_t(cos_i, n) * cos_i / mu;
        double ph = (1 - g * g) / (4 * PI * pow(1 + g * g + 2 * g * (T[0] * w[0] + T[1] * w[1] + T[2] * w[2]), 1.5));
        const int N = 2000000; /* 0.5 mm over 1000 m */
        double sum = 0.0, full = 0.0;
        for (int i = 0; i < N; i++) {
            double t = D * (i + 0.5) / N;
            double x[3] = {w[0] * t, -z0 + w[1] * t, w[2] * t};
            double depth = -x[1], path = depth / mu;
            double f = 0.5 * sig * ph * Ew * exp(-sig * path) * exp(-sig * t) * D / N;
            full += f;
            double up[3] = {-T[0], -T[1], -T[2]};
            if (with_occ && (hits_box(x, up, path, box_c, box_s) || hits_sphere(x, up, path, sph_c, sph_r))) continue;
            sum += f;
        }
        double got = res.image->pixels[0], se = res.image->pixels[3];
        printf("occluders %d: rendered %.6g +- %.2g, oracle %.6g (unshadowed %.6g), %+.3f%%\n", with_occ, got, se, sum,
               full, 100.0 * (got / sum - 1.0));
        CHECK_REL(got, sum, 0.005);
        if (with_occ) CHECK_MSG(sum < 0.9 * full, "the shadows must matter in this setup (%g vs %g)", sum, full);
        gr_ref_result_free(&res);
        free(s);
    }
    CHECK_DONE();
}
