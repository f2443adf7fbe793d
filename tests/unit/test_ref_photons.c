/* Validation 5: two independent estimators of the caustic irradiance agree within their
 * error bars on the default wavy scene (data/scenes/default.json: its 8 waves, sun and disc).
 *  - main: beam prisms, the horizontal irradiance averaged over a small square bin
 *    (stratified points), over 16 passes (sun-disc directions and grid offsets); standard
 *    error from the spread of the pass means;
 *  - slow and simple: photon binning written here from scratch: rest points drawn uniformly
 *    over a patch that covers every possible source, each carrying the flux
 *    F_t |I . (dP/dx0 x dP/dz0)| dA0 (tangents by central differences of seed eq. 5.5.7,
 *    Snell and Fresnel written out below), a direction drawn uniformly in the sun's disc,
 *    traced straight to the bin's depth; standard error from the sample variance.
 * The bins are 0.25 m squares at 8 m (camera depth) and 20 m. Agreement within 3 combined
 * standard errors. No extinction: irradiance only. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include "core/gerstner.h"

static const double PI = 3.14159265358979323846;

static unsigned long long lcg = 20240601ULL;
static double urand(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg >> 11) * 0x1p-53;
}

static double v_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Snell refraction of unit I through unit upward normal n, air (1) -> water (nw). */
static void snell(const double I[3], const double n[3], double nw, double T[3])
{
    double ci = -v_dot(I, n), eta = 1.0 / nw, k = 1.0 - eta * eta * (1.0 - ci * ci);
    for (int c = 0; c < 3; c++) T[c] = eta * I[c] + (eta * ci - sqrt(k)) * n[c];
}

