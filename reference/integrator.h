/* The ground truth: ray-marched single scattering of refracted sunlight (the god-ray layer),
 * with its own error bars. Derivation and method: docs/reference.md.
 *
 *   L(w) = int_0^D exp(-sigma_t t) sigma_s SUM_k p(T_k . -w) E_k(x(t)) dt
 *
 * Camera rays end at an occluder, the seabed, the water surface seen from below, or where
 * the camera ray's transmittance falls below reference.transmittance_cutoff. E_k comes
 * from beam prisms (reference/beams.h) under waves and from the closed form on flat water.
 * The sun's disc is averaged analytically (reference.sun_disc = "convolve": each beam's
 * footprint convolved with the disc's image, reference/beams.h) or sampled, one direction
 * per pass ("sample"). Each pass has its own jitter of the surface grid; pass p feeds
 * batch p mod batches, and the spread of the batch means gives the per-pixel standard
 * error. */
#ifndef GR_REF_INTEGRATOR_H
#define GR_REF_INTEGRATOR_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include "common/status.h"
#include "core/vec.h"
#include "image/image.h"
#include "reference/sums.h"
#include "scene/scene.h"

typedef struct gr_ref_options {
    int fresnel;            /* 1 (default): exact Fresnel transmittance; 0: F_t = 1 */
    int force_beams;        /* 1: use beam prisms even on flat water (tests the beam path) */
    int aovs;               /* 1: add "transmittance" and "ray_length" channels */
    int progress;           /* 1: progress bar on stderr (only if a tty and > 2 s) */
    volatile sig_atomic_t *interrupt; /* set nonzero (e.g. by SIGINT) to stop at the next row */
    size_t max_prims;       /* beam-slab primitive budget; 0 = default (16 M, about 1 GB) */
    int max_rounds;         /* --target-error: at most this many rounds of passes; 0 = 64 */
    int fixed_grid;         /* 1: every pass uses the grid offset (0.5, 0.5) cells (tests: the
                               sun-disc treatments then differ only in the disc) */
    /* Lit region override for irradiance probes (tests): world x/z bounds at depths down to
     * y_min. Unused when lit_box_valid = 0 (the region then follows the camera frustum). */
    int lit_box_valid;
    double lit_box[5];      /* x0, x1, z0, z1, y_min (world) */
    int full_column;        /* 1: beams' slabs up to the surface even where no ray rises so
                               high (the check of the region's top: docs/reference.md 2.2) */
    /* A part of the work (godrays farm, docs/farm.md): image rows [row0, row1) and batches
     * [batch0, batch1) only; both 0, 0 = all. Passes of other batches are skipped, the pixel
     * and pass random numbers stay keyed as in a full render, so a part's sums are the same
     * bytes as those pixels' and batches' sums in a full render. The surface-bias probe runs
     * (on its pixels in these rows) only in the part that holds batch 0. */
    int row0, row1, batch0, batch1;
    int keep_sums;          /* 1: gr_ref_result.sums holds the raw per-batch sums (parts) */
} gr_ref_options;

void gr_ref_options_default(gr_ref_options *o);

typedef struct gr_ref_renderer gr_ref_renderer;

gr_status gr_ref_create(const gr_scene *s, const gr_ref_options *o, gr_ref_renderer **out, gr_error *err);
void gr_ref_destroy(gr_ref_renderer *r); /* accepts NULL */

/* The raw sums a render's image, error bars and statistics are computed from (gr_ref_sums)
 * and the table of their fields: reference/sums.h. */

typedef struct gr_ref_result {
    gr_image *image;        /* R, G, B, stderr.R, stderr.G, stderr.B [, transmittance, ray_length]
                               [, bias.R, bias.G, bias.B] (with the surface-bias probe) */
    gr_metadata meta;       /* "godrays:*" keys: settings, samples, errors, timings */
    int partial;            /* 1 if interrupted: fewer samples than asked */
    int spp;                /* camera samples per pixel actually taken (pixels done last) */
    int passes;             /* passes (sun directions) completed */
    double wall_s;
    double rel_se_mean;     /* relative standard error of the image mean (mean of RGB) */
    double rel_se_p95;      /* relative standard error of the 95th-percentile pixel value */
    double frac_se_1pct;    /* fraction of pixels whose standard error <= 1% of max(pixel, mean) */
    double block8_rel_se_max; /* 8x8 blocks: the largest standard error of a block mean over max(block
                               mean, image mean), worst channel (-1: none) */
    double preview_exposure;/* exposure that maps the 99th percentile to 0.8 in the preview */
    double queries_per_s;   /* beam lookups (or closed-form evaluations) per second, all threads */
    double shadow_rays_per_s;
    double beam_build_s;    /* total time spent building beam sets */
    int rounds, max_rounds; /* rounds of passes done; the cap that --target-error refines up to */
    double bias_surface_rel;/* surface-tessellation bias: mean |pixel bias| / image mean,
                               measured by the probe (0 on flat water, -1 if not estimated) */
    double bias_block_p95;  /* 95th percentile over 10x10-pixel blocks of |block bias| / max(block
                               mean, image mean) (-1 if not estimated) */
    double steps_mean;      /* march steps per camera ray, mean over the pixels (adaptive steps) */
    double steps_capped_frac;   /* adaptive steps: the pixels whose pilot asked for more than reference.steps */
    double steps_wanted_capped; /* the steps those asked for, on average (0: none) */
    int target_met;         /* --target-error: 1 when met (Student t, batches - 1 dof); 1 if off */
    gr_ref_sums *sums;      /* with gr_ref_options.keep_sums: the raw sums (freed with the result) */
    /* Per phase (beams, grid, pilot, march, probe, stats, other: GR_REF_PHASES, the metadata's
     * godrays:phase.NAME.*): wall, CPU (all threads) and serial time (wall with at most one
     * thread busy); serial_frac = their serial sum over their wall sum. phases 0: not measured
     * (assembled parts) */
    int phases;
    double phase_wall_s[7], phase_cpu_s[7], phase_serial_s[7], serial_frac;
} gr_ref_result;
#define GR_REF_PHASES 7
extern const char *const gr_ref_phase_names[GR_REF_PHASES];

