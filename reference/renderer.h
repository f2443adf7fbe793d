/* The renderer's state, shared by the integrator's parts (internal to reference/): the
 * public API in reference/integrator.h (integrator.c: setup, passes, the render's course),
 * the march (march.h), the worker threads (pool.h), the step pilot (pilot.h), the
 * surface-bias probe (probe.h), the image and its statistics (stats.h), the raw sums
 * (sums.h). Code map: docs/reference.md. */
#ifndef GR_REF_RENDERER_H
#define GR_REF_RENDERER_H

#include <limits.h>
#include <stdint.h>
#include "core/rng.h"
#include "core/vec.h"
#include "reference/beams.h"
#include "reference/embree_scene.h"
#include "reference/integrator.h"
#include "reference/phase.h"
#include "reference/pool.h"

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
/* at most this many camera rays share one camera sample's march (reference.camera_rays) */
enum { REF_MAX_RAYS = 16 };
#define ALLOT_FLOOR 0.25
/* the march's unit of work: bands of MARCH_TILE rows, walked in square tiles (worker; the
 * pilot's of MARCH_TILE / PILOT_STRIDE pilot pixels: the same image area) */
#define MARCH_TILE 16
/* the surface-bias probe's pixel grid and passes (gr_ref_probe_run, reference/probe.c) */
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
    /* Refinement near the camera (docs/reference.md 2.2, "Near the camera"): the set `near`
     * covers near_box (sheared u0 u1 w0 w1) on the plain grid's lines, its cells within near_D
     * (m, sheared) of P_s split near_F x near_F (1: none, near NULL); every march point of a
     * ray on the plain set that lies in near_box looks it up instead. near_cpw: the plain
     * grid's cells across the shortest wave, near_lambda (m) */
    gr_beams *near;
    int near_F;
    /* the near set's statistics as the last gr_ref_prepare_pass built it (the bias probe's
     * fourth level replaces `near` by a finer set afterwards: gr_ref_near_fine) */
    gr_beam_stats near_stats;
    int near_stats_valid;     /* 1: near_stats describe the last pass's near set */
    double near_D, near_cpw, near_lambda, near_box[4];
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
    /* the slabs' thickness (render_slab_cells): the plain set's primitives at half a cell of
     * drift (sampled by gr_ref_sample_sets or when the render starts; 0: not yet), and the lookups the march of the next set to be
     * built will ask (set before each gr_ref_prepare_pass inside a render; 0: unknown) */
    double slab_prims, lookups_next;
    double cutoff_d;          /* D_cut of rays that do not rise (w_y <= 0); gr_ref_cutoff_d */
    double cutoff_ln;         /* -ln(transmittance_cutoff) (0: no cutoff) */
    double mu_min;            /* the least |T_y| of any refracted sunlight (waves, disc) */
    gr_beam_region region;
    double pad;
    int passes_per_round, spp_pass, batches, threads;
    int camera_rays;          /* rays per camera sample in the main passes (1..REF_MAX_RAYS) */
    double sig_t[3], sig_s[3], E[3];
    double sig_ref;           /* min_c sigma_t: the march's importance density */
    /* current pass */
    gr_dvec3 Ip;
    gr_vec3 Tp;
    float flat_eperp;         /* F_t cos(theta_i) / cos(theta_t): Oracle 1's E_w / E_sun */
    float mu_t;
    /* surface-bias probe: mean |bias| / mean (-1 = not estimated), its cost and size */
    double bias_rel;
    double bias_ratio, bias_order; /* the probe's |L_4h - L_2h| / |L_2h - L_h| and the order p used */
    double bias_rel_cons;     /* the same with the measured order (conservative) */
    int have_main_beams;      /* 1: tally.beam_* describe the main passes' last beam set */
    long long bias_probe_pixels;
    int bias_probe_passes;
    /* While the main passes 0 .. PROBE_PASSES - 1 run: the probe's level-h accumulator (NULL
     * otherwise). A probe pixel's level-h value is exactly the main pass's (the same beam set,
     * steps and random numbers), so it is taken there instead of building the beam set again;
     * probe_captured has bit p set once pass p was taken (gr_ref_probe_run, reference/probe.c) */
    struct ref_accum *probe_capture;
    int probe_capture_off;
    unsigned probe_captured;
    /* the same for the probe's fourth level (the near cells 2x finer): bit p once pass p's probe
     * pixels were marched with gr_ref_near_fine's set (gr_ref_render) */
    unsigned probe_captured_fine;
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
    /* The render's tallies (no arrays): times, counters, the main passes' last beam set, the
     * steps' statistics and the pilot (tally.pilot_steps 0: no pilot), the probe's time. What
     * a part file carries besides the arrays (gr_ref_sums_copy_tallies), and what the
     * statistics read (reference/stats.h), from a render or from merged parts alike */
    gr_ref_sums tally;
    /* per-phase wall, CPU and serial time of the render (reference/phase.h; on while
     * gr_ref_render runs, and then read by the statistics) */
    gr_ref_phases phases;
};