static double fresnel_t(double cos_i, double n)
{
    double sin_t = sqrt(fmax(0.0, 1.0 - cos_i * cos_i)) / n, cos_t = sqrt(1.0 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

/* Photon estimate of the mean horizontal irradiance (per unit E_sun) over the bin
 * [bx, bx + b] x [bz, bz + b] at height y. */
static void photons(const gr_scene *s, double bx, double bz, double b, double y, long n, double *mean, double *se)
{
    const gr_water *w = &s->water;
    double I0[3] = {s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]};
    /* a frame around I0 for sampling the disc */
    double e1[3] = {I0[2], 0.0, -I0[0]}, l = sqrt(e1[0] * e1[0] + e1[2] * e1[2]);
    e1[0] /= l; e1[2] /= l;
    double e2[3] = {I0[1] * e1[2] - I0[2] * e1[1], I0[2] * e1[0] - I0[0] * e1[2], I0[0] * e1[1] - I0[1] * e1[0]};
    double R = 0.5 * s->sun.angular_diameter_deg * PI / 180.0;
    /* sources: the bin moved back up along the flat refracted ray, padded generously */
    double T0[3], up[3] = {0, 1, 0};
    snell(I0, up, s->medium.ior, T0);
    double cx = bx + 0.5 * b - T0[0] / T0[1] * y, cz = bz + 0.5 * b - T0[2] / T0[1] * y;
    double half = 0.5 * b + 0.8 + 0.12 * fabs(y);
    double area = 4.0 * half * half, h = 1e-5, sum = 0.0, sum2 = 0.0;
    for (long i = 0; i < n; i++) {
        double x0 = cx - half + 2.0 * half * urand(), z0 = cz - half + 2.0 * half * urand();
        double cr = 1.0 - urand() * (1.0 - cos(R)), sr = sqrt(fmax(0.0, 1.0 - cr * cr)), ph = 2.0 * PI * urand();
        double I[3];
        for (int c = 0; c < 3; c++) I[c] = I0[c] * cr + (e1[c] * cos(ph) + e2[c] * sin(ph)) * sr;
        gr_dvec3 P = gr_gerstner_position(w, x0, z0, w->time_s);
        gr_dvec3 px = gr_d3_scale(gr_d3_sub(gr_gerstner_position(w, x0 + h, z0, w->time_s), gr_gerstner_position(w, x0 - h, z0, w->time_s)), 0.5 / h);
        gr_dvec3 pz = gr_d3_scale(gr_d3_sub(gr_gerstner_position(w, x0, z0 + h, w->time_s), gr_gerstner_position(w, x0, z0 - h, w->time_s)), 0.5 / h);
        gr_dvec3 a = gr_d3_cross(pz, px); /* upward area vector per unit rest area */
        double al = gr_d3_len(a), n_[3] = {a.x / al, a.y / al, a.z / al};
        double ci = -v_dot(I, n_);
        double f = 0.0;
        if (ci > 0.0) {
            double T[3];
            snell(I, n_, s->medium.ior, T);
            double t = (y - P.y) / T[1];
            double X = P.x + T[0] * t, Z = P.z + T[2] * t;
            if (X >= bx && X < bx + b && Z >= bz && Z < bz + b) f = fresnel_t(ci, s->medium.ior) * ci * al * area / (b * b);
        }
        sum += f;
        sum2 += f * f;
    }
    *mean = sum / n;
    *se = sqrt(fmax(0.0, sum2 / n - *mean * *mean) / (n - 1));
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[4096];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    /* no camera cone: the irradiance probes read the plain grid's set only
     * (gr_ref_irradiance_h), and the cone's refined set, built for camera rays, was most of
     * this test's time (without extinction it reaches the seabed: 8.6 M primitives a pass) */
    const char *ov[] = {"medium.absorption_per_m=0", "medium.scattering_per_m=0", "reference.sun_samples=16",
                        "reference.batches=2", "reference.surface_res=256", "reference.refine_factor=1"};
    gr_scene *s = malloc(sizeof *s);
    gr_error err = {GR_OK, ""};
    if (!s || gr_scene_load_file(path, ov, 6, s, &err) != GR_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    int reduced = ref_reduced();
    const double bins[][3] = {{0.3, 2.1, -8.0}, {-1.7, 4.4, -8.0}, {2.6, 6.0, -8.0}, {1.0, 3.0, -20.0}};
    const int nbins = reduced ? 2 : 4;
    const long nphot = reduced ? 300000 : 4000000;
    const double b = 0.25;
    for (int k = 0; k < nbins; k++) {
        double bx = bins[k][0], bz = bins[k][1], y = bins[k][2];
        gr_ref_options o;
        gr_ref_options_default(&o);
        o.progress = 0;
        o.lit_box_valid = 1;
        double box[5] = {bx - 0.5, bx + b + 0.5, bz - 0.5, bz + b + 0.5, y - 0.5};
        memcpy(o.lit_box, box, sizeof box);
        gr_ref_renderer *r = NULL;
        CHECK_OK(gr_ref_create(s, &o, &r, &err), err);
        if (!r) return 1;
        const int passes = 16, m = 24;
        double pm[16], s1 = 0.0, s2 = 0.0;
        for (int p = 0; p < passes; p++) {
            CHECK_OK(gr_ref_prepare_pass(r, p, &err), err);
            double acc = 0.0;
            for (int i = 0; i < m; i++)
                for (int j = 0; j < m; j++)
                    acc += gr_ref_irradiance_h(r, gr_d3(bx + b * (i + urand()) / m, y, bz + b * (j + urand()) / m));
            pm[p] = acc / (m * m);
            s1 += pm[p];
            s2 += pm[p] * pm[p];
        }
        gr_ref_destroy(r);
        double beam = s1 / passes, beam_se = sqrt(fmax(0.0, (s2 - passes * beam * beam) / (passes - 1)) / passes);
        double ph, ph_se;
        photons(s, bx, bz, b, y, nphot, &ph, &ph_se);
        double tol = 3.0 * sqrt(beam_se * beam_se + ph_se * ph_se);
        printf("bin (%.2f, %.2f) at y = %g m: beams %.4f +- %.4f, photons %.4f +- %.4f, difference %.4f (3 sigma %.4f)\n",
               bx, bz, y, beam, beam_se, ph, ph_se, beam - ph, tol);
        CHECK_NEAR(beam, ph, tol);
    }
    free(s);
    CHECK_DONE();
}
