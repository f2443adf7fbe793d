#include "reference/integrator.h"

#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#if defined(__SSE2__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

#include "core/gerstner.h"
#include "core/optics.h"
#include "core/rng.h"
#include "core/student.h"
#include "reference/beams.h"
#include "reference/embree_scene.h"
#include "reference/progress.h"
#include "scene/settings.h"

#define REF_DEFAULT_MAX_PRIMS ((size_t)16 * 1024 * 1024)
#define REF_EXP_LIMIT 700.0 /* exp(-700) ~ 1e-304: below any image value, above denormals */

/* Random numbers: counter-based (core/rng.h), one generator per (seed, stream, index), so
 * a sample's numbers never depend on the thread that draws them. */
typedef gr_rng ref_rng;
static inline ref_rng rng_make(uint64_t seed, uint64_t stream, uint64_t index) { return gr_rng_make(seed, stream, index); }
static inline double rng_u(ref_rng *r) { return gr_rng_double(r); } /* [0, 1) */
/* streams under the render's seed: 1 the passes (index: pass), 4 the step pilot's rays (index:
 * pilot pixel), 16 + pixel the camera samples (index: sample); 2 and 3 are the benchmarks'
 * (seed 42). The pilot's numbers are thus independent of every number of the estimate. */
enum { STREAM_PASS = 1, STREAM_PILOT = 4, STREAM_PIXEL0 = 16 };
/* The step pilot's beam set: a pass index no render reaches (rounds x passes <= 64 x 4096),
 * so its grid offset is independent of the render's passes (docs/reference.md 2.5). */
#define PILOT_PASS INT_MAX
/* The step pilot (docs/reference.md 2.5): one ray per PILOT_STRIDE x PILOT_STRIDE block of
 * pixels; a pixel's step noise from the mean over the (2 PILOT_RADIUS + 1)^2 pilot pixels
 * around it; the image mean that normalizes it from every PILOT_MEAN_STRIDE-th pilot pixel
 * in x and y (so every part of a split render computes the same mean). */
enum { PILOT_STRIDE = 2, PILOT_RADIUS = 2, PILOT_MEAN_STRIDE = 4 };
/* the exponent of the step-noise model V(n) = V(n0) (n0 / n)^alpha (docs/reference.md 2.5) */
#define PILOT_ALPHA 2.0
/* Steps along the ray (docs/reference.md 2.5, "Steps along the ray"): the march's CDF range
 * [0, 1) is cut into SEGMENTS equal parts, each with its own number of jittered strata (at
 * least one), allotted from the pilot's step noise in that part. */
enum { SEGMENTS = 8 };
#define ALLOT_FLOOR 0.25
/* the march's unit of work: bands of MARCH_TILE rows, walked in square tiles (worker; the
 * pilot's of MARCH_TILE / PILOT_STRIDE pilot pixels: the same image area) */
#define MARCH_TILE 16
/* the surface-bias probe's pixel grid and passes (surface_bias_probe) */
enum { PROBE_STRIDE = 5, PROBE_PASSES = 4 };

typedef struct ref_light {
    gr_vec3 T;        /* unit refracted direction */
    float eperp;      /* irradiance perpendicular to T per unit E_sun, before extinction */
    float path;       /* distance from the surface along T */
} ref_light;

struct gr_ref_renderer {
    gr_scene scene;
    gr_ref_options opt;
    gr_reference_settings set;
    gr_rtc *rtc;
    gr_ref_geometry *geom;
    gr_beams *beams;
    /* The camera cone's beam set (docs/reference.md 2.2, "Local refinement"): camera rays
     * within refine_angle of +-T0 look up `cone`, refined near P_s and covering only the
     * region such rays reach (cone_box, sheared u0 u1 w0 w1); every other ray looks up
     * `beams`, the plain grid. NULL: no refinement (factor 1, or no camera ray that close) */
    gr_beams *cone;
    int cone_on;              /* 1: a cone (set by gr_ref_create, the same for every pass) */
    double cone_box[4], cone_cos;
    int beams_pass;
    int flat;
    gr_dvec3 origin;          /* (camera x, rest height, camera z) */
    gr_vec3 cam;              /* camera in the local frame */
    gr_dvec3 I0, T0, e1, e2;  /* sun centre, its flat refraction, a frame around I0 */
    double sx, sz;            /* shear T0x / T0y, T0z / T0y */
    double sun_radius;        /* angular radius in air (rad) */
    int convolve;             /* 1: the disc by the analytic convolution, passes use I0 */
    int rendering;            /* 1 inside gr_ref_render (beam sets for the march) */
    double cutoff_d;
    gr_beam_region region;
    double pad;
    int passes_per_round, spp_pass, batches, threads;
    double sig_t[3], sig_s[3], E[3];
    double sig_ref;           /* min_c sigma_t: the march's importance density */
    /* current pass */
    gr_dvec3 Ip;
    gr_vec3 Tp;
    float flat_eperp;         /* F_t cos(theta_i) / cos(theta_t): Oracle 1's E_w / E_sun */
    float mu_t;
    double beam_build_s;
    /* surface-bias probe: mean |bias| / mean (-1 = not estimated), its cost and size */
    double bias_rel, bias_probe_s;
    double bias_ratio, bias_order; /* the probe's |L_4h - L_2h| / |L_2h - L_h| and the order p used */
    double bias_rel_cons;     /* the same with the measured order (conservative) */
    gr_beam_stats main_beams; /* the main passes' last beam set (the probe builds others) */
    int have_main_beams;
    long long bias_probe_pixels;
    int bias_probe_passes;
    /* While the main passes 0 .. PROBE_PASSES - 1 run: the probe's level-h accumulator (NULL
     * otherwise). A probe pixel's level-h value is exactly the main pass's (the same beam set,
     * steps and random numbers), so it is taken there instead of building the beam set again;
     * probe_captured has bit p set once pass p was taken (surface_bias_probe) */
    struct ref_accum *probe_capture;
    int probe_capture_off;
    unsigned probe_captured;
    /* per probe pixel (pw x ph, stride PROBE_STRIDE, offset poff), RGB: the signed Richardson
     * estimate of the surface bias (bias.R/G/B channels; NULL when not estimated) */
    float *bias_px;
    int bias_pw, bias_ph, bias_poff;
    double bias_block_p95;    /* 95th percentile of |block bias| / max(block mean, image mean) */
    int bias_blocks;
    /* adaptive steps (docs/reference.md 2.5): march steps per image pixel (NULL: r->set.steps
     * everywhere), set by the pilot for the rows [row0, row1); their statistics */
    int *steps_px;
    uint16_t *alloc_px;       /* per pixel: the strata of each of the SEGMENTS parts (NULL: uniform) */
    int pilot_n0;             /* the pilot's steps (0: no pilot) */
    double steps_sum, steps_pixels, pilot_s;
    int steps_min, steps_max;
};

void gr_ref_options_default(gr_ref_options *o)
{
    memset(o, 0, sizeof *o);
    o->fresnel = 1;
    o->progress = 1;
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int is_flat(const gr_water *w)
{
    for (int i = 0; i < w->n_waves; i++)
        if (w->waves[i].amplitude_m != 0.0) return 0;
    return 1;
}

static double wave_amplitude_sum(const gr_water *w)
{
    double a = 0.0;
    for (int i = 0; i < w->n_waves; i++) a += fabs(w->waves[i].amplitude_m);
    return a;
}

static gr_dvec3 cam_dir(const gr_ref_renderer *r, double ndx, double ndy)
{
    const gr_camera *c = &r->scene.camera;
    gr_dvec3 f = gr_d3(c->forward[0], c->forward[1], c->forward[2]);
    gr_dvec3 rt = gr_d3(c->right[0], c->right[1], c->right[2]);
    gr_dvec3 up = gr_d3(c->up[0], c->up[1], c->up[2]);
    return gr_d3_norm(gr_d3_madd(gr_d3_madd(f, rt, ndx), up, ndy));
}

static void grow(double b[4], double u, double w)
{
    if (u < b[0]) b[0] = u;
    if (u > b[1]) b[1] = u;
    if (w < b[2]) b[2] = w;
    if (w > b[3]) b[3] = w;
}

/* Largest drift |T_xz / T_y - T0_xz / T0_y| of a refracted ray per metre of height, over
 * every normal the waves can have: Gerstner slopes are bounded by tan = Q / sqrt(1 - Q^2)
 * with Q = sum a_i k_i (the slope sin / (1 - Q cos) peaks at cos = Q). */
static double max_drift(const gr_ref_renderer *r)
{
    double Q = gr_gerstner_steepness(&r->scene.water);
    if (Q >= 0.999) Q = 0.999;
    double tilt = atan(Q / sqrt(1.0 - Q * Q)) + r->sun_radius;
    double best = 0.0;
    for (int ia = 0; ia < 64; ia++) {
        double az = 2.0 * GR_PI * ia / 64.0;
        for (int it = 1; it <= 8; it++) {
            double a = tilt * it / 8.0;
            gr_dvec3 n = gr_d3(sin(a) * sin(az), cos(a), sin(a) * cos(az));
            if (gr_d3_dot(r->I0, n) >= 0.0) continue;
            gr_dvec3 T = gr_refract_d(r->I0, n, 1.0 / r->scene.medium.ior);
            if (!(T.y < -1e-3)) return INFINITY;
            double du = T.x / T.y - r->sx, dw = T.z / T.y - r->sz;
            double d = sqrt(du * du + dw * dw);
            if (d > best) best = d;
        }
    }
    return best;
}

/* The lit region: sheared bounds of the visible volume (camera frustum up to each ray's
 * end), clamped to reference.patch_radius_m around the camera. */
static void compute_region(gr_ref_renderer *r)
{
    const gr_scene *s = &r->scene;
    double A = wave_amplitude_sum(&s->water);
    double R = s->reference.patch_radius_m;
    double b[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    double ymin = 0.0;
    gr_vec3 o = r->cam;
    double seabed_y = s->has_seabed ? -s->seabed_depth_m : -INFINITY;
    if (r->opt.lit_box_valid) {
        const double *lb = r->opt.lit_box;
        ymin = lb[4] - r->origin.y;
        for (int i = 0; i < 8; i++) {
            double x = ((i & 1) ? lb[1] : lb[0]) - r->origin.x, z = ((i & 2) ? lb[3] : lb[2]) - r->origin.z;
            double y = (i & 4) ? A : ymin;
            grow(b, x - r->sx * y, z - r->sz * y);
        }
    } else {
        grow(b, o.x - r->sx * o.y, o.z - r->sz * o.y);
        ymin = o.y;
        const gr_camera *c = &s->camera;
        double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), aspect = (double)c->width / (double)c->height;
        enum { NS = 16 };
        for (int iy = 0; iy <= NS; iy++)
            for (int ix = 0; ix <= NS; ix++) {
                gr_dvec3 d = cam_dir(r, (2.0 * ix / NS - 1.0) * tf * aspect, (1.0 - 2.0 * iy / NS) * tf);
                double D = r->cutoff_d;
                if (d.y < 0.0 && s->has_seabed) D = fmin(D, (seabed_y - o.y) / d.y);
                if (d.y > 0.0) D = fmin(D, (A - o.y) / d.y);
                double ex = o.x + D * d.x, ey = o.y + D * d.y, ez = o.z + D * d.z;
                grow(b, ex - r->sx * ey, ez - r->sz * ey);
                if (ey < ymin) ymin = ey;
            }
        double uc = o.x - r->sx * o.y, wc = o.z - r->sz * o.y;
        b[0] = fmax(b[0], uc - R); b[1] = fmin(b[1], uc + R);
        b[2] = fmax(b[2], wc - R); b[3] = fmin(b[3], wc + R);
        ymin = fmax(ymin, o.y - R);
    }
    ymin = fmax(ymin, seabed_y);
    ymin = fmin(ymin, -A) - 0.05;
    double mu = 0.02 * fmax(b[1] - b[0], b[3] - b[2]) + 0.1;
    r->region.u0 = b[0] - mu; r->region.u1 = b[1] + mu;
    r->region.w0 = b[2] - mu; r->region.w1 = b[3] + mu;
    r->region.y_min = ymin;
    /* rest patch margin: horizontal Gerstner displacement plus the largest drift of a beam
     * over the region's depth (rays enter the region from outside it) */
    double pad = A + fabs(ymin) * max_drift(r) + 0.25;
    if (!(pad <= R)) pad = R;
    r->pad = pad;
}

gr_status gr_ref_create(const gr_scene *s, const gr_ref_options *o, gr_ref_renderer **out, gr_error *err)
{
    *out = NULL;
    gr_ref_renderer *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "reference: out of memory");
    r->scene = *s;
    if (o) r->opt = *o;
    else gr_ref_options_default(&r->opt);
    if (!r->opt.max_prims) r->opt.max_prims = REF_DEFAULT_MAX_PRIMS;
    if (!r->opt.max_rounds) r->opt.max_rounds = 64;
    r->set = s->reference;
    r->beams_pass = -1;
    r->bias_rel = -1.0;
    r->flat = is_flat(&s->water) && !r->opt.force_beams;
    const gr_reference_settings *st = &r->set;
    if (st->batches < 2) {
        int nb = st->batches;
        free(r);
        return gr_fail(err, GR_E_INPUT, "reference.batches: %d, need at least 2 for error bars", nb);
    }
    r->batches = st->batches;
    /* a part of the work (godrays farm): rows [row0, row1), batches [batch0, batch1) */
    if (!r->opt.row0 && !r->opt.row1) r->opt.row1 = s->camera.height;
    if (!r->opt.batch0 && !r->opt.batch1) r->opt.batch1 = r->batches;
    if (r->opt.row0 < 0 || r->opt.row1 > s->camera.height || r->opt.row0 >= r->opt.row1 || r->opt.batch0 < 0 ||
        r->opt.batch1 > r->batches || r->opt.batch0 >= r->opt.batch1) {
        gr_status e = gr_fail(err, GR_E_INPUT, "reference: part rows [%d, %d) of %d, batches [%d, %d) of %d: empty or outside",
                              r->opt.row0, r->opt.row1, s->camera.height, r->opt.batch0, r->opt.batch1, r->batches);
        free(r);
        return e;
    }
    if ((r->opt.row1 - r->opt.row0 < s->camera.height || r->opt.batch1 - r->opt.batch0 < r->batches) &&
        st->target_error > 0.0) {
        free(r);
        return gr_fail(err, GR_E_INPUT, "reference.target_error: a part of a render (rows or batches) takes the fixed "
                                        "passes of one round; set it to 0 (docs/farm.md)");
    }
    int S = st->sun_samples < 1 ? 1 : st->sun_samples;
    /* every batch gets the same number of passes: round the sun samples up */
    r->passes_per_round = ((S + r->batches - 1) / r->batches) * r->batches;
    /* reference.spp counts samples per pixel in each batch; a batch has P / B passes */
    int per_batch = r->passes_per_round / r->batches;
    r->spp_pass = (st->spp + per_batch - 1) / per_batch;
    if (r->spp_pass < 1) r->spp_pass = 1;
    r->threads = st->threads > 0 ? st->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (r->threads < 1) r->threads = 1;

    r->origin = gr_d3(s->camera.position_m[0], s->water.rest_height_m, s->camera.position_m[2]);
    r->cam = gr_v3(0.0f, (float)(s->camera.position_m[1] - s->water.rest_height_m), 0.0f);
    r->I0 = gr_d3_norm(gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]));
    r->T0 = gr_refract_d(r->I0, gr_d3(0, 1, 0), 1.0 / s->medium.ior);
    r->sx = r->T0.x / r->T0.y;
    r->sz = r->T0.z / r->T0.y;
    gr_dvec3 helper = fabs(r->I0.y) < 0.9 ? gr_d3(0, 1, 0) : gr_d3(1, 0, 0);
    r->e1 = gr_d3_norm(gr_d3_cross(r->I0, helper));
    r->e2 = gr_d3_cross(r->I0, r->e1);
    r->sun_radius = 0.5 * s->sun.angular_diameter_deg * GR_PI / 180.0;
    r->convolve = st->sun_disc == GR_SUN_DISC_CONVOLVE && r->sun_radius > 0.0;
    double smin = INFINITY;
    for (int c = 0; c < 3; c++) {
        r->sig_t[c] = s->medium.extinction[c];
        r->sig_s[c] = s->medium.scattering[c];
        r->E[c] = s->sun.irradiance[c];
        if (r->sig_t[c] < smin) smin = r->sig_t[c];
    }
    r->sig_ref = smin > 0.0 ? smin : 0.0;
    /* camera rays stop where the transmittance of the least attenuated channel falls below
     * the cutoff, and in any case at reference.max_distance_m */
    r->cutoff_d = st->max_distance_m;
    if (smin > 0.0 && st->transmittance_cutoff > 0.0) r->cutoff_d = fmin(r->cutoff_d, -log(st->transmittance_cutoff) / smin);
    compute_region(r);
    {
        /* the camera cone's radius (docs/reference.md 2.2): the same for every pass */
        gr_beam_params bp;
        memset(&bp, 0, sizeof bp);
        bp.shear_x = r->sx;
        bp.shear_z = r->sz;
        bp.region = r->region;
        bp.refine_factor = st->refine_factor;
        bp.refine_angle = st->refine_angle_deg * GR_PI / 180.0;
        bp.camera = &s->camera;
        bp.eye = r->cam;
        double rho = r->flat ? -1.0 : gr_beam_refine_radius(&bp);
        if (rho >= 0.0) {
            /* its rays stay within rho of P_s (sheared); the waves' displacement as margin */
            double R = rho + wave_amplitude_sum(&s->water), pu = r->cam.x - r->sx * r->cam.y, pw = r->cam.z - r->sz * r->cam.y;
            r->cone_on = 1;
            r->cone_box[0] = pu - R; r->cone_box[1] = pu + R;
            r->cone_box[2] = pw - R; r->cone_box[3] = pw + R;
            r->cone_cos = cos(bp.refine_angle);
        }
    }

    gr_status rc = gr_rtc_create(r->threads, &r->rtc, err);
    if (rc == GR_OK)
        rc = gr_ref_geometry_create(r->rtc, s, r->origin, r->cutoff_d + fabs(r->cam.y) + 1.0, &r->geom, err);
    if (rc != GR_OK) {
        gr_ref_destroy(r);
        return rc;
    }
    *out = r;
    return GR_OK;
}