/* Per pixel (of the image or of the probe's grid) and batch: RGB sums, counts, the AOVs. */
typedef struct ref_accum {
    int W, H, B;
    double *sum;        /* [(pixel * B + batch) * 3 + c] */
    uint32_t *count;    /* [pixel * B + batch] */
    double *aov;        /* [pixel * 2 + {transmittance, ray length}] */
} ref_accum;

/* Pass `pass` feeds batch pass mod B and is the k-th (returned) of the *per_batch passes that
 * batch takes in a round (docs/reference.md 2.6): the index of its strata (sun directions,
 * camera samples) and of its antithetic pair. */
static inline int pass_in_batch(const gr_ref_renderer *r, int pass, int *per_batch)
{
    *per_batch = r->passes_per_round / r->batches;
    return (pass % r->passes_per_round) / r->batches;
}

/* Antithetic pairs (reference.antithetic; docs/reference.md 2.5): the pairs each batch holds
 * in a round, the passes k = 2m and 2m + 1 of the batch for m < the count (an odd pass count
 * leaves the last alone); 0 when off. */
static inline int antithetic_pairs(const gr_ref_renderer *r)
{
    return r->set.antithetic ? r->passes_per_round / r->batches / 2 : 0;
}

/* 1 when pass `pass` is the second of an antithetic pair (the pilot's pass never is) */
static inline int pass_antithetic(const gr_ref_renderer *r, int pass)
{
    int per_batch, k = pass_in_batch(r, pass, &per_batch);
    return pass != PILOT_PASS && (k & 1) && k < 2 * antithetic_pairs(r);
}

/* The pass whose random numbers pass `pass` draws: its pair's first (B passes before it, in
 * the same batch and round) when it is a pair's second, else itself. */
static inline int pass_stream(const gr_ref_renderer *r, int pass)
{
    return pass - pass_antithetic(r, pass) * r->batches;
}

/* Where a camera ray of direction w (unit, w_y its upward part) stops at the latest
 * (docs/reference.md 1, "Camera ray ends and the cutoff"): on flat water the integrand falls
 * as exp(-sigma_t k t), k = 1 - w_y / mu_t (Oracle 1), so D_cut = -ln(cutoff) / (sigma_min k)
 * drops at most the cutoff's fraction of each channel; with waves mu_t >= mu_min bounds k
 * from below. A ray that rises at least as steeply as the sunlight sinks (k <= 0) sees an
 * integrand that does not fall: no cutoff but max_distance_m. */
static inline double gr_ref_cutoff_d(const gr_ref_renderer *r, double wy)
{
    if (!(wy > 0.0) || !(r->cutoff_ln > 0.0) || !(r->sig_ref > 0.0)) return r->cutoff_d;
    double k = 1.0 - wy / r->mu_min, dmax = r->scene.reference.max_distance_m;
    return k > 0.0 && r->cutoff_ln < k * r->sig_ref * dmax ? r->cutoff_ln / (k * r->sig_ref) : dmax;
}

static inline gr_dvec3 cam_dir(const gr_ref_renderer *r, double ndx, double ndy)
{
    const gr_camera *c = &r->scene.camera;
    gr_dvec3 f = gr_d3(c->forward[0], c->forward[1], c->forward[2]);
    gr_dvec3 rt = gr_d3(c->right[0], c->right[1], c->right[2]);
    gr_dvec3 up = gr_d3(c->up[0], c->up[1], c->up[2]);
    return gr_d3_norm(gr_d3_madd(gr_d3_madd(f, rt, ndx), up, ndy));
}

#endif