/* Renders the image; `progress_label` may be NULL. On interruption returns GR_OK with
 * out->partial = 1 (the caller writes what is there). */
gr_status gr_ref_render(gr_ref_renderer *r, gr_ref_result *out, gr_error *err);
void gr_ref_result_free(gr_ref_result *res); /* accepts NULL */
/* The result of a render from its full sums (every row and batch, e.g. merged parts): the
 * same code as the end of gr_ref_render, so pixels, error channels and statistics are the
 * bytes a single render writes. Needs r's scene and settings (no pass is rendered);
 * wall_s is the caller's. Timings and counters come from the sums. */
gr_status gr_ref_assemble(gr_ref_renderer *r, const gr_ref_sums *sums, double wall_s, gr_ref_result *out, gr_error *err);

/* ---- probes for the oracles and the second estimator ---- */
/* Builds the beam set of pass `pass` (sun direction and grid jitter of that pass). */
gr_status gr_ref_prepare_pass(gr_ref_renderer *r, int pass, gr_error *err);
/* The bias probe's fourth level (reference/probe.c): after gr_ref_prepare_pass(pass), replaces
 * the near set by one with factor F on the same plain grid and jitter (the old one freed first;
 * the next gr_ref_prepare_pass builds the pass's sets again). */
gr_status gr_ref_near_fine(gr_ref_renderer *r, int pass, int F, gr_error *err);
/* Sun direction I of a pass (unit, world): the disc's centre when the disc is convolved. */
gr_dvec3 gr_ref_pass_sun_dir(const gr_ref_renderer *r, int pass);
/* Horizontal irradiance per unit sun irradiance at a world point for the prepared pass,
 * from every beam through it: SUM_k F_t |I.a_k| / |A_k(y)|, no extinction, no shadows.
 * On flat water without force_beams: the closed form F_t cos(theta_i). Points outside the
 * lit region return the flat-water value too. */
double gr_ref_irradiance_h(const gr_ref_renderer *r, gr_dvec3 world);
/* Number of beams through the point (0 outside the lit region or on flat water). */
int gr_ref_beam_count(const gr_ref_renderer *r, gr_dvec3 world);
/* Surface patch, cell size, lit region and D_cut, for reports and tests. */
typedef struct gr_ref_info {
    int flat;               /* 1: closed-form sunlight, no beams */
    int passes_per_round;   /* sun directions per round (sun_samples rounded up to batches) */
    int spp_per_pass;
    double cutoff_distance_m;
    double region[6];       /* sheared u0, u1, w0, w1, y_min (local), pad_m */
    double y_top;           /* the region's top (local; INFINITY: the whole column) */
    double cell_m;          /* surface cell size of the last beam set (0 before one is built) */
    size_t prims;           /* beam-slab primitives of the last beam set */
    double cone_cells;      /* estimated surface cells of the camera cone's beam set, its
                               refined sub-cells included (0: none; docs/reference.md 2.2) */
    int near_factor;        /* refinement near the camera (docs/reference.md 2.2): the factor (1: none), */
    double near_radius_m;   /* its radius around P_s (sheared, m), */
    double near_cells;      /* estimated surface cells of its beam set, the refined sub-cells included */
    double probe_near_cells; /* the same for the bias probe's fourth level (its cells 2x finer), 0: none */
    /* expected beam-slab primitives of pass 0's sets and their lookup-grid entries per
     * primitive (gr_ref_sample_sets; 0: not sampled, or no such set): the plain set, the
     * camera cone's, the near set, the probe's finer one */
    double plain_prims, cone_prims, near_prims, probe_near_prims;
    double plain_entries, cone_entries, near_entries, probe_near_entries;
    double cells_per_wave;  /* the plain grid's cells across the shortest wave (0: flat water) */
} gr_ref_info;
void gr_ref_get_info(const gr_ref_renderer *r, gr_ref_info *info);
/* Fills info's primitives and entries (info from gr_ref_get_info): pass 0's sets sampled
 * without building them (gr_beams_sample_prims, gr_beams_entries_per_prim), for the memory
 * estimate (reference/memory.h). 9-15 ms, so kept out of gr_ref_get_info; the renderer keeps
 * the plain set's count for its slabs' choice (gr_ref_render would sample it otherwise). */
void gr_ref_sample_sets(gr_ref_renderer *r, gr_ref_info *info);
/* For the benchmark (reference/bench.c): the displaced surface mesh of the prepared pass
 * (NULL on flat water), its triangle count, and the rate of bare beam lookups (1 thread)
 * at random local points of box = {u0, u1, w0, w1, y0, y1}. */
void *gr_ref_surface_scene_ptr(const gr_ref_renderer *r);
long long gr_ref_surface_triangles(const gr_ref_renderer *r);
double gr_ref_lookup_rate(const gr_ref_renderer *r, const double box[6], int n);

#endif