void gr_ref_destroy(gr_ref_renderer *r)
{
    if (!r) return;
    gr_beams_destroy(r->beams);
    gr_beams_destroy(r->cone);
    free(r->bias_px);
    free(r->steps_px);
    free(r->alloc_px);
    gr_ref_geometry_destroy(r->geom);
    gr_rtc_destroy(r->rtc);
    free(r);
}

gr_dvec3 gr_ref_pass_sun_dir(const gr_ref_renderer *r, int pass)
{
    /* the convolution averages the disc analytically around its centre (docs/reference.md):
     * sampling directions as well would count the disc twice */
    if (r->convolve) return r->I0;
    ref_rng g = rng_make(r->set.seed, STREAM_PASS, (uint64_t)pass);
    /* Stratified in the disc's solid angle (cos r uniform in [cos R, 1]), random azimuth.
     * The strata are those of one batch: batch b = pass mod B takes the passes b, b + B, ...
     * of a round, the k-th of them stratum k of P / B. Every batch is then a stratified
     * estimator of its own, independent of the others, so the spread of the batch means is
     * an honest error bar (strata spread across batches would inflate it). */
    int per_batch = r->passes_per_round / r->batches;
    int k = (pass % r->passes_per_round) / r->batches;
    double u = (k + rng_u(&g)) / per_batch;
    double phi = 2.0 * GR_PI * rng_u(&g);
    double cr = 1.0 - u * (1.0 - cos(r->sun_radius)), sr = sqrt(fmax(0.0, 1.0 - cr * cr));
    gr_dvec3 off = gr_d3_madd(gr_d3_scale(r->e1, cos(phi)), r->e2, sin(phi));
    return gr_d3_norm(gr_d3_madd(gr_d3_scale(r->I0, cr), off, sr));
}

gr_status gr_ref_prepare_pass(gr_ref_renderer *r, int pass, gr_error *err)
{
    r->Ip = gr_ref_pass_sun_dir(r, pass);
    ref_rng g = rng_make(r->set.seed, STREAM_PASS, (uint64_t)pass);
    (void)rng_u(&g);
    (void)rng_u(&g);
    double jit[2] = {rng_u(&g), rng_u(&g)};
    if (r->opt.fixed_grid) jit[0] = jit[1] = 0.5;
    /* Oracle 1: flat refraction, E_w / E_sun = F_t cos(theta_i) / cos(theta_t) */
    gr_dvec3 T = gr_refract_d(r->Ip, gr_d3(0, 1, 0), 1.0 / r->scene.medium.ior);
    double cos_i = -r->Ip.y;
    double ft = r->opt.fresnel ? 1.0 - gr_fresnel_exact(cos_i, 1.0, r->scene.medium.ior) : 1.0;
    r->Tp = gr_d3_to_f(T);
    r->mu_t = (float)(-T.y);
    r->flat_eperp = (float)(ft * cos_i / -T.y);
    if (r->flat || r->beams_pass == pass) return GR_OK;
    gr_beams_destroy(r->beams);
    gr_beams_destroy(r->cone);
    r->beams = r->cone = NULL;
    r->beams_pass = -1;
    gr_beam_params bp;
    memset(&bp, 0, sizeof bp);
    bp.water = &r->scene.water;
    bp.origin = r->origin;
    bp.sun_dir = r->Ip;
    bp.ior = r->scene.medium.ior;
    bp.fresnel = r->opt.fresnel;
    bp.shear_x = r->sx;
    bp.shear_z = r->sz;
    bp.region = r->region;
    bp.pad_m = r->pad;
    bp.res = r->set.surface_res;
    bp.interrupt = r->opt.interrupt;
    bp.jitter[0] = jit[0];
    bp.jitter[1] = jit[1];
    bp.max_prims = r->opt.max_prims;
    bp.surface_mesh = 1;
    /* a render's march looks up millions of points per beam set: thinner slabs pay off
     * there (docs/reference.md, "Lookups"); probes keep the cheaper build */
    bp.slab_cells = r->rendering ? 0.5 : 1.0;
    bp.threads = r->threads;
    bp.refine_factor = r->set.refine_factor; /* local refinement (docs/reference.md 2.2) */
    bp.refine_angle = r->set.refine_angle_deg * GR_PI / 180.0;
    bp.camera = &r->scene.camera;
    bp.eye = r->cam;
    if (r->convolve) {
        bp.disc_radius = r->sun_radius;
        bp.disc_e1 = r->e1;
        bp.disc_e2 = r->e2;
    }
    /* the camera cone (docs/reference.md 2.2): the rays within refine_angle of +-T0 stay in
     * cone_box; their set covers it, refined, on the plain grid's lines; the plain grid
     * serves every other ray */
    bp.refine_factor = 1;
    gr_status st = gr_beams_build(r->rtc, &bp, &r->beams, err);
    if (st != GR_OK) return st;
    r->beam_build_s += gr_beams_stats(r->beams)->build_s;
    if (r->cone_on) {
        const gr_beam_stats *bs = gr_beams_stats(r->beams);
        bp.region.u0 = r->cone_box[0];
        bp.region.u1 = r->cone_box[1];
        bp.region.w0 = r->cone_box[2];
        bp.region.w1 = r->cone_box[3];
        bp.refine_factor = r->set.refine_factor;
        bp.cell_m = bs->cell_m;
        bp.anchor_u = bs->grid_u0;
        bp.anchor_w = bs->grid_w0;
        bp.surface_mesh = 1;
        /* slabs of a cell's drift: the cone set's refined cells are many and only the cone's
         * rays look them up (measured: its builds 5.6 s -> 3.8 s of a render, the same bias) */
        bp.slab_cells = 1.0;
        st = gr_beams_build(r->rtc, &bp, &r->cone, err);
        if (st != GR_OK) return st;
        r->beam_build_s += gr_beams_stats(r->cone)->build_s;
    }
    r->beams_pass = pass;
    return GR_OK;
}

/* Sunlight arriving at the local point x: every beam through it under waves, the closed
 * form on flat water (and outside the lit region, where the waves' mean is used). The
 * lists grow as needed (no beam is ever dropped); returns the number of lights in
 * *lights, or -1 when out of memory. */
static int light_at(const gr_ref_renderer *r, const gr_beams *bs, gr_vec3 x, ref_light **lights, int *lcap, gr_beam_hits *hits)
{
    if (*lcap < 1) {
        ref_light *nl = realloc(*lights, 64 * sizeof *nl);
        if (!nl) return -1;
        *lights = nl;
        *lcap = 64;
    }
    if (!r->flat) {
        double u = x.x - r->sx * x.y, w = x.z - r->sz * x.y;
        const gr_beam_region *g = &r->region;
        if (x.y >= g->y_min && u >= g->u0 && u <= g->u1 && w >= g->w0 && w <= g->w1) {
            int n = gr_beams_lookup(bs, x, hits);
            if (n < 0) return -1;
            if (n > *lcap) {
                ref_light *nl = realloc(*lights, (size_t)n * sizeof *nl);
                if (!nl) return -1;
                *lights = nl;
                *lcap = n;
            }
            ref_light *out = *lights;
            int m = 0;
            for (int i = 0; i < n; i++) {
                const gr_beam_hit *h = &hits->h[i];
                if (!(h->T.y < 0.0f)) continue;
                out[m].T = h->T;
                out[m].eperp = h->e_h / -h->T.y; /* horizontal -> perpendicular to T */
                out[m].path = h->path_m;
                m++;
            }
            return m;
        }
    }
    float depth = -x.y;
    if (!(depth > 0.0f)) return 0;
    ref_light *out = *lights;
    out[0].T = r->Tp;
    out[0].eperp = r->flat_eperp;
    out[0].path = depth / r->mu_t;
    return 1;
}

double gr_ref_irradiance_h(const gr_ref_renderer *r, gr_dvec3 world)
{
    gr_beam_hits hits = {NULL, 0, 0};
    ref_light *l = NULL;
    int lcap = 0;
    gr_vec3 x = gr_d3_to_f(gr_d3_sub(world, r->origin));
    int n = light_at(r, r->beams, x, &l, &lcap, &hits);
    double e = n < 0 ? NAN : 0.0; /* out of memory: NaN, never a silently smaller value */
    for (int i = 0; i < n; i++) e += (double)l[i].eperp * -(double)l[i].T.y;
    free(l);
    gr_beam_hits_free(&hits);
    return e;
}

int gr_ref_beam_count(const gr_ref_renderer *r, gr_dvec3 world)
{
    if (r->flat || !r->beams) return 0;
    gr_beam_hits hits = {NULL, 0, 0};
    int n = gr_beams_lookup(r->beams, gr_d3_to_f(gr_d3_sub(world, r->origin)), &hits);
    gr_beam_hits_free(&hits);
    return n;
}

void gr_ref_get_info(const gr_ref_renderer *r, gr_ref_info *info)
{
    memset(info, 0, sizeof *info);
    info->flat = r->flat;
    info->passes_per_round = r->passes_per_round;
    info->spp_per_pass = r->spp_pass;
    info->cutoff_distance_m = r->cutoff_d;
    info->region[0] = r->region.u0; info->region[1] = r->region.u1;
    info->region[2] = r->region.w0; info->region[3] = r->region.w1;
    info->region[4] = r->region.y_min; info->region[5] = r->pad;
    if (r->beams) {
        info->cell_m = gr_beams_stats(r->beams)->cell_m;
        info->prims = gr_beams_stats(r->beams)->prims;
    }
    if (r->cone_on && r->set.surface_res > 0) {
        /* the camera cone's set (prepare_pass): cone_box (half side R) padded, on the plain
         * grid's cells h, those within R + h of P_s split F x F */
        double eu = r->region.u1 - r->region.u0 + 2.0 * r->pad, ew = r->region.w1 - r->region.w0 + 2.0 * r->pad;
        double h = sqrt(eu * ew) / r->set.surface_res, R = 0.5 * (r->cone_box[1] - r->cone_box[0]);
        double side = 2.0 * (R + r->pad) / h + 2.0, F = r->set.refine_factor, disc = GR_PI * (R / h + 1.0) * (R / h + 1.0);
        info->cone_cells = side * side + disc * (F * F - 1.0);
    }
}

/* ---- rendering ---- */

typedef struct ref_accum {
    int W, H, B;
    double *sum;        /* [(pixel * B + batch) * 3 + c] */
    uint32_t *count;    /* [pixel * B + batch] */
    double *aov;        /* [pixel * 2 + {transmittance, ray length}] */
} ref_accum;

typedef struct ref_job {
    gr_ref_renderer *r;
    ref_accum *acc;
    int pass, batch;
    /* accumulator pixel (x, y) is image pixel (x stride + off, y stride + off): stride 1 for
     * the image, a sparse grid for the surface-bias probe */
    int stride, off, img_w;
    int y1;             /* accumulator rows [next_row's start, y1) */
    atomic_int next_row;
    atomic_int rows_done;
    atomic_int stop;
    /* per-thread counters, summed after the pass */
    atomic_llong queries, shadow_rays, max_hits; /* max_hits: the most beams at one point */
} ref_job;

typedef struct ref_counters { long long queries, shadow_rays, max_hits; } ref_counters;

/* Stratum j of n over the pixel: an nx x ny grid of cells (nx the largest divisor of n not
 * above sqrt(n)); the sample is jittered within its cell. */
static void pixel_stratum(int j, int n, ref_rng *g, double *jx, double *jy)
{
    int nx = 1;
    for (int d = 1; d * d <= n; d++)
        if (n % d == 0) nx = d;
    int ny = n / nx, ix = j % nx, iy = j / nx;
    *jx = (ix + rng_u(g)) / nx;
    *jy = (iy + rng_u(g)) / ny;
}

/* Per-thread scratch memory of the march. */
typedef struct ref_scratch {
    gr_beam_hits hits;   /* grow as needed */
    ref_light *lights;
    int lcap;
    double *t;     /* march points along the ray (m) */
    double *w;     /* their weights, with a steps allocation along the ray */
    float *tf;     /* the same in float, as the points are placed */
} ref_scratch;

static void scratch_free(ref_scratch *sc)
{
    gr_beam_hits_free(&sc->hits);
    free(sc->lights);
    free(sc->t);
    free(sc->w);
    free(sc->tf);
}

static int scratch_alloc(ref_scratch *sc, int steps)
{
    memset(sc, 0, sizeof *sc);
    sc->lights = malloc(64 * sizeof *sc->lights);
    sc->lcap = 64;
    sc->t = malloc((size_t)steps * sizeof *sc->t);
    sc->w = malloc((size_t)steps * sizeof *sc->w);
    sc->tf = malloc((size_t)steps * sizeof *sc->tf);
    if (sc->lights && sc->t && sc->w && sc->tf) return 0;
    scratch_free(sc);
    memset(sc, 0, sizeof *sc);
    return -1;
}

/* L (RGB) along the camera ray through the image point (fx, fy) (pixels), marched with n
 * steps (n <= the scratch's). With ck, ck[k] receives the RGB mean of march point k's
 * contribution to L (the step pilot). Returns 0, or -1 when out of memory (a growing hit list). */
/* Where the camera ray (o, d) ends on the set's displaced surface, before De (occluder,
 * seabed, cutoff); past the tessellated patch (or on flat water), the rest plane. */
static float ray_end(const gr_ref_renderer *r, const gr_beams *bs, gr_vec3 o, gr_vec3 d, float De)
{
    unsigned hit = RTC_INVALID_GEOMETRY_ID;
    float D = r->flat ? De : gr_rtc_intersect(gr_beams_surface(bs), o, d, 0.0f, De, &hit, NULL);
    if (hit == RTC_INVALID_GEOMETRY_ID && d.y > 0.0f && -o.y / d.y < D) D = -o.y / d.y;
    return D;
}

static int render_ray(const gr_ref_renderer *r, double fx, double fy, int n, const uint16_t *alloc, ref_rng *g, double L[3],
                      double *trans, double *len, ref_counters *cnt, ref_scratch *sc, double *ck)
{
    const gr_camera *c = &r->scene.camera;
    double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), aspect = (double)c->width / (double)c->height;
    gr_dvec3 dd = cam_dir(r, (2.0 * fx / c->width - 1.0) * tf * aspect, (1.0 - 2.0 * fy / c->height) * tf);
    gr_vec3 d = gr_d3_to_f(dd), o = r->cam;
    L[0] = L[1] = L[2] = 0.0;
    /* where the camera ray ends: occluder or seabed, the water surface, the cutoff */
    float De = gr_rtc_intersect(r->geom->ends, o, d, 0.0f, (float)r->cutoff_d, NULL, NULL), D = -1.0f;
    const gr_beams *bs = r->beams;
    if (r->cone && fabs(dd.x * r->T0.x + dd.y * r->T0.y + dd.z * r->T0.z) >= r->cone_cos) {
        /* within the cone: its refined set, if the whole ray stays where that set is complete
         * (sheared coordinates are linear along the ray: its two ends tell) */
        D = ray_end(r, r->cone, o, d, De);
        /* the part that looks beams up: above the lit region's bottom */
        float De2 = d.y < 0.0f && o.y + d.y * D < (float)r->region.y_min ? ((float)r->region.y_min - o.y) / d.y : D;
        gr_vec3 e = gr_v3_madd(o, d, De2 > 0.0f ? De2 : 0.0f);
        float u0 = o.x - (float)r->sx * o.y, w0 = o.z - (float)r->sz * o.y, u1 = e.x - (float)r->sx * e.y, w1 = e.z - (float)r->sz * e.y;
        const double *cb = r->cone_box;
        if (u0 >= cb[0] && u0 <= cb[1] && u1 >= cb[0] && u1 <= cb[1] && w0 >= cb[2] && w0 <= cb[3] && w1 >= cb[2] && w1 <= cb[3])
            bs = r->cone;
    }
    if (bs == r->beams) D = ray_end(r, r->beams, o, d, De);
    if (!(D > 0.0f)) D = 0.0f;
    *len = D;
    *trans = (exp(-r->sig_t[0] * D) + exp(-r->sig_t[1] * D) + exp(-r->sig_t[2] * D)) / 3.0;
    if (ck)
        for (int k = 0; k < n; k++) ck[k] = 0.0;
    if (D == 0.0f) return 0;
    /* March density ~ exp(-lam t) on [0, D], lam = sig_ref (1 - w_y / mu_t0): the camera
     * ray's extinction times the sunlight's extinction down to the point on flat water, so
     * the flat-water integrand is sampled exactly in proportion (Oracle 1) and the waves
     * only add their caustic modulation. Stratified in the density's CDF, jittered. */
    double lam = r->sig_ref * (1.0 - (double)d.y / -r->T0.y), lD = lam * D, om, wbase;
    if (fabs(lD) > 1e-6) {
        om = -expm1(-lD);
        wbase = om / (lam * n);
    } else {
        lam = 0.0;
        om = 0.0;
        wbase = (double)D / n;
    }
    const gr_hg hg = gr_hg_make(r->scene.medium.g); /* seed eq. 5.5.4 */
    /* segment sg of the CDF range, [sg, sg + 1) / nseg, holds a >= 1 jittered strata; a point
     * there stands for 1 / (nseg a) of the range (the weight wbase n / (nseg a)); n = the sum
     * of alloc (docs/reference.md 2.5). Without an allotment: one segment of n strata, each
     * of weight wbase */
    const int nseg = alloc ? SEGMENTS : 1;
    for (int sg = 0, k = 0; sg < nseg; sg++) {
        int a = alloc ? alloc[sg] : n;
        double ws = alloc ? wbase * n / ((double)SEGMENTS * a) : wbase;
        for (int j = 0; j < a; j++, k++) {
            double u = (sg + (j + rng_u(g)) / a) / nseg;
            sc->t[k] = lam != 0.0 ? -log1p(-u * om) / lam : u * D;
            sc->tf[k] = (float)sc->t[k];
            sc->w[k] = ws;
        }
    }
    for (int k = 0; k < n; k++) {
        double t = sc->t[k];
        gr_vec3 x = gr_v3_madd(o, d, sc->tf[k]);
        int m = light_at(r, bs, x, &sc->lights, &sc->lcap, &sc->hits);
        if (m < 0) return -1;
        cnt->queries++;
        if (m > cnt->max_hits) cnt->max_hits = m;
        int shadow = r->geom->shadow != NULL && m > 0;
        if (shadow) {
            /* the shadow rays' prefilter once for the point's bundle (docs/reference.md 2.3):
             * every ray lies within path |T - Tp| of the one along Tp */
            float lmax = 0.0f, d2max = 0.0f;
            for (int i = 0; i < m; i++) {
                gr_vec3 dt = gr_v3_sub(sc->lights[i].T, r->Tp);
                float d2 = gr_v3_dot(dt, dt);
                lmax = sc->lights[i].path > lmax ? sc->lights[i].path : lmax;
                d2max = d2 > d2max ? d2 : d2max;
            }
            shadow = gr_ref_shadow_near(r->geom, x, gr_v3_scale(r->Tp, -1.0f), lmax, lmax * sqrtf(d2max));
            cnt->shadow_rays += m;
        }
        for (int i = 0; i < m; i++) {
            const ref_light *l = &sc->lights[i];
            if (shadow && gr_ref_shadowed(r->geom, x, gr_v3_scale(l->T, -1.0f), l->path)) continue;
            double ph = gr_hg_eval(hg, -(double)gr_v3_dot(l->T, d));
            double base = ph * l->eperp * sc->w[k];
            for (int ch = 0; ch < 3; ch++) {
                /* sun-to-point and point-to-camera extinction, divided by the march density */
                double ex = r->sig_t[ch] * ((double)l->path + t) - lam * t;
                /* float exp where its range suffices (per-sample work), double below that */
                double tr = ex < 80.0 ? (double)expf((float)-ex) : ex < REF_EXP_LIMIT ? exp(-ex) : 0.0;
                double v = r->sig_s[ch] * r->E[ch] * base * tr;
                L[ch] += v;
                if (ck) ck[k] += v / 3.0;
            }
        }
    }
    return 0;
}

/* One camera sample of pixel (px, py) with n march steps: stratum j of the n_strata camera
 * samples its batch takes in this round, jittered within it. */
static int render_sample(const gr_ref_renderer *r, int px, int py, int j, int n_strata, int n, const uint16_t *alloc,
                         ref_rng *g, double L[3], double *trans, double *len, ref_counters *cnt, ref_scratch *sc)
{
    double jx, jy;
    pixel_stratum(j, n_strata, g, &jx, &jy);
    return render_ray(r, px + jx, py + jy, n, alloc, g, L, trans, len, cnt, sc, NULL);
}

/* Every worker thread: flush denormals, so deep, murky water does not slow down (hard case
 * sigma_t = 20 /m). */
static void flush_denormals(void)
{
#if defined(__SSE2__)
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
}

static void *worker(void *arg)
{
    flush_denormals();
    ref_job *job = arg;
    const gr_ref_renderer *r = job->r;
    ref_accum *acc = job->acc;
    ref_scratch sc;
    ref_counters cnt = {0, 0, 0};
    int oom = 0;
    /* camera samples are stratified over the pixel within a batch (like the passes' strata):
     * this pass is the k-th of its batch in the round */
    int per_batch = r->passes_per_round / r->batches, k_in_batch = (job->pass % r->passes_per_round) / r->batches;
    if (scratch_alloc(&sc, r->set.steps) != 0) {
        atomic_store(&job->stop, 2);
        return NULL;
    }
    for (;;) {
        if (atomic_load(&job->stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        /* a band of MARCH_TILE rows, in tiles of MARCH_TILE x MARCH_TILE pixels: neighbouring
         * rays look up the same beams while they are still in cache (docs/reference.md 2.2,
         * "Lookups"); the pixels' sums do not depend on the order */
        int yb = atomic_fetch_add(&job->next_row, MARCH_TILE);
        if (yb >= job->y1) break;
        int ye = job->y1 - yb < MARCH_TILE ? job->y1 : yb + MARCH_TILE;
        for (int xb = 0; xb < acc->W && !oom; xb += MARCH_TILE)
        for (int y = yb; y < ye && !oom; y++)
        for (int x = xb; x < acc->W && x < xb + MARCH_TILE && !oom; x++) {
            int px = x * job->stride + job->off, py = y * job->stride + job->off;
            size_t pix = (size_t)py * (size_t)job->img_w + (size_t)px; /* the image pixel: its RNG stream */
            size_t ai = (size_t)y * acc->W + x;
            double *sum = acc->sum + (ai * acc->B + job->batch) * 3;
            int n = r->steps_px ? r->steps_px[pix] : r->set.steps; /* the pixel's steps (adaptive: the pilot's) */
            const uint16_t *alloc = r->alloc_px ? r->alloc_px + pix * SEGMENTS : NULL; /* and along its ray */
            /* a probe pixel during the probe's passes: its level-h sums too (one thread per pixel) */
            double *psum = NULL;
            uint32_t *pcnt = NULL;
            const struct ref_accum *pc = r->probe_capture;
            int po = r->probe_capture_off;
            if (pc && px >= po && py >= po && (px - po) % PROBE_STRIDE == 0 && (py - po) % PROBE_STRIDE == 0) {
                size_t qi = (size_t)((py - po) / PROBE_STRIDE) * pc->W + (size_t)((px - po) / PROBE_STRIDE);
                psum = pc->sum + qi * 3;
                pcnt = pc->count + qi;
            }
            for (int s = 0; s < r->spp_pass; s++) {
                /* Ctrl-C within about a second even at thousands of samples per pixel per pass:
                 * a volatile read every 16 samples (the row then stays unfinished: partial) */
                if ((s & 15) == 15 && r->opt.interrupt && *r->opt.interrupt) break;
                uint64_t sample = (uint64_t)job->pass * (uint64_t)r->spp_pass + (uint64_t)s;
                ref_rng g = rng_make(r->set.seed, STREAM_PIXEL0 + pix, sample);
                double L[3], tr, len;
                if (render_sample(r, px, py, k_in_batch * r->spp_pass + s, per_batch * r->spp_pass, n, alloc, &g, L, &tr, &len,
                                  &cnt, &sc) != 0) {
                    oom = 1;
                    break;
                }
                sum[0] += L[0];
                sum[1] += L[1];
                sum[2] += L[2];
                acc->count[ai * acc->B + job->batch]++;
                if (psum) {
                    psum[0] += L[0];
                    psum[1] += L[1];
                    psum[2] += L[2];
                    (*pcnt)++;
                }
                if (acc->aov) {
                    acc->aov[ai * 2] += tr;
                    acc->aov[ai * 2 + 1] += len;
                }
            }
        }
        if (oom) {
            atomic_store(&job->stop, 2); /* out of memory: the pass fails, nothing is dropped */
            break;
        }
        if (r->opt.interrupt && *r->opt.interrupt) break; /* the band may be unfinished: not counted */
        atomic_fetch_add(&job->rows_done, ye - yb);
    }
    atomic_fetch_add(&job->queries, cnt.queries);
    atomic_fetch_add(&job->shadow_rays, cnt.shadow_rays);
    long long mh = atomic_load(&job->max_hits);
    while (cnt.max_hits > mh && !atomic_compare_exchange_weak(&job->max_hits, &mh, cnt.max_hits)) {}
    scratch_free(&sc);
    return NULL;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double percentile(double *v, size_t n, double q)
{
    if (!n) return 0.0;
    qsort(v, n, sizeof *v, cmp_double);
    double pos = q * (double)(n - 1);
    size_t i = (size_t)pos;
    if (i + 1 >= n) return v[n - 1];
    double f = pos - (double)i;
    return v[i] * (1.0 - f) + v[i + 1] * f;
}

static const double *sort_v; /* values that cmp_by_value orders indices by (one caller at a time) */
static int cmp_by_value(const void *a, const void *b)
{
    double x = sort_v[*(const size_t *)a], y = sort_v[*(const size_t *)b];
    return (x > y) - (x < y);
}

typedef struct ref_errors { double rel_mean, rel_p95, frac_1pct, mean, p95; } ref_errors;

/* --target-error E: the relative standard errors come from B batch means, B - 1 degrees of
 * freedom; the target is met when their Student-t 95 % half-widths are within those a
 * known standard error E would give, t_{0.975, B-1} se <= 1.96 E (docs/reference.md). */
static int target_met(const ref_errors *e, int batches, double target)
{
    double k = gr_student_t975(batches - 1) / GR_NORMAL_Q975;
    return k * e->rel_mean < target && k * e->rel_p95 < target;
}

/* Image-level error estimates from the batch images (docs/reference.md, "Error bars"). */
static gr_status image_errors(const ref_accum *acc, ref_errors *e)
{
    size_t np = (size_t)acc->W * acc->H;
    int B = acc->B;
    double *tmp = malloc(np * sizeof *tmp), *Mb = calloc((size_t)B, sizeof *Mb), *Qb = calloc((size_t)B, sizeof *Qb);
    double *v = malloc(np * sizeof *v), *se = malloc(np * sizeof *se);
    if (!tmp || !Mb || !Qb || !v || !se) {
        free(tmp); free(Mb); free(Qb); free(v); free(se);
        return GR_E_NOMEM;
    }
    int nb = 0;
    for (int b = 0; b < B; b++) {
        size_t k = 0;
        double m = 0.0;
        for (size_t p = 0; p < np; p++) {
            uint32_t c = acc->count[p * B + b];
            if (!c) continue;
            const double *s = acc->sum + (p * B + b) * 3;
            tmp[k++] = (s[0] + s[1] + s[2]) / (3.0 * c);
            m += tmp[k - 1];
        }
        if (k < np) continue; /* an unfinished batch (interrupted) does not enter image errors */
        Mb[nb] = m / (double)k;
        nb++;
    }
    double mean = 0.0;
    size_t nr = 0; /* rendered pixels */
    for (size_t p = 0; p < np; p++) {
        double s = 0.0, s2 = 0.0;
        uint32_t n = 0;
        int kb = 0;
        double tot = 0.0;
        for (int b = 0; b < B; b++) {
            uint32_t c = acc->count[p * B + b];
            if (!c) continue;
            const double *sm = acc->sum + (p * B + b) * 3;
            double mb = (sm[0] + sm[1] + sm[2]) / (3.0 * c);
            s += mb;
            s2 += mb * mb;
            kb++;
            n += c;
            tot += sm[0] + sm[1] + sm[2];
        }
        v[p] = n ? tot / (3.0 * n) : 0.0;
        double mm = kb ? s / kb : 0.0;
        se[p] = kb >= 2 ? sqrt(fmax(0.0, (s2 - kb * mm * mm) / (kb - 1)) / kb) : fabs(v[p]);
        if (!n) se[p] = -1.0; /* not rendered (interrupted): no estimate, not "converged" */
        mean += v[p];
        nr += n > 0;
    }
    mean /= (double)(nr ? nr : 1);
    size_t ok = 0;
    for (size_t p = 0; p < np; p++) ok += se[p] >= 0.0 && se[p] <= 0.01 * fmax(v[p], mean);
    e->mean = mean;
    e->frac_1pct = (double)ok / (double)np; /* unrendered pixels count as not within 1 % */
    memcpy(tmp, v, np * sizeof *v);
    e->p95 = percentile(tmp, np, 0.95);
    if (nb >= 2) {
        double a = 0.0, a2 = 0.0;
        for (int b = 0; b < nb; b++) { a += Mb[b]; a2 += Mb[b] * Mb[b]; }
        a /= nb;
        double sdm = sqrt(fmax(0.0, (a2 - nb * a * a) / (nb - 1)) / nb);
        e->rel_mean = mean > 0.0 ? sdm / mean : (sdm > 0.0 ? INFINITY : 0.0);
        /* The 95th-percentile pixel: the pixels ranked within +-1% (at least one) around the
         * 95th percentile of the final image, their RMS standard error over their RMS value.
         * (The spread of the batch images' own percentiles would mix in the upward bias that
         * noise gives an order statistic, and does not shrink like the noise.) */
        size_t *ord = malloc(np * sizeof *ord);
        if (!ord) { free(tmp); free(Mb); free(Qb); free(v); free(se); return GR_E_NOMEM; }
        for (size_t p = 0; p < np; p++) ord[p] = p;
        sort_v = v;
        qsort(ord, np, sizeof *ord, cmp_by_value);
        size_t c = (size_t)(0.95 * (double)(np - 1)), band = np / 100;
        size_t lo = c > band ? c - band : 0, hi = c + band < np ? c + band : np - 1;
        double sv = 0.0, ss = 0.0;
        for (size_t i = lo; i <= hi; i++) { sv += v[ord[i]] * v[ord[i]]; ss += se[ord[i]] * se[ord[i]]; }
        free(ord);
        e->rel_p95 = sv > 0.0 ? sqrt(ss / sv) : (ss > 0.0 ? INFINITY : 0.0);
    } else {
        e->rel_mean = e->rel_p95 = INFINITY;
    }
    free(tmp); free(Mb); free(Qb); free(v); free(se);
    return GR_OK;
}

static float bias_at(const gr_ref_renderer *r, int x, int y, int c);

static gr_status build_image(const gr_ref_renderer *r, const ref_accum *acc, gr_ref_result *out, gr_error *err)
{
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "transmittance", "ray_length"};
    static const char *const names_b[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "bias.R", "bias.G", "bias.B"};
    static const char *const names_ab[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "transmittance", "ray_length",
                                           "bias.R", "bias.G", "bias.B"};
    /* bias.R/G/B (the surface-bias probe's signed estimate of the pixel's 5 x 5 block) come last */
    int bias = r->bias_px != NULL && r->bias_pw > 0 && r->bias_ph > 0;
    int nch = (acc->aov ? 8 : 6) + (bias ? 3 : 0), B = acc->B;
    gr_image *img = gr_image_create(acc->W, acc->H, nch, bias ? (acc->aov ? names_ab : names_b) : names);
    if (!img) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for a %dx%d image", acc->W, acc->H);
    uint32_t min_n = UINT32_MAX;
    for (int y = 0; y < acc->H; y++)
        for (int x = 0; x < acc->W; x++) {
            size_t p = (size_t)y * acc->W + x;
            float *px = gr_image_pixel(img, x, y);
            uint32_t n = 0;
            for (int b = 0; b < B; b++) n += acc->count[p * B + b];
            if (n < min_n) min_n = n;
            for (int c = 0; c < 3; c++) {
                double tot = 0.0, s = 0.0, s2 = 0.0;
                int kb = 0;
                for (int b = 0; b < B; b++) {
                    uint32_t k = acc->count[p * B + b];
                    if (!k) continue;
                    double v = acc->sum[(p * B + b) * 3 + c];
                    tot += v;
                    s += v / k;
                    s2 += (v / k) * (v / k);
                    kb++;
                }
                double mean = n ? tot / n : 0.0, mm = kb ? s / kb : 0.0;
                double se = kb >= 2 ? sqrt(fmax(0.0, (s2 - kb * mm * mm) / (kb - 1)) / kb) : fabs(mean);
                /* nothing non-finite may reach an image */
                px[c] = isfinite(mean) ? (float)mean : 0.0f;
                px[3 + c] = isfinite(se) ? (float)se : 0.0f;
            }
            if (acc->aov) {
                px[6] = n ? (float)(acc->aov[p * 2] / n) : 0.0f;
                px[7] = n ? (float)(acc->aov[p * 2 + 1] / n) : 0.0f;
            }
            if (bias)
                for (int c = 0; c < 3; c++) px[nch - 3 + c] = bias_at(r, x, y, c);
        }
    out->image = img;
    out->spp = min_n == UINT32_MAX ? 0 : (int)min_n;
    return GR_OK;
}

static double finite_or(double v, double alt) { return isfinite(v) ? v : alt; }

static gr_status fill_metadata(const gr_ref_renderer *r, gr_ref_result *out, const ref_errors *e, double qps)
{
    gr_metadata *m = &out->meta;
    gr_status st = GR_OK;
    char key[64], buf[256];
#define SET(call) do { if (st == GR_OK) st = (call); } while (0)
    SET(gr_meta_set_string(m, "godrays:renderer", "reference (Embree ray-marched single scattering, beam prisms)"));
    SET(gr_meta_set_string(m, "godrays:layer", "in-scattered radiance of refracted sunlight (single scattering)"));
    SET(gr_meta_set_string(m, "godrays:scene", r->scene.source_path[0] ? r->scene.source_path : r->scene.name));
    SET(gr_meta_set_string(m, "godrays:scene_hash", r->scene.hash));
    const gr_param_table *t = &gr_reference_param_table;
    for (size_t i = 0; i < t->count; i++) {
        snprintf(key, sizeof key, "godrays:reference.%s", t->params[i].name);
        double v = gr_param_get_number(&t->params[i], &r->set, 0);
        if (t->params[i].type == GR_PT_DOUBLE) SET(gr_meta_set_double(m, key, v));
        else if (t->params[i].type == GR_PT_ENUM && t->params[i].enum_names) /* the name, as in the scene */
            SET(gr_meta_set_string(m, key, t->params[i].enum_names[(int)v]));
        else SET(gr_meta_set_int(m, key, (long long)v));
    }
    SET(gr_meta_set_int(m, "godrays:spp", out->spp));
    SET(gr_meta_set_int(m, "godrays:passes", out->passes));
    SET(gr_meta_set_int(m, "godrays:passes_per_round", r->passes_per_round));
    SET(gr_meta_set_int(m, "godrays:spp_per_pass", r->spp_pass));
    SET(gr_meta_set_int(m, "godrays:partial", out->partial));
    SET(gr_meta_set_int(m, "godrays:flat_water_closed_form", r->flat));
    SET(gr_meta_set_int(m, "godrays:threads", r->threads));
    SET(gr_meta_set_double(m, "godrays:wall_s", out->wall_s));
    SET(gr_meta_set_double(m, "godrays:rel_stderr_mean", finite_or(e->rel_mean, -1.0)));
    SET(gr_meta_set_double(m, "godrays:rel_stderr_p95", finite_or(e->rel_p95, -1.0)));
    SET(gr_meta_set_double(m, "godrays:image_mean", e->mean));
    SET(gr_meta_set_double(m, "godrays:image_p95", e->p95));
    SET(gr_meta_set_double(m, "godrays:frac_pixels_stderr_le_1pct", e->frac_1pct));
    SET(gr_meta_set_double(m, "godrays:cutoff_distance_m", r->cutoff_d));
    SET(gr_meta_set_double(m, "godrays:preview_exposure", out->preview_exposure));
    SET(gr_meta_set_double(m, "godrays:queries_per_s", qps));
    SET(gr_meta_set_double(m, "godrays:beam_build_s", r->beam_build_s));
    snprintf(buf, sizeof buf, "u [%.3f, %.3f] w [%.3f, %.3f] y_min %.3f pad %.3f (local sheared, m)",
             r->region.u0, r->region.u1, r->region.w0, r->region.w1, r->region.y_min, r->pad);
    SET(gr_meta_set_string(m, "godrays:lit_region", buf));
    if (r->have_main_beams) {
        const gr_beam_stats *bs = &r->main_beams;
        SET(gr_meta_set_double(m, "godrays:surface_cell_m", bs->cell_m));
        SET(gr_meta_set_int(m, "godrays:beam_prims", (long long)bs->prims));
        if (bs->refine_factor > 1) { /* local refinement (docs/reference.md 2.2) */
            snprintf(buf, sizeof buf, "camera rays within %g deg of +-T0: factor %d within %.3f m of P_s, %zu cells refined, "
                     "%zu transition cells, %zu triangles; the other rays: the plain grid",
                     r->set.refine_angle_deg, bs->refine_factor, bs->refine_radius_m, bs->refined_cells, bs->transition_cells,
                     bs->triangles);
            SET(gr_meta_set_string(m, "godrays:surface_refine", buf));
        }
    }
    /* bias next to the noise (docs/reference.md section 4): the surface tessellation is the
     * only discretization bias; measured on this scene by the probe (surface_bias_probe) */
    SET(gr_meta_set_double(m, "godrays:bias_surface_rel_est", finite_or(r->bias_rel, -1.0)));
    if (r->bias_rel >= 0.0 && !r->flat) SET(gr_meta_set_double(m, "godrays:bias_surface_order", finite_or(r->bias_order, -1.0)));
    /* the bound: twice the estimate (unit.ref_convergence checks that the estimate is at least
     * half the bias measured against a 2x finer tessellation), or the figure with the measured
     * order where that is larger (cells that do not resolve the waves yet: docs/reference.md) */
    SET(gr_meta_set_double(m, "godrays:bias_surface_rel_bound",
                           r->bias_rel >= 0.0 ? finite_or(r->flat ? 0.0 : fmax(2.0 * r->bias_rel, r->bias_rel_cons), -1.0) : -1.0));
    if (r->bias_rel >= 0.0 && !r->flat)
        SET(gr_meta_set_double(m, "godrays:bias_surface_rel_measured_order", finite_or(r->bias_rel_cons, -1.0)));
    if (r->flat)
        snprintf(buf, sizeof buf, "none: flat water takes the closed form (no tessellation)");
    else if (r->bias_rel >= 0.0)
        snprintf(buf, sizeof buf,
                 "Richardson from %lld pixels (every %dth) x %d passes at surface_res %d, %d and %d: difference ratio "
                 "%.2f, measured order %.2f (clamped to [1, 2]), %.2f s",
                 r->bias_probe_pixels, PROBE_STRIDE, r->bias_probe_passes, r->set.surface_res,
                 r->set.surface_res / 2 > 2 ? r->set.surface_res / 2 : 2, r->set.surface_res / 4 > 2 ? r->set.surface_res / 4 : 2,
                 r->bias_ratio, r->bias_order, r->bias_probe_s);
    else
        snprintf(buf, sizeof buf, "not estimated (reference.bias_probe = false or interrupted); -1");
    SET(gr_meta_set_string(m, "godrays:bias_surface_probe", buf));
    /* per-block bias next to the mean's (bias.R/G/B channels; 10 x 10 pixel blocks) */
    SET(gr_meta_set_double(m, "godrays:bias_block_p95_rel", r->bias_px ? finite_or(r->bias_block_p95, -1.0) : (r->flat ? 0.0 : -1.0)));
    SET(gr_meta_set_int(m, "godrays:stderr_dof", r->batches - 1));
    /* adaptive steps (docs/reference.md 2.5): march steps per camera ray over the pixels, the
     * pilot's steps (0: no pilot, the same steps everywhere) and its share of the wall time */
    SET(gr_meta_set_double(m, "godrays:steps_mean", r->steps_pixels > 0.0 ? r->steps_sum / r->steps_pixels : -1.0));
    SET(gr_meta_set_int(m, "godrays:steps_min", r->steps_min));
    SET(gr_meta_set_int(m, "godrays:steps_max", r->steps_max));
    SET(gr_meta_set_int(m, "godrays:pilot_steps", r->pilot_n0));
    SET(gr_meta_set_double(m, "godrays:pilot_s", r->pilot_s));
    SET(gr_meta_set_double(m, "godrays:pilot_share", out->wall_s > 0.0 ? r->pilot_s / out->wall_s : 0.0));
    SET(gr_meta_set_string(m, "godrays:bias_note",
                           "bias_surface_rel_est = mean |pixel bias| / image mean from the surface tessellation "
                           "(measured here with order 2, see bias_surface_probe; bound = max(2x the estimate, the figure with "
                           "the measured order, bias_surface_rel_measured_order); bias.* channels and bias_block_p95_rel "
                           "use the measured order; march steps: unbiased (jittered strata; per-pixel counts "
                           "from an independent pilot), noise only; sun disc: convolved to first order, error "
                           "below 0.3 % L1 (sun_disc = sample: unbiased); cutoff tail <= transmittance_cutoff * "
                           "S_max / sigma_t (docs/reference.md)"));
    SET(gr_meta_set_string(m, "godrays:error_bars",
                           r->bias_px ? "stderr.* channels: batch-mean spread (noise only; Student t with stderr_dof "
                                        "degrees of freedom); bias.* channels: the surface bias of the pixel's 5x5 block "
                                        "(signed Richardson estimate from the probe; |bias| + t stderr bounds the error)"
                                      : "stderr.* channels: batch-mean spread (noise only; Student t with stderr_dof "
                                        "degrees of freedom); discretization bias: docs/reference.md"));
#undef SET
    return st;
}

typedef struct ref_march_totals { double march_s; long long queries, shadows, max_hits; } ref_march_totals;

/* Marches one pass over the rows [y0, y1) of acc with r->threads workers (thread handles in th),
 * the progress bar going from frac0 to frac0 + span. *complete = 0 when interrupted. */
static gr_status march_pass(gr_ref_renderer *r, ref_accum *acc, int pass, int batch, int stride, int off, int y0,
                            int y1, pthread_t *th, gr_progress *prog, double frac0, double span, const char *note,
                            ref_march_totals *tot, int *complete, gr_error *err)
{
    ref_job job;
    job.r = r;
    job.acc = acc;
    job.pass = pass;
    job.batch = batch;
    job.stride = stride;
    job.off = off;
    job.img_w = r->scene.camera.width;
    job.y1 = y1;
    atomic_init(&job.next_row, y0);
    atomic_init(&job.rows_done, 0);
    atomic_init(&job.stop, 0);
    atomic_init(&job.queries, 0);
    atomic_init(&job.shadow_rays, 0);
    atomic_init(&job.max_hits, 0);
    *complete = 0;
    double tm = mono_s();
    int started = 0;
    for (int i = 0; i < r->threads; i++) {
        if (pthread_create(&th[i], NULL, worker, &job) != 0) break;
        started++;
    }
    if (!started)
        return gr_fail(err, GR_E_RUNTIME, "reference: could not start worker threads (reference.threads = %d)", r->threads);
    for (;;) {
        int done = atomic_load(&job.rows_done);
        gr_progress_update(prog, frac0 + span * (double)done / (y1 - y0), note);
        if (done >= y1 - y0 || atomic_load(&job.stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        /* short sleeps first so tiny renders (tests) do not wait on the poll */
        double waited = mono_s() - tm;
        struct timespec ts = {0, waited < 0.05 ? 500 * 1000 : 20 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    for (int i = 0; i < started; i++) pthread_join(th[i], NULL);
    tot->march_s += mono_s() - tm;
    tot->queries += atomic_load(&job.queries);
    tot->shadows += atomic_load(&job.shadow_rays);
    if (atomic_load(&job.max_hits) > tot->max_hits) tot->max_hits = atomic_load(&job.max_hits);
    if (atomic_load(&job.stop) == 2) return gr_fail(err, GR_E_NOMEM, "reference: out of memory in a worker thread");
    *complete = atomic_load(&job.rows_done) >= y1 - y0;
    return GR_OK;
}

/* ---- adaptive steps: the step pilot (docs/reference.md 2.5, "Adaptive steps") ---- */

typedef struct pilot_job {
    gr_ref_renderer *r;
    int pw, ph;         /* the pilot grid: one ray per PILOT_STRIDE^2 block of pixels */
    int jb0, jb1;       /* pilot rows needed in full (a part's rows and their neighbours) */
    int n0;             /* the pilot's steps (even) */
    double *pl, *pv;    /* per pilot pixel: L (RGB mean), the step-noise variance estimate V */
    double *pvs;        /* per pilot pixel and segment: the part of V from the segment's strata */
    atomic_int next_row, rows_done, stop;
    atomic_llong queries, shadow_rays;
} pilot_job;

/* Pilot rows [jb0, jb1) in full; elsewhere every PILOT_MEAN_STRIDE-th row and column (the
 * image mean). Each pilot pixel's ray is keyed by (seed, STREAM_PILOT, its index), so every
 * part computes the same values. */
static void *pilot_worker(void *arg)
{
    flush_denormals();
    pilot_job *job = arg;
    const gr_ref_renderer *r = job->r;
    const int W = r->scene.camera.width, H = r->scene.camera.height, n0 = job->n0;
    ref_scratch sc;
    ref_counters cnt = {0, 0, 0};
    double *ck = malloc((size_t)n0 * sizeof *ck);
    if (!ck || scratch_alloc(&sc, n0) != 0) {
        free(ck);
        atomic_store(&job->stop, 2);
        return NULL;
    }
    for (;;) {
        if (atomic_load(&job->stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        /* bands of pilot rows in square tiles, as the march's (worker) */
        const int pt = MARCH_TILE / PILOT_STRIDE;
        int jb = atomic_fetch_add(&job->next_row, pt), oom = 0;
        if (jb >= job->ph) break;
        int je = job->ph - jb < pt ? job->ph : jb + pt;
        for (int ib = 0; ib < job->pw && !oom; ib += pt)
        for (int j = jb; j < je && !oom; j++)
        for (int i = ib; i < job->pw && i < ib + pt && !oom; i++) {
            int full = j >= job->jb0 && j < job->jb1;
            if (!full && (j % PILOT_MEAN_STRIDE || i % PILOT_MEAN_STRIDE)) continue;
            size_t q = (size_t)j * job->pw + i;
            ref_rng g = rng_make(r->set.seed, STREAM_PILOT, q);
            /* uniform over the pilot pixel's block of image pixels */
            int bw = W - i * PILOT_STRIDE < PILOT_STRIDE ? W - i * PILOT_STRIDE : PILOT_STRIDE;
            int bh = H - j * PILOT_STRIDE < PILOT_STRIDE ? H - j * PILOT_STRIDE : PILOT_STRIDE;
            double fx = i * PILOT_STRIDE + bw * rng_u(&g), fy = j * PILOT_STRIDE + bh * rng_u(&g);
            double L[3], tr, len;
            if (render_ray(r, fx, fy, n0, NULL, &g, L, &tr, &len, &cnt, &sc, ck) != 0) { oom = 1; break; }
            /* collapsed strata: the strata 2i and 2i + 1 merged into one holding two samples,
             * whose variance (c_2i - c_2i+1)^2 estimates without bias and that of the stratified
             * pair at most (docs/reference.md 2.5) */
            double v = 0.0;
            for (int k = 0; k + 1 < n0; k += 2) v += (ck[k] - ck[k + 1]) * (ck[k] - ck[k + 1]);
            /* per segment (where along the ray the noise is): every stratum's squared differences
             * to both neighbours, halved twice (each difference is counted by two strata, and
             * the expectation of a difference holds two strata's variances), so that a jump
             * between merged pairs is seen as well as one inside a pair */
            double *vs = job->pvs + q * SEGMENTS;
            for (int k = 0; k < n0; k++) {
                double dl = k > 0 ? ck[k] - ck[k - 1] : ck[k] - ck[k + 1], dr = k + 1 < n0 ? ck[k] - ck[k + 1] : dl;
                vs[(size_t)k * SEGMENTS / (size_t)n0] += 0.25 * (dl * dl + dr * dr);
            }
            job->pl[q] = (L[0] + L[1] + L[2]) / 3.0;
            job->pv[q] = v;
        }
        if (oom) { atomic_store(&job->stop, 2); break; }
        if (r->opt.interrupt && *r->opt.interrupt) break;
        atomic_fetch_add(&job->rows_done, je - jb);
    }
    atomic_fetch_add(&job->queries, cnt.queries);
    atomic_fetch_add(&job->shadow_rays, cnt.shadow_rays);
    scratch_free(&sc);
    free(ck);
    return NULL;
}

/* Steps along the ray (docs/reference.md 2.5, "Steps along the ray"). Segment s holds m[s]
 * pilot strata whose step noise was V[s]; with n_s strata its noise is V[s] (m[s] / n_s)^2
 * (the model, alpha = 2), and the least total sum n_s for sum V[s] (m[s] / n_s)^2 <= T is
 * n_s = c (V[s] m[s]^2)^(1/3), c = sqrt(sum (V m^2)^(1/3) / T) (Lagrange). Rounded up, at
 * least one stratum per segment (unbiased), the total clamped to [nmin, nmax]. Returns the
 * total. */
static int allot_segments(const double V[SEGMENTS], const int m[SEGMENTS], double T, int nmin, int nmax, double floor_n,
                          uint16_t n[SEGMENTS])
{
    double x[SEGMENTS], sx = 0.0, sc = 0.0;
    for (int k = 0; k < SEGMENTS; k++) {
        x[k] = V[k] > 0.0 ? cbrt(V[k] * (double)m[k] * (double)m[k]) : 0.0;
        sc += x[k];
    }
    double c = T > 0.0 ? sqrt(sc / T) : 0.0;
    int tot = 0;
    for (int k = 0; k < SEGMENTS; k++) {
        x[k] *= c;
        sx += x[k];
        double v = ceil(fmax(x[k], floor_n * m[k])); /* fmax: NaN gives the floor */
        n[k] = (uint16_t)(v > 1.0 ? (v < 65535.0 ? v : 65535.0) : 1.0);
        tot += n[k];
    }
    if (tot > nmax) {
        /* over the cap: the same proportions within it (at least one each) */
        double f = sx > 0.0 ? (double)(nmax - SEGMENTS) / sx : 0.0; /* the floors sum to at most nmax / 4 */
        tot = 0;
        for (int k = 0; k < SEGMENTS; k++) {
            n[k] = (uint16_t)(1.0 + floor(f * x[k]));
            tot += n[k];
        }
    }
    while (tot < nmin) {
        /* under the floor: one more where the strata are scarcest against x */
        int best = 0;
        for (int k = 1; k < SEGMENTS; k++)
            if ((x[k] + 1e-300) / n[k] > (x[best] + 1e-300) / n[best]) best = k;
        n[best]++;
        tot++;
    }
    return tot;
}

/* The steps of each pixel of the rows [row0, row1) from the pilot (docs/reference.md 2.5):
 * with V and L the means of the pilot's variances and values over the pilot neighbourhood,
 * norm = max(L, pilot image mean), N camera samples per pixel in a round, the
 * step noise V (n0 / n)^alpha / N of the finished pixel is at most (step_error norm)^2 for
 * n = n0 (V / (N step_error^2 norm^2))^(1 / alpha), clamped to [min_steps, steps]. */
static void pilot_steps_map(gr_ref_renderer *r, const pilot_job *job)
{
    const int W = r->scene.camera.width, pw = job->pw, ph = job->ph;
    double msum = 0.0;
    long long mn = 0;
    for (int j = 0; j < ph; j += PILOT_MEAN_STRIDE)
        for (int i = 0; i < pw; i += PILOT_MEAN_STRIDE) {
            msum += job->pl[(size_t)j * pw + i];
            mn++;
        }
    double mean = mn ? msum / (double)mn : 0.0;
    double N = (double)r->passes_per_round * r->spp_pass, tau = r->set.step_error;
    int nmax = r->set.steps, nmin = r->set.min_steps < nmax ? r->set.min_steps : nmax;
    int m[SEGMENTS] = {0}; /* pilot strata per segment (pairs assigned by their first stratum) */
    for (int k = 0; k + 1 < job->n0; k += 2) m[(size_t)k * SEGMENTS / (size_t)job->n0] += 2;
    r->steps_sum = r->steps_pixels = 0.0;
    r->steps_min = INT_MAX;
    r->steps_max = 0;
    for (int py = r->opt.row0; py < r->opt.row1; py++)
        for (int px = 0; px < W; px++) {
            /* the pilot neighbourhood, clamped to the pilot grid: its means of V, L and (with
             * the allotment) the segments' V */
            int i0 = px / PILOT_STRIDE, j0 = py / PILOT_STRIDE;
            int ia = i0 - PILOT_RADIUS > 0 ? i0 - PILOT_RADIUS : 0, ib = i0 + PILOT_RADIUS < pw - 1 ? i0 + PILOT_RADIUS : pw - 1;
            int ja = j0 - PILOT_RADIUS > 0 ? j0 - PILOT_RADIUS : 0, jb = j0 + PILOT_RADIUS < ph - 1 ? j0 + PILOT_RADIUS : ph - 1;
            int nq = (ib - ia + 1) * (jb - ja + 1);
            double vsum = 0.0, lsum = 0.0, V[SEGMENTS] = {0};
            for (int j = ja; j <= jb; j++)
                for (int i = ia; i <= ib; i++) {
                    size_t q = (size_t)j * pw + i;
                    vsum += job->pv[q];
                    lsum += job->pl[q];
                    if (r->alloc_px)
                        for (int k = 0; k < SEGMENTS; k++) V[k] += job->pvs[q * SEGMENTS + (size_t)k];
                }
            double v = vsum / nq, norm = fmax(lsum / nq, mean);
            /* the even spread's steps (its floor below, or the pixel's steps without the allotment) */
            double n = job->n0 * pow(v / (N * tau * tau * norm * norm), 1.0 / PILOT_ALPHA);
            int ni;
            if (r->alloc_px) {
                /* the steps along the ray, segment by segment */
                for (int k = 0; k < SEGMENTS; k++) V[k] /= nq;
                /* the floor: ALLOT_FLOOR of the uniform allocation's steps per pilot stratum (a part
                 * the pilot saw as quiet keeps some strata: its noise is at most 1 / ALLOT_FLOOR^2
                 * times what the uniform march would leave there) */
                double nu = v > 0.0 ? (n < nmax ? n : nmax) : nmin; /* also NaN: the most */
                ni = allot_segments(V, m, N * tau * tau * norm * norm, nmin, nmax, ALLOT_FLOOR * nu / job->n0,
                                    r->alloc_px + ((size_t)py * W + px) * SEGMENTS);
            } else {
                if (v == 0.0) ni = nmin;
                else if (!(n < (double)nmax)) ni = nmax; /* also NaN: the most steps */
                else ni = n > nmin ? (int)ceil(n) : nmin;
            }
            r->steps_px[(size_t)py * W + px] = ni;
            r->steps_sum += ni;
            r->steps_pixels += 1.0;
            if (ni < r->steps_min) r->steps_min = ni;
            if (ni > r->steps_max) r->steps_max = ni;
        }
}

/* Adaptive steps: the pilot rays and the steps map, or r->steps_px = NULL (fixed steps:
 * adaptive_steps off, or steps no more than min_steps). *complete = 0 when interrupted. */
static gr_status step_pilot(gr_ref_renderer *r, pthread_t *th, gr_progress *prog, int *complete, gr_error *err)
{
    const int W = r->scene.camera.width, H = r->scene.camera.height;
    free(r->steps_px);
    r->steps_px = NULL;
    free(r->alloc_px);
    r->alloc_px = NULL;
    r->pilot_n0 = 0;
    r->pilot_s = 0.0;
    r->steps_min = r->steps_max = r->set.steps;
    r->steps_pixels = (double)W * (r->opt.row1 - r->opt.row0);
    r->steps_sum = r->steps_pixels * r->set.steps;
    *complete = 1;
    if (!r->set.adaptive_steps || r->set.steps <= r->set.min_steps) return GR_OK;
    double t0 = mono_s();
    pilot_job job;
    memset(&job, 0, sizeof job);
    job.r = r;
    job.n0 = (r->set.pilot_steps < r->set.steps ? r->set.pilot_steps : r->set.steps) & ~1;
    if (job.n0 < 2) job.n0 = 2;
    job.pw = (W + PILOT_STRIDE - 1) / PILOT_STRIDE;
    job.ph = (H + PILOT_STRIDE - 1) / PILOT_STRIDE;
    job.jb0 = r->opt.row0 / PILOT_STRIDE - PILOT_RADIUS;
    if (job.jb0 < 0) job.jb0 = 0;
    job.jb1 = (r->opt.row1 - 1) / PILOT_STRIDE + PILOT_RADIUS + 1;
    if (job.jb1 > job.ph) job.jb1 = job.ph;
    size_t nq = (size_t)job.pw * job.ph;
    job.pl = calloc(nq, sizeof *job.pl);
    job.pv = calloc(nq, sizeof *job.pv);
    job.pvs = calloc(nq * SEGMENTS, sizeof *job.pvs);
    r->steps_px = calloc((size_t)W * H, sizeof *r->steps_px);
    /* steps along the ray: when every segment can take a stratum within [min_steps, steps]
     * and the pilot has one per segment at least */
    int allot = r->set.steps_along_ray && r->set.min_steps >= SEGMENTS && job.n0 >= 2 * SEGMENTS;
    if (allot) r->alloc_px = calloc((size_t)W * H * SEGMENTS, sizeof *r->alloc_px);
    if (!job.pl || !job.pv || !job.pvs || !r->steps_px || (allot && !r->alloc_px)) {
        free(job.pl); free(job.pv); free(job.pvs);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the step pilot (%dx%d)", W, H);
    }
    gr_status st = gr_ref_prepare_pass(r, PILOT_PASS, err);
    if (st == GR_E_INTERRUPTED) { *complete = 0; st = GR_OK; goto out; }
    if (st != GR_OK) goto out;
    atomic_init(&job.next_row, 0);
    atomic_init(&job.rows_done, 0);
    atomic_init(&job.stop, 0);
    atomic_init(&job.queries, 0);
    atomic_init(&job.shadow_rays, 0);
    int started = 0;
    for (int i = 0; i < r->threads; i++) {
        if (pthread_create(&th[i], NULL, pilot_worker, &job) != 0) break;
        started++;
    }
    if (!started) {
        st = gr_fail(err, GR_E_RUNTIME, "reference: could not start worker threads (reference.threads = %d)", r->threads);
        goto out;
    }
    for (;;) {
        int done = atomic_load(&job.rows_done);
        gr_progress_update(prog, 0.0, "step pilot");
        if (done >= job.ph || atomic_load(&job.stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        double waited = mono_s() - t0;
        struct timespec ts = {0, waited < 0.05 ? 500 * 1000 : 20 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    for (int i = 0; i < started; i++) pthread_join(th[i], NULL);
    if (atomic_load(&job.stop) == 2) {
        st = gr_fail(err, GR_E_NOMEM, "reference: out of memory in a worker thread");
        goto out;
    }
    if (atomic_load(&job.rows_done) < job.ph) { *complete = 0; goto out; } /* interrupted: partial */
    r->pilot_n0 = job.n0;
    pilot_steps_map(r, &job);
out:
    if (st != GR_OK || !*complete) { /* no steps map: nothing is rendered after this */
        free(r->steps_px);
        r->steps_px = NULL;
        free(r->alloc_px);
        r->alloc_px = NULL;
        r->steps_sum = r->steps_pixels = 0.0; /* steps_mean -1: none taken */
        r->steps_min = r->steps_max = 0;
    }
    free(job.pl);
    free(job.pv);
    free(job.pvs);
    r->pilot_s = mono_s() - t0;
    return st;
}

/* Surface-bias probe (docs/reference.md, section 4). Every PROBE_STRIDE-th pixel in x and y
 * is rendered again for the first PROBE_PASSES passes with the beam sets of surface_res
 * (cell h), surface_res / 2 (2h) and surface_res / 4 (4h), from the same random numbers
 * (camera samples, march steps, grid offsets in cells). The tessellation's error is O(h^p),
 * p = 2 once the cells resolve the waves (section 2.2), less before: the order is measured
 * from the three levels, r = mean |L_4h - L_2h| / mean |L_2h - L_h|, p = log2 r clamped to
 * [1, 2] (clamping p at 2 when r > 4 overestimates; noise in the differences flattens r and
 * also overestimates). Richardson then gives the bias at h per pixel as
 * (L_2h - L_h) / (2^p - 1); r->bias_rel = the mean of its absolute value over the probe
 * pixels divided by their mean value: the same figure as the convergence study's table. */
/* The probe's figures from its per-level sums (np probe pixels, [pixel * 3 + c]; level k has
 * cells 2^k h): the estimate (order 2), the figure with the measured order, the order, and
 * the per-pixel signed estimates (bias channels). Shared by gr_ref_render and
 * gr_ref_assemble, so that merged parts give the same bytes. */
static int probe_stats(gr_ref_renderer *r, double *const sum[3], uint32_t *const cnt[3], size_t np, int pw, int ph,
                       int off)
{
    enum { NL = 3 };
    float *bpx = malloc(np * 3 * sizeof *bpx + 1);
    if (!bpx) return -1;
    double d1 = 0.0, d2 = 0.0, v = 0.0;
    for (size_t i = 0; i < np; i++) {
        double l[NL] = {0.0, 0.0, 0.0};
        for (int k = 0; k < NL; k++)
            for (int c = 0; c < 3; c++) l[k] += cnt[k][i] ? sum[k][i * 3 + c] / (3.0 * cnt[k][i]) : 0.0;
        d1 += fabs(l[1] - l[0]);
        d2 += fabs(l[2] - l[1]);
        v += l[0];
    }
    /* the measured order of convergence, clamped to [1, 2] */
    double ratio = d1 > 0.0 ? d2 / d1 : 4.0, order = ratio > 0.0 ? log2(ratio) : 2.0;
    if (!(order <= 2.0)) order = 2.0;
    if (!(order >= 1.0)) order = 1.0;
    double div = pow(2.0, order) - 1.0; /* Richardson: e_h = (L_2h - L_h) / (2^p - 1) */
    for (size_t i = 0; i < np; i++)
        for (int c = 0; c < 3; c++) {
            double lh = cnt[0][i] ? sum[0][i * 3 + c] / cnt[0][i] : 0.0, l2h = cnt[1][i] ? sum[1][i * 3 + c] / cnt[1][i] : 0.0;
            double e = (l2h - lh) / div; /* signed, per channel */
            bpx[i * 3 + c] = isfinite(e) ? (float)e : 0.0f;
        }
    /* the estimate: the asymptotic order 2 (divide by 3); the conservative figure: the
     * measured order (convergence accelerates as h shrinks, so the order measured on the
     * coarser pair is a lower bound of the order at h and the figure an upper one) */
    r->bias_rel = v > 0.0 && isfinite(d1) ? d1 / 3.0 / v : (d1 > 0.0 ? -1.0 : 0.0);
    r->bias_rel_cons = v > 0.0 && isfinite(d1) ? d1 / div / v : (d1 > 0.0 ? -1.0 : 0.0);
    r->bias_ratio = ratio;
    r->bias_order = order;
    r->bias_probe_pixels = (long long)np;
    free(r->bias_px);
    r->bias_px = bpx;
    r->bias_pw = pw;
    r->bias_ph = ph;
    r->bias_poff = off;
    return 0;
}

/* First probe row at or below image row `row` (rows py = y stride + off). */
static int probe_row(int row, int stride, int off, int h)
{
    int y = row <= off ? 0 : (row - off + stride - 1) / stride;
    return y < h ? y : h;
}

/* The probe's pixel grid: its offset in the image and its size. */
static void probe_grid(const gr_ref_renderer *r, int *off, int *pw, int *ph)
{
    int W = r->scene.camera.width, H = r->scene.camera.height;
    *off = W > PROBE_STRIDE / 2 && H > PROBE_STRIDE / 2 ? PROBE_STRIDE / 2 : 0;
    *pw = (W - *off + PROBE_STRIDE - 1) / PROBE_STRIDE;
    *ph = (H - *off + PROBE_STRIDE - 1) / PROBE_STRIDE;
}

static gr_status surface_bias_probe(gr_ref_renderer *r, gr_ref_sums *keep, ref_accum *captured, pthread_t *th,
                                    gr_progress *prog, double frac0, double span, ref_march_totals *tot, gr_error *err)
{
    enum { NL = 3 }; /* levels h, 2h, 4h */
    int off, pw, ph;
    probe_grid(r, &off, &pw, &ph);
    int res = r->set.surface_res, lres[NL];
    for (int k = 0; k < NL; k++) lres[k] = (res >> k) > 2 ? res >> k : 2;
    int passes = r->passes_per_round < PROBE_PASSES ? r->passes_per_round : PROBE_PASSES;
    ref_accum a[NL];
    memset(a, 0, sizeof a);
    for (int k = 0; k < NL; k++) {
        a[k].W = pw;
        a[k].H = ph;
        a[k].B = 1; /* the passes summed: the sums a part file carries (src/farm/parts.h) */
    }
    size_t np = (size_t)a[0].W * a[0].H;
    gr_status st = GR_OK;
    /* level h taken from the main passes when every probe pass ran there (a part whose batches
     * miss some of them renders level h here, as the others) */
    int k0 = 0;
    unsigned want = (1u << passes) - 1u;
    if (captured && captured->sum && (r->probe_captured & want) == want) {
        a[0].sum = captured->sum;
        a[0].count = captured->count;
        captured->sum = NULL;
        captured->count = NULL;
        k0 = 1;
    }
    for (int k = k0; k < NL && st == GR_OK; k++) {
        a[k].sum = calloc(np * 3, sizeof *a[k].sum);
        a[k].count = calloc(np, sizeof *a[k].count);
        if (!a[k].sum || !a[k].count) st = gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
    }
    int complete = 1;
    /* a part probes its own rows' probe pixels */
    int y0 = probe_row(r->opt.row0, PROBE_STRIDE, off, a[0].H), y1 = probe_row(r->opt.row1, PROBE_STRIDE, off, a[0].H);
    for (int p = 0; p < passes && st == GR_OK && complete; p++)
        for (int k = k0; k < NL && st == GR_OK && complete; k++) {
            r->set.surface_res = lres[k];
            r->beams_pass = -1; /* another resolution: rebuild */
            st = gr_ref_prepare_pass(r, p, err);
            if (st == GR_E_INTERRUPTED) { st = GR_OK; complete = 0; break; }
            if (st == GR_OK)
                st = march_pass(r, &a[k], p, 0, PROBE_STRIDE, off, y0, y1, th, prog,
                                frac0 + span * ((NL - k0) * p + k - k0) / ((NL - k0) * (double)passes),
                                span / ((NL - k0) * (double)passes),
                                "surface-bias probe", tot, &complete, err);
        }
    r->set.surface_res = res;
    r->beams_pass = -1;
    if (st == GR_OK && complete) {
        double *sums[NL] = {a[0].sum, a[1].sum, a[2].sum};
        uint32_t *cnts[NL] = {a[0].count, a[1].count, a[2].count};
        if (probe_stats(r, sums, cnts, np, a[0].W, a[0].H, off) != 0)
            st = gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
        r->bias_probe_passes = passes;
        if (st == GR_OK && keep) { /* hand the sums over */
            keep->probe_w = a[0].W;
            keep->probe_h = a[0].H;
            keep->probe_levels = NL;
            for (int k = 0; k < NL; k++) {
                free(keep->probe_sum[k]);
                free(keep->probe_count[k]);
                keep->probe_sum[k] = a[k].sum;
                keep->probe_count[k] = a[k].count;
                a[k].sum = NULL;
                a[k].count = NULL;
            }
            keep->probe = 1;
            keep->probe_stride = PROBE_STRIDE;
            keep->probe_off = off;
            keep->probe_passes = passes;
        }
    }
    for (int k = 0; k < NL; k++) {
        free(a[k].sum);
        free(a[k].count);
    }
    return st;
}

/* The surface-bias estimate of image pixel (x, y), channel c: that of its probe pixel (the
 * PROBE_STRIDE x PROBE_STRIDE block it lies in). */
static float bias_at(const gr_ref_renderer *r, int x, int y, int c)
{
    int i = x / PROBE_STRIDE, j = y / PROBE_STRIDE;
    if (i >= r->bias_pw) i = r->bias_pw - 1;
    if (j >= r->bias_ph) j = r->bias_ph - 1;
    return r->bias_px[((size_t)j * r->bias_pw + (size_t)i) * 3 + c];
}

/* Block bias: over blocks of 2 x 2 probe pixels (10 x 10 image pixels), the mean of the probe
 * pixels' signed estimates (RGB mean) relative to max(block mean, image mean) (the same
 * normalization as the 1 % standard-error figure); the 95th percentile of its magnitude. The
 * probe's residual noise enters the magnitude: an overestimate, not an underestimate. */
static void block_bias(gr_ref_renderer *r, const gr_image *img, double image_mean)
{
    r->bias_block_p95 = -1.0;
    r->bias_blocks = 0;
    if (!r->bias_px || !img) return;
    int bw = (r->bias_pw + 1) / 2, bh = (r->bias_ph + 1) / 2, bs = 2 * PROBE_STRIDE;
    double *v = malloc((size_t)bw * bh * sizeof *v);
    if (!v) return;
    size_t n = 0;
    for (int J = 0; J < bh; J++)
        for (int I = 0; I < bw; I++) {
            double b = 0.0, m = 0.0;
            int nb = 0, nm = 0;
            for (int j = 2 * J; j < 2 * J + 2 && j < r->bias_ph; j++)
                for (int i = 2 * I; i < 2 * I + 2 && i < r->bias_pw; i++, nb++)
                    for (int c = 0; c < 3; c++) b += r->bias_px[((size_t)j * r->bias_pw + (size_t)i) * 3 + c] / 3.0;
            for (int y = J * bs; y < (J + 1) * bs && y < img->height; y++)
                for (int x = I * bs; x < (I + 1) * bs && x < img->width; x++, nm++) {
                    const float *px = gr_image_pixel((gr_image *)img, x, y);
                    m += (px[0] + px[1] + px[2]) / 3.0;
                }
            if (!nb || !nm) continue;
            double den = fmax(m / nm, image_mean);
            if (den > 0.0) v[n++] = fabs(b / nb) / den;
        }
    if (n) {
        r->bias_block_p95 = percentile(v, n, 0.95);
        r->bias_blocks = (int)n;
    }
    free(v);
}

/* The end of a render from its sums: image, error bars, statistics, metadata (shared by
 * gr_ref_render and gr_ref_assemble, so merged parts give the same bytes). */
static gr_status finish_result(gr_ref_renderer *r, const ref_accum *acc, const ref_march_totals *tot, double wall_s,
                               gr_ref_result *out, gr_error *err)
{
    size_t np = (size_t)acc->W * acc->H;
    int P = r->passes_per_round;
    ref_errors e;
    memset(&e, 0, sizeof e);
    gr_status st = GR_OK;
    if (image_errors(acc, &e) != GR_OK) st = gr_fail(err, GR_E_NOMEM, "reference: out of memory");
    if (st == GR_OK) st = build_image(r, acc, out, err);
    if (st != GR_OK) return st;
    block_bias(r, out->image, e.mean);
    out->bias_block_p95 = r->bias_block_p95;
    out->target_met = r->set.target_error > 0.0 ? target_met(&e, acc->B, r->set.target_error) : 1;
    out->wall_s = wall_s;
    out->rel_se_mean = e.rel_mean;
    out->rel_se_p95 = e.rel_p95;
    out->frac_se_1pct = e.frac_1pct;
    out->queries_per_s = tot->march_s > 0.0 ? (double)tot->queries / tot->march_s : 0.0;
    out->shadow_rays_per_s = tot->march_s > 0.0 ? (double)tot->shadows / tot->march_s : 0.0;
    out->beam_build_s = r->beam_build_s;
    out->bias_surface_rel = r->bias_rel;
    out->steps_mean = r->steps_pixels > 0.0 ? r->steps_sum / r->steps_pixels : -1.0;
    out->rounds = P > 0 ? (out->passes + P - 1) / P : 0;
    out->max_rounds = r->set.target_error > 0.0 ? r->opt.max_rounds : 1;
    /* preview: the 99th percentile of the brightest channel maps to 0.8 */
    double *v = malloc(np * sizeof *v);
    out->preview_exposure = 1.0;
    if (v) {
        for (size_t p = 0; p < np; p++) {
            const float *px = out->image->pixels + p * out->image->nchannels;
            v[p] = fmax(px[0], fmax(px[1], px[2]));
        }
        double p99 = percentile(v, np, 0.99);
        if (p99 > 0.0 && isfinite(p99)) out->preview_exposure = 0.8 / p99;
        free(v);
    }
    if (fill_metadata(r, out, &e, out->queries_per_s) != GR_OK)
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for metadata");
    gr_meta_set_double(&out->meta, "godrays:shadow_rays_per_s", out->shadow_rays_per_s);
    /* the most beams at one march point (the list grows; -1: not carried through parts) */
    gr_meta_set_int(&out->meta, "godrays:beam_max_hits", tot->max_hits);
    return GR_OK;
}

gr_ref_sums *gr_ref_sums_create(int W, int H, int B, int probe_levels, int probe_w, int probe_h)
{
    gr_ref_sums *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    size_t np = (size_t)W * H, nq = (size_t)probe_w * probe_h;
    s->W = W;
    s->H = H;
    s->B = B;
    s->sum = calloc(np * B * 3 + 1, sizeof *s->sum);
    s->count = calloc(np * B + 1, sizeof *s->count);
    int ok = s->sum && s->count;
    if (probe_levels > GR_REF_PROBE_MAX_LEVELS) ok = 0;
    if (nq && probe_levels > 0 && ok) {
        s->probe_w = probe_w;
        s->probe_h = probe_h;
        s->probe_levels = probe_levels;
        for (int k = 0; k < probe_levels; k++) {
            s->probe_sum[k] = calloc(nq * 3, sizeof *s->probe_sum[k]);
            s->probe_count[k] = calloc(nq, sizeof *s->probe_count[k]);
            ok = ok && s->probe_sum[k] && s->probe_count[k];
        }
    }
    if (!ok) {
        gr_ref_sums_destroy(s);
        return NULL;
    }
    return s;
}

void gr_ref_sums_destroy(gr_ref_sums *s)
{
    if (!s) return;
    free(s->sum);
    free(s->count);
    for (int k = 0; k < GR_REF_PROBE_MAX_LEVELS; k++) {
        free(s->probe_sum[k]);
        free(s->probe_count[k]);
    }
    free(s);
}

gr_status gr_ref_render(gr_ref_renderer *r, gr_ref_result *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    gr_meta_init(&out->meta);
    double t0 = mono_s();
    ref_accum acc;
    acc.W = r->scene.camera.width;
    acc.H = r->scene.camera.height;
    acc.B = r->batches;
    size_t np = (size_t)acc.W * acc.H;
    acc.sum = calloc(np * acc.B * 3, sizeof *acc.sum);
    acc.count = calloc(np * acc.B, sizeof *acc.count);
    acc.aov = r->opt.aovs ? calloc(np * 2, sizeof *acc.aov) : NULL;
    gr_progress *prog = gr_progress_create("reference", r->opt.progress);
    pthread_t *th = calloc((size_t)r->threads, sizeof *th);
    gr_ref_sums *keep = r->opt.keep_sums ? calloc(1, sizeof *keep) : NULL;
    if (!acc.sum || !acc.count || (r->opt.aovs && !acc.aov) || !prog || !th || (r->opt.keep_sums && !keep)) {
        free(acc.sum); free(acc.count); free(acc.aov); free(th); free(keep); gr_progress_destroy(prog);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %dx%d pixels x %d batches", acc.W, acc.H, acc.B);
    }
    int P = r->passes_per_round;
    int rounds = r->set.target_error > 0.0 ? r->opt.max_rounds : 1;
    gr_status st = GR_OK;
    ref_errors e;
    memset(&e, 0, sizeof e);
    int pass = 0;
    r->rendering = 1;
    int probe = r->set.bias_probe && !r->flat && r->opt.batch0 == 0; /* a part: the one with batch 0 */
    double mainw = probe ? 0.95 : 1.0; /* share of the progress bar for the main passes */
    ref_march_totals tot = {0.0, 0, 0, 0};
    /* the probe's level h, taken during the main passes 0 .. PROBE_PASSES - 1 */
    ref_accum cap;
    memset(&cap, 0, sizeof cap);
    r->probe_captured = 0;
    if (probe) {
        int poff;
        probe_grid(r, &poff, &cap.W, &cap.H);
        cap.B = 1;
        cap.sum = calloc((size_t)cap.W * cap.H * 3, sizeof *cap.sum);
        cap.count = calloc((size_t)cap.W * cap.H, sizeof *cap.count);
        r->probe_capture_off = poff;
        if (!cap.sum || !cap.count) { /* the probe then renders level h itself */
            free(cap.sum); free(cap.count);
            cap.sum = NULL; cap.count = NULL;
        }
    }
    /* adaptive steps: the pilot sets every pixel's steps before the first pass */
    int pilot_done = 1;
    st = step_pilot(r, th, prog, &pilot_done, err);
    if (st == GR_OK && !pilot_done) out->partial = 1;
    for (int round = 0; round < rounds && st == GR_OK && !out->partial; round++) {
        for (int pp = 0; pp < P && st == GR_OK; pp++, pass++) {
            if (pass % acc.B < r->opt.batch0 || pass % acc.B >= r->opt.batch1) continue; /* another part's batch */
            if (r->opt.interrupt && *r->opt.interrupt) { out->partial = 1; break; }
            st = gr_ref_prepare_pass(r, pass, err);
            if (st == GR_E_INTERRUPTED) { st = GR_OK; out->partial = 1; break; }
            if (st != GR_OK) break;
            char note[64];
            snprintf(note, sizeof note, "pass %d/%d%s", pp + 1, P, rounds > 1 ? " (refining)" : "");
            int complete = 0;
            /* the probe's passes: the first min(P, PROBE_PASSES) (surface_bias_probe) */
            r->probe_capture = cap.sum && pass < (P < PROBE_PASSES ? P : PROBE_PASSES) ? &cap : NULL;
            st = march_pass(r, &acc, pass, pass % acc.B, 1, 0, r->opt.row0, r->opt.row1, th, prog,
                            mainw * (rounds > 1 ? pp : pass) / P, mainw / P, note, &tot, &complete, err);
            if (r->probe_capture && st == GR_OK && complete) r->probe_captured |= 1u << pass;
            r->probe_capture = NULL;
            if (st != GR_OK) break;
            if (!complete) { out->partial = 1; break; }
            out->passes++;
        }
        if (st != GR_OK || out->partial) break;
        if (rounds > 1) {
            if (image_errors(&acc, &e) != GR_OK) { st = gr_fail(err, GR_E_NOMEM, "reference: out of memory"); break; }
            if (target_met(&e, acc.B, r->set.target_error)) break;
        }
    }
    /* the tessellation's bias, measured on this scene (flat water has none: closed form) */
    r->bias_rel = r->flat ? 0.0 : -1.0;
    r->have_main_beams = r->beams != NULL;
    if (r->beams) r->main_beams = *gr_beams_stats(r->beams);
    if (r->cone) { /* the refinement is the camera cone's set's (docs/reference.md 2.2) */
        const gr_beam_stats *cs = gr_beams_stats(r->cone);
        r->main_beams.refine_factor = cs->refine_factor;
        r->main_beams.refine_radius_m = cs->refine_radius_m;
        r->main_beams.refined_cells = cs->refined_cells;
        r->main_beams.transition_cells = cs->transition_cells;
        r->main_beams.triangles = cs->triangles;
    }
    ref_march_totals ptot = {0.0, 0, 0, 0};
    if (st == GR_OK && probe && !out->partial) {
        double tp = mono_s();
        st = surface_bias_probe(r, keep, &cap, th, prog, mainw, 1.0 - mainw, &ptot, err);
        r->bias_probe_s = mono_s() - tp;
    }
    r->rendering = 0;
    gr_progress_finish(prog);
    gr_progress_destroy(prog);
    free(th);
    if (st == GR_OK && (r->flat || out->partial || !probe)) { free(r->bias_px); r->bias_px = NULL; }
    if (st == GR_OK) st = finish_result(r, &acc, &tot, mono_s() - t0, out, err);
    if (st == GR_OK && keep) { /* the raw sums for a part file (src/farm/parts.h) */
        keep->W = acc.W;
        keep->H = acc.H;
        keep->B = acc.B;
        keep->sum = acc.sum;
        keep->count = acc.count;
        acc.sum = NULL;
        acc.count = NULL;
        keep->passes = out->passes;
        keep->probe_s = r->bias_probe_s;
        keep->beam_cell_m = r->have_main_beams ? r->main_beams.cell_m : 0.0;
        keep->beam_prims = r->have_main_beams ? (long long)r->main_beams.prims : 0;
        if (r->have_main_beams) {
            keep->beam_refine_factor = r->main_beams.refine_factor;
            keep->beam_refine_radius_m = r->main_beams.refine_radius_m;
            keep->beam_refined_cells = (long long)r->main_beams.refined_cells;
            keep->beam_transition_cells = (long long)r->main_beams.transition_cells;
            keep->beam_triangles = (long long)r->main_beams.triangles;
        }
        keep->beam_build_s = r->beam_build_s;
        keep->march_s = tot.march_s;
        keep->queries = tot.queries;
        keep->shadows = tot.shadows;
        keep->overflows = 0; /* nothing overflows: the hit list grows */
        keep->steps_sum = r->steps_sum;
        keep->steps_pixels = r->steps_pixels;
        keep->steps_min = r->steps_min;
        keep->steps_max = r->steps_max;
        keep->pilot_steps = r->pilot_n0;
        keep->pilot_s = r->pilot_s;
        out->sums = keep;
        keep = NULL;
    }
    gr_ref_sums_destroy(keep);
    free(cap.sum);
    free(cap.count);
    free(acc.sum);
    free(acc.count);
    free(acc.aov);
    if (st != GR_OK) gr_ref_result_free(out);
    return st;
}

gr_status gr_ref_assemble(gr_ref_renderer *r, const gr_ref_sums *sums, double wall_s, gr_ref_result *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    gr_meta_init(&out->meta);
    if (sums->W != r->scene.camera.width || sums->H != r->scene.camera.height || sums->B != r->batches)
        return gr_fail(err, GR_E_INPUT, "reference: sums of %dx%d pixels x %d batches for a %dx%d render with %d batches",
                       sums->W, sums->H, sums->B, r->scene.camera.width, r->scene.camera.height, r->batches);
    ref_accum acc = {sums->W, sums->H, sums->B, sums->sum, sums->count, NULL};
    r->bias_rel = r->flat ? 0.0 : -1.0;
    free(r->bias_px);
    r->bias_px = NULL;
    if (sums->probe && sums->probe_levels != 3)
        return gr_fail(err, GR_E_INPUT, "reference: sums with %d probe levels; this integrator's probe has 3",
                       sums->probe_levels);
    if (sums->probe && !r->flat) {
        int off = r->scene.camera.width > PROBE_STRIDE / 2 && r->scene.camera.height > PROBE_STRIDE / 2 ? PROBE_STRIDE / 2 : 0;
        if (probe_stats(r, sums->probe_sum, sums->probe_count, (size_t)sums->probe_w * sums->probe_h, sums->probe_w,
                        sums->probe_h, off) != 0)
            return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
        r->bias_probe_passes = sums->probe_passes;
        r->bias_probe_s = sums->probe_s;
    }
    r->have_main_beams = sums->beam_prims > 0;
    memset(&r->main_beams, 0, sizeof r->main_beams);
    r->main_beams.cell_m = sums->beam_cell_m;
    r->main_beams.prims = (size_t)sums->beam_prims;
    r->main_beams.refine_factor = sums->beam_refine_factor;
    r->main_beams.refine_radius_m = sums->beam_refine_radius_m;
    r->main_beams.refined_cells = (size_t)sums->beam_refined_cells;
    r->main_beams.transition_cells = (size_t)sums->beam_transition_cells;
    r->main_beams.triangles = (size_t)sums->beam_triangles;
    r->beam_build_s = sums->beam_build_s;
    r->steps_sum = sums->steps_sum;
    r->steps_pixels = sums->steps_pixels;
    r->steps_min = sums->steps_min;
    r->steps_max = sums->steps_max;
    r->pilot_n0 = sums->pilot_steps;
    r->pilot_s = sums->pilot_s;
    out->passes = sums->passes;
    ref_march_totals tot = {sums->march_s, sums->queries, sums->shadows, -1};
    gr_status st = finish_result(r, &acc, &tot, wall_s, out, err);
    if (st != GR_OK) gr_ref_result_free(out);
    return st;
}

void gr_ref_result_free(gr_ref_result *res)
{
    if (!res) return;
    gr_image_destroy(res->image);
    res->image = NULL;
    gr_ref_sums_destroy(res->sums);
    res->sums = NULL;
    gr_meta_free(&res->meta);
}

void *gr_ref_surface_scene_ptr(const gr_ref_renderer *r) { return r->beams ? (void *)gr_beams_surface(r->beams) : NULL; }

long long gr_ref_surface_triangles(const gr_ref_renderer *r)
{
    return r->beams ? (long long)gr_beams_stats(r->beams)->triangles : 0;
}

double gr_ref_lookup_rate(const gr_ref_renderer *r, const double box[6], int n)
{
    if (r->flat || !r->beams || n < 1) return 0.0;
    gr_beam_hits hits = {NULL, 0, 0};
    gr_rng g = gr_rng_make(42, 2, 0);
    long long found = 0;
    double t0 = mono_s();
    for (int i = 0; i < n; i++) {
        double y = box[4] + (box[5] - box[4]) * gr_rng_double(&g);
        double u = box[0] + (box[1] - box[0]) * gr_rng_double(&g), w = box[2] + (box[3] - box[2]) * gr_rng_double(&g);
        gr_vec3 p = gr_v3((float)(u + r->sx * y), (float)y, (float)(w + r->sz * y));
        found += gr_beams_lookup(r->beams, p, &hits);
    }
    double dt = mono_s() - t0;
    gr_beam_hits_free(&hits);
    (void)found;
    return dt > 0.0 ? n / dt : 0.0;
}
