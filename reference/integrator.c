#include "reference/integrator.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/gerstner.h"
#include "core/optics.h"
#include "reference/beam_grid.h"
#include "reference/march.h"
#include "reference/pilot.h"
#include "reference/probe.h"
#include "reference/progress.h"
#include "reference/renderer.h"
#include "reference/stats.h"

/* The renderer's course: setup (gr_ref_create), a pass's sunlight and beam sets
 * (gr_ref_prepare_pass), the render (the pilot, the rounds of passes, the probe) and the
 * result from sums (gr_ref_assemble). The march, the pilot, the probe and the statistics
 * live in their own files (reference/renderer.h lists them). */

void gr_ref_options_default(gr_ref_options *o)
{
    memset(o, 0, sizeof *o);
    o->fresnel = 1;
    o->progress = 1;
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

static void grow(double b[4], double u, double w)
{
    if (u < b[0]) b[0] = u;
    if (u > b[1]) b[1] = u;
    if (w < b[2]) b[2] = w;
    if (w > b[3]) b[3] = w;
}

/* Over every refracted sunlight direction T the waves and the sun's disc allow (normals
 * tilted up to the waves' largest slope, tan = Q / sqrt(1 - Q^2) with Q = sum a_i k_i, where
 * the Gerstner slope sin / (1 - Q cos) peaks at cos = Q, plus the disc's angular radius;
 * facets that face away from the sun are unlit and refract nothing), scanned over 64
 * azimuths x 8 tilts:
 * - *drift: the largest drift |T_xz / T_y - T0_xz / T0_y| per metre of height (INFINITY once
 *   a T is within 1e-3 of level), for the rest patch's margin;
 * - *mu: the least |T_y| (T0's on flat water under a point sun), less 1 % for the scan's
 *   azimuth step (5.6 deg: it misses the least value by a second-order amount), which
 *   bounds the integrand's fall along rising camera rays (gr_ref_cutoff_d). */
static void refraction_range(const gr_ref_renderer *r, double *drift, double *mu)
{
    double Q = gr_gerstner_steepness(&r->scene.water);
    if (Q >= 0.999) Q = 0.999;
    double tilt = atan(Q / sqrt(1.0 - Q * Q)) + r->sun_radius, best = 0.0, least = -r->T0.y;
    for (int ia = 0; ia < 64 && tilt > 0.0; ia++) {
        double az = 2.0 * GR_PI * ia / 64.0;
        for (int it = 1; it <= 8; it++) {
            double a = tilt * it / 8.0;
            gr_dvec3 n = gr_d3(sin(a) * sin(az), cos(a), sin(a) * cos(az));
            if (gr_d3_dot(r->I0, n) >= 0.0) continue;
            gr_dvec3 T = gr_refract_d(r->I0, n, 1.0 / r->scene.medium.ior);
            if (-T.y < least) least = -T.y;
            if (!(T.y < -1e-3)) {
                best = INFINITY;
                continue;
            }
            double du = T.x / T.y - r->sx, dw = T.z / T.y - r->sz;
            double d = sqrt(du * du + dw * dw);
            if (d > best) best = d;
        }
    }
    *drift = best;
    *mu = tilt > 0.0 ? 0.99 * least : least;
}

/* The plain grid's cell at surface_res res: the lit region with its pad over res (as
 * gr_beams_build); 0 when the region is empty or res < 1. */
static double plain_cell(const gr_ref_renderer *r, int res)
{
    double eu = r->region.u1 - r->region.u0 + 2.0 * r->pad, ew = r->region.w1 - r->region.w0 + 2.0 * r->pad;
    return eu > 0.0 && ew > 0.0 && res >= 1 ? sqrt(eu * ew) / res : 0.0;
}

/* The square of half side R around P_s, the camera's sheared position (u0 u1 w0 w1). */
static void box_around_ps(const gr_ref_renderer *r, double R, double box[4])
{
    double pu = r->cam.x - r->sx * r->cam.y, pw = r->cam.z - r->sz * r->cam.y;
    box[0] = pu - R; box[1] = pu + R;
    box[2] = pw - R; box[3] = pw + R;
}

/* The estimated surface cells of a set over box on the plain grid's cells (prepare_pass): the
 * box padded, those within disc_r + h of P_s split F x F. */
static double set_cells(const gr_ref_renderer *r, const double box[4], double disc_r, int F, double *plain, double *fine)
{
    double h = plain_cell(r, r->set.surface_res), R = 0.5 * (box[1] - box[0]);
    *plain = *fine = 0.0;
    if (!(h > 0.0)) return 0.0;
    double side = 2.0 * (R + r->pad) / h + 2.0, disc = GR_PI * (disc_r / h + 1.0) * (disc_r / h + 1.0);
    disc = fmin(disc, side * side);
    *plain = side * side - disc; /* the cells left whole */
    *fine = disc * (double)F * F; /* the refined cells' sub-cells */
    return *plain + *fine;
}

/* The expected beam primitives of a set (the memory estimate) and their lookup-grid entries
 * per primitive: its whole cells' and its sub-cells' two triangles each, sampled (beams.h). */
static double set_prims(const gr_beam_params *bp, double plain, double fine, int F, double slab_cells, double *entries)
{
    enum { SAMPLES = 32 }; /* 1024 cells: the counts to about 2 % (unit.ref_memory) */
    gr_beam_params q = *bp;
    q.slab_cells = slab_cells;
    gr_beam_prim_sample s[2];
    gr_beams_sample_prims(&q, 1, SAMPLES, &s[0]);
    memset(&s[1], 0, sizeof s[1]);
    if (fine > 0.0) gr_beams_sample_prims(&q, F, SAMPLES, &s[1]);
    /* each class's primitives in the set per sampled one: its triangles over the sampled ones */
    double w[2] = {s[0].tris > 0.0 ? 2.0 * plain / s[0].tris : 0.0, s[1].tris > 0.0 ? 2.0 * fine / s[1].tris : 0.0};
    *entries = gr_beams_entries_per_prim(s, w, 2);
    return w[0] * s[0].prims + w[1] * s[1].prims;
}

/* Refinement near the camera (docs/reference.md 2.2, "Near the camera"): when the plain grid
 * (surface_res cells across the lit region) has fewer than near_cells_per_wavelength cells
 * across the shortest wave, the cells within near_radius_cells of them around P_s are split
 * by the smallest odd factor that brings them to it (at most near_max_factor). Computed once
 * from the full surface_res: the probe's coarser levels keep the same factor and disc in
 * metres. */
static void near_refinement(gr_ref_renderer *r)
{
    const gr_reference_settings *st = &r->scene.reference;
    r->near_F = 1;
    r->near_D = r->near_cpw = r->near_lambda = 0.0;
    double lam = INFINITY;
    for (int i = 0; i < r->scene.water.n_waves; i++)
        if (r->scene.water.waves[i].amplitude_m != 0.0) lam = fmin(lam, r->scene.water.waves[i].wavelength_m);
    double h = plain_cell(r, st->surface_res);
    if (r->flat || !isfinite(lam) || !(h > 0.0)) return;
    r->near_lambda = lam;
    r->near_cpw = lam / h;
    if (!(st->near_cells_per_wavelength > 0.0)) return;
    /* the smallest odd factor that brings the cells to the target (odd: half a plain cell is
     * then half a fine one too, the antithetic passes' shift, docs/reference.md 2.5), at most
     * near_max_factor's odd part; a finer plain grid never gets coarser cells near the camera */
    double ratio = st->near_cells_per_wavelength / r->near_cpw;
    int cap = st->near_max_factor % 2 ? st->near_max_factor : st->near_max_factor - 1;
    if (!(ratio > 1.0) || cap <= 1) return;
    int F = ratio >= cap ? cap : (int)ceil(ratio);
    if (F % 2 == 0) F++;
    if (F > cap) F = cap;
    r->near_F = F;
    r->near_D = st->near_radius_cells * h;
    /* the set covers the disc and the waves' horizontal displacement around P_s */
    box_around_ps(r, r->near_D + wave_amplitude_sum(&r->scene.water), r->near_box);
}

/* The largest w_y of any camera ray: straight up where the frustum holds it, else the
 * largest on the image's border (w_y over the image plane has no other local maximum: its
 * only one on the directions in front of the camera is the one nearest +y), sampled 4096
 * times an edge, plus 1e-4 for the samples' spacing. */
static double frustum_max_wy(const gr_ref_renderer *r, double ta, double tf)
{
    const gr_camera *c = &r->scene.camera;
    double z = c->forward[1], x = c->right[1], y = c->up[1];
    if (z > 0.0 && fabs(x) <= ta * z && fabs(y) <= tf * z) return 1.0;
    enum { NE = 4096 };
    double best = -1.0;
    for (int e = 0; e < 4; e++)
        for (int i = 0; i <= NE; i++) {
            double s = 2.0 * i / NE - 1.0;
            double a = e < 2 ? s * ta : (e == 2 ? -ta : ta), b = e < 2 ? (e == 0 ? -tf : tf) : s * tf;
            best = fmax(best, cam_dir(r, a, b).y);
        }
    return fmin(1.0, best + 1e-4);
}

/* The lit region: sheared bounds of the visible volume (camera frustum up to each ray's
 * end), clamped to reference.patch_radius_m around the camera. */
static void compute_region(gr_ref_renderer *r)
{
    double drift;
    refraction_range(r, &drift, &r->mu_min);
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
                double D = gr_ref_cutoff_d(r, d.y);
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
    /* the region's top (docs/reference.md 2.2, "The region's top"): a ray rising at w_y ends
     * by w_y D(w_y), which grows with w_y (gr_ref_cutoff_d), so the steepest ray's end is the
     * highest point any lookup asks for; 5 cm and 1 % of the column above it. With a lit box
     * (the irradiance probes of tests), or where the steepest ray reaches the crests, none. */
    r->region.has_top = 0;
    r->region.y_top = A;
    if (!r->opt.lit_box_valid && !r->opt.full_column) {
        const gr_camera *c = &s->camera;
        double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), ta = tf * (double)c->width / (double)c->height;
        double wy = frustum_max_wy(r, ta, tf), top = o.y;
        if (wy > 0.0) top += wy * gr_ref_cutoff_d(r, wy);
        top = fmax(top, o.y) + 0.05 + 0.01 * (top - ymin);
        if (top < A) {
            r->region.has_top = 1;
            r->region.y_top = top;
        }
    }
    double mu = 0.02 * fmax(b[1] - b[0], b[3] - b[2]) + 0.1;
    r->region.u0 = b[0] - mu; r->region.u1 = b[1] + mu;
    r->region.w0 = b[2] - mu; r->region.w1 = b[3] + mu;
    r->region.y_min = ymin;
    /* rest patch margin: horizontal Gerstner displacement plus the largest drift of a beam
     * over the region's depth (rays enter the region from outside it) */
    double pad = A + fabs(ymin) * drift + 0.25;
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
    r->camera_rays = st->camera_rays < 1 ? 1 : st->camera_rays > REF_MAX_RAYS ? REF_MAX_RAYS : st->camera_rays;
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
    /* camera rays that do not rise stop where the transmittance of the least attenuated
     * channel falls below the cutoff, rising ones later (gr_ref_cutoff_d), and all at
     * reference.max_distance_m at the latest */
    r->cutoff_d = st->max_distance_m;
    r->cutoff_ln = st->transmittance_cutoff > 0.0 && st->transmittance_cutoff < 1.0 ? -log(st->transmittance_cutoff) : 0.0;
    if (smin > 0.0 && r->cutoff_ln > 0.0) r->cutoff_d = fmin(r->cutoff_d, r->cutoff_ln / smin);
    compute_region(r);
    near_refinement(r);
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
            r->cone_on = 1;
            box_around_ps(r, rho + wave_amplitude_sum(&s->water), r->cone_box);
            r->cone_cos = cos(bp.refine_angle);
            /* the near set covers the cone's disc at least as finely: no cone set, its rays'
             * points look up the near set (march.c) */
            if (r->near_F >= st->refine_factor && r->near_D >= rho) r->cone_on = 0;
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
    gr_beams_destroy(r->near);
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
    int per_batch, k = pass_in_batch(r, pass, &per_batch);
    double u = (k + rng_u(&g)) / per_batch;
    double phi = 2.0 * GR_PI * rng_u(&g);
    double cr = 1.0 - u * (1.0 - cos(r->sun_radius)), sr = sqrt(fmax(0.0, 1.0 - cr * cr));
    gr_dvec3 off = gr_d3_madd(gr_d3_scale(r->e1, cos(phi)), r->e2, sin(phi));
    return gr_d3_norm(gr_d3_madd(gr_d3_scale(r->I0, cr), off, sr));
}

/* A beam set's build in the phases: its parallel time, and its lookup grid's part moved
 * from the beams' phase to the grid's (the switch after the builds charges the whole span) */
static void account_build(gr_ref_renderer *r, const gr_beams *b)
{
    const gr_beam_stats *bs = gr_beams_stats(b);
    r->phases.par_total += bs->par_s;
    gr_ref_phases_move(&r->phases, REF_PH_BEAMS, REF_PH_GRID, bs->index_s, bs->index_cpu_s, bs->index_par_s);
}

static void *destroy_job(void *arg)
{
    gr_beams_destroy(*(gr_beams **)arg);
    return NULL;
}

static gr_status build_set(gr_ref_renderer *r, const gr_beam_params *bp, gr_beams **out, gr_error *err)
{
    gr_status st = gr_beams_build(r->rtc, bp, out, err);
    if (st == GR_OK) {
        account_build(r, *out);
        r->tally.beam_build_s += gr_beams_stats(*out)->build_s;
    }
    return st;
}

/* A set over box (sheared u0 u1 w0 w1) on the plain set's grid lines (the camera cone's, the
 * one near the camera: docs/reference.md 2.2), its cells near P_s split F x F (within radius
 * m; 0: the cone's own radius); bp holds the pass's parameters and is changed. */
static gr_status build_on_plain_lines(gr_ref_renderer *r, gr_beam_params *bp, const double box[4], int F, double radius,
                                      double slab_cells, gr_beams **out, gr_error *err)
{
    const gr_beam_stats *bs = gr_beams_stats(r->beams);
    bp->region.u0 = box[0];
    bp->region.u1 = box[1];
    bp->region.w0 = box[2];
    bp->region.w1 = box[3];
    bp->refine_factor = F;
    bp->refine_radius_m = radius;
    bp->cell_m = bs->cell_m;
    bp->anchor_u = bs->grid_u0;
    bp->anchor_w = bs->grid_w0;
    bp->surface_mesh = 1;
    bp->slab_cells = slab_cells;
    return build_set(r, bp, out, err);
}

/* The slabs of a render's plain and near sets, in cells of drift (docs/reference.md 2.2,
 * "Slab thickness"): half a cell (tight boxes, fewer candidates per lookup) where the march
 * looks the set up more than SLAB_THIN_RHO times per primitive, one cell above SLAB_MID_RHO,
 * else two (fewer primitives to build, sort and grid). Slabs change the boxes, never the
 * hits: the pixels are the same bytes for any choice. Outside a render (the tests' probes):
 * one cell. */
enum { SLAB_THIN_RHO_X10 = 23, SLAB_MID_RHO_X10 = 6 };
static double slab_cells_for(double lookups, double prims)
{
    if (!(lookups > 0.0) || !(prims > 0.0)) return 0.5;
    double rho = lookups / prims;
    return rho >= SLAB_THIN_RHO_X10 / 10.0 ? 0.5 : rho >= SLAB_MID_RHO_X10 / 10.0 ? 1.0 : 2.0;
}
static double render_slab_cells(const gr_ref_renderer *r)
{
    return r->rendering ? slab_cells_for(r->lookups_next, r->slab_prims) : 1.0;
}

/* The beam parameters of pass `pass` for its plain set (r->Ip: the pass's sun direction,
 * set by gr_ref_prepare_pass). The grid's offset: the pass's own; with reference.antithetic,
 * the (2m + 1)-th pass of a batch in a round takes the (2m)-th's moved by half a cell in both
 * directions (a batch then holds antithetic pairs, the batches stay independent:
 * docs/reference.md 2.5) */
static void pass_params(const gr_ref_renderer *r, int pass, gr_beam_params *bp)
{
    int half = pass_antithetic(r, pass);
    ref_rng g = rng_make(r->set.seed, STREAM_PASS, (uint64_t)pass_stream(r, pass));
    (void)rng_u(&g);
    (void)rng_u(&g);
    double jit[2] = {rng_u(&g), rng_u(&g)};
    if (half) {
        jit[0] = jit[0] < 0.5 ? jit[0] + 0.5 : jit[0] - 0.5;
        jit[1] = jit[1] < 0.5 ? jit[1] + 0.5 : jit[1] - 0.5;
    }
    if (r->opt.fixed_grid) jit[0] = jit[1] = 0.5;
    memset(bp, 0, sizeof *bp);
    bp->water = &r->scene.water;
    bp->origin = r->origin;
    bp->sun_dir = r->Ip;
    bp->ior = r->scene.medium.ior;
    bp->fresnel = r->opt.fresnel;
    bp->shear_x = r->sx;
    bp->shear_z = r->sz;
    bp->region = r->region;
    bp->pad_m = r->pad;
    bp->res = r->set.surface_res;
    bp->interrupt = r->opt.interrupt;
    bp->jitter[0] = jit[0];
    bp->jitter[1] = jit[1];
    bp->max_prims = r->opt.max_prims;
    bp->surface_mesh = 1;
    /* thinner slabs where the march looks the set up many times per primitive (docs/reference.md
     * 2.2, "Lookups" and "Slab thickness") */
    bp->slab_cells = render_slab_cells(r);
    bp->threads = r->threads;
    bp->refine_angle = r->set.refine_angle_deg * GR_PI / 180.0;
    bp->camera = &r->scene.camera;
    bp->eye = r->cam;
    if (r->convolve) {
        bp->disc_radius = r->sun_radius;
        bp->disc_e1 = r->e1;
        bp->disc_e2 = r->e2;
    }
    /* the camera cone (docs/reference.md 2.2): the rays within refine_angle of +-T0 stay in
     * cone_box; their set covers it, refined, on the plain grid's lines; the plain grid
     * serves every other ray */
    bp->refine_factor = 1;
}

gr_status gr_ref_prepare_pass(gr_ref_renderer *r, int pass, gr_error *err)
{
    r->Ip = gr_ref_pass_sun_dir(r, pass);
    /* Oracle 1: flat refraction, E_w / E_sun = F_t cos(theta_i) / cos(theta_t) */
    gr_dvec3 T = gr_refract_d(r->Ip, gr_d3(0, 1, 0), 1.0 / r->scene.medium.ior);
    double cos_i = -r->Ip.y;
    double ft = r->opt.fresnel ? 1.0 - gr_fresnel_exact(cos_i, 1.0, r->scene.medium.ior) : 1.0;
    r->Tp = gr_d3_to_f(T);
    r->mu_t = (float)(-T.y);
    r->flat_eperp = (float)(ft * cos_i / -T.y);
    if (r->flat || r->beams_pass == pass) return GR_OK;
    /* the last pass's sets freed side by side (their pages go back: issue 30's serial part) */
    gr_beams *old[3] = {r->beams, r->cone, r->near};
    int nold = 0;
    for (int i = 0; i < 3; i++)
        if (old[i]) old[nold++] = old[i];
    if (nold > 1 && r->threads > 1)
        r->phases.par_total += gr_beams_run_jobs(destroy_job, old, sizeof old[0], nold);
    else
        for (int i = 0; i < nold; i++) gr_beams_destroy(old[i]);
    r->beams = r->cone = r->near = NULL;
    r->beams_pass = -1;
    r->near_stats_valid = 0;
    gr_beam_params bp;
    pass_params(r, pass, &bp);
    int prev = gr_ref_phases_switch(&r->phases, REF_PH_BEAMS);
    gr_status st = build_set(r, &bp, &r->beams, err);
    /* the cone's set: twice the plain set's slabs, one or two cells of drift (its refined
     * cells are many and only the cone's rays look them up: at one cell its builds 5.6 s ->
     * 3.8 s of a 640 x 360 render, the same bias; two cost the same there and less below
     * it, docs/reference.md 2.2, "Slab thickness"); the near set's as the plain set's
     * (measured: 1.0 and 2.0 cost more there) */
    if (r->cone_on && st == GR_OK) {
        double cone_slabs = r->rendering ? fmin(2.0, 2.0 * bp.slab_cells) : 1.0;
        st = build_on_plain_lines(r, &bp, r->cone_box, r->set.refine_factor, 0.0, cone_slabs, &r->cone, err);
    }
    if (r->near_F > 1 && st == GR_OK) {
        st = build_on_plain_lines(r, &bp, r->near_box, r->near_F, r->near_D, render_slab_cells(r), &r->near, err);
        if (st == GR_OK && r->near) {
            r->near_stats = *gr_beams_stats(r->near);
            r->near_stats_valid = 1;
        }
    }
    gr_ref_phases_switch(&r->phases, prev);
    if (st != GR_OK) return st;
    r->beams_pass = pass;
    return GR_OK;
}

gr_status gr_ref_near_fine(gr_ref_renderer *r, int pass, int F, gr_error *err)
{
    if (r->flat || !r->beams || r->beams_pass != pass || r->near_F <= 1)
        return gr_fail(err, GR_E_RUNTIME, "reference: the finer near set needs pass %d's sets (internal)", pass);
    /* one near set at a time (the memory estimate counts the larger) */
    gr_beams_destroy(r->near);
    r->near = NULL;
    r->beams_pass = -1; /* the next prepare_pass builds this pass's sets again */
    gr_beam_params bp;
    pass_params(r, pass, &bp);
    int prev = gr_ref_phases_switch(&r->phases, REF_PH_BEAMS);
    /* only the probe's sparse pixels look it up: thicker slabs, a cheaper build (measured on
     * the level view at 160x90: grid fill 19.2 -> 10.0 CPU-s from 0.5 to 2 cells, the same
     * bytes) */
    gr_status st = build_on_plain_lines(r, &bp, r->near_box, F, r->near_D, 2.0, &r->near, err);
    gr_ref_phases_switch(&r->phases, prev);
    return st;
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
    info->y_top = r->region.has_top ? r->region.y_top : INFINITY;
    if (r->beams) {
        info->cell_m = gr_beams_stats(r->beams)->cell_m;
        info->prims = gr_beams_stats(r->beams)->prims;
    }
    info->near_factor = r->near_F;
    info->near_radius_m = r->near_D;
    info->cells_per_wave = r->near_cpw;
    double plain, fine;
    /* the near set's and the camera cone's (prepare_pass) */
    if (r->near_F > 1) info->near_cells = set_cells(r, r->near_box, r->near_D, r->near_F, &plain, &fine);
    /* the probe's fourth level: the plain set with the near cells 2x finer (probe.c) */
    if (r->near_F > 1 && r->set.bias_probe && !r->flat && gr_ref_probe_holds_near(r))
        info->probe_near_cells = set_cells(r, r->near_box, r->near_D, 2 * r->near_F, &plain, &fine);
    if (r->cone_on && r->set.surface_res > 0)
        info->cone_cells = set_cells(r, r->cone_box, 0.5 * (r->cone_box[1] - r->cone_box[0]), r->set.refine_factor,
                                     &plain, &fine);
}

/* Pass 0's plain set (its parameters in *bp): the primitives sampled at half a cell of drift
 * and their grid entries per primitive (*entries) */
static double plain_prims_half(const gr_ref_renderer *r, gr_beam_params *bp, double *entries)
{
    pass_params(r, 0, bp);
    bp->sun_dir = gr_ref_pass_sun_dir(r, 0);
    double sr = r->set.surface_res;
    return set_prims(bp, sr * sr, 0.0, 1, 0.5, entries);
}

void gr_ref_sample_sets(gr_ref_renderer *r, gr_ref_info *info)
{
    if (r->flat || !(plain_cell(r, r->set.surface_res) > 0.0)) return;
    /* the sets of pass 0 (prepare_pass), their slabs as a render builds them at the thinnest:
     * the plain set's and the near set's (0.5 cells of drift where it looks them up enough),
     * the cone's 1, the probe's finer near set's 2 */
    gr_beam_params bp;
    double sr = r->set.surface_res, plain, fine;
    info->plain_prims = r->slab_prims = plain_prims_half(r, &bp, &info->plain_entries); /* kept for the render */
    /* the render's slabs are no thinner than its most lookups make them (render_slab_cells):
     * every pixel of its rows at the step cap, or the pilot's rays */
    const gr_camera *c = &r->scene.camera;
    double most = fmax((double)c->width * (r->opt.row1 - r->opt.row0) * r->spp_pass * r->set.steps,
                       (double)((c->width + PILOT_STRIDE - 1) / PILOT_STRIDE) * ((c->height + PILOT_STRIDE - 1) / PILOT_STRIDE) *
                           r->set.pilot_steps);
    double thin = slab_cells_for(most, info->plain_prims);
    if (thin > 0.5) info->plain_prims = set_prims(&bp, sr * sr, 0.0, 1, thin, &info->plain_entries);
    if (info->near_cells > 0.0) {
        set_cells(r, r->near_box, r->near_D, r->near_F, &plain, &fine);
        info->near_prims = set_prims(&bp, plain, fine, r->near_F, thin, &info->near_entries);
    }
    if (info->probe_near_cells > 0.0) {
        set_cells(r, r->near_box, r->near_D, 2 * r->near_F, &plain, &fine);
        info->probe_near_prims = set_prims(&bp, plain, fine, 2 * r->near_F, 2.0, &info->probe_near_entries);
    }
    if (info->cone_cells > 0.0) {
        set_cells(r, r->cone_box, 0.5 * (r->cone_box[1] - r->cone_box[0]), r->set.refine_factor, &plain, &fine);
        info->cone_prims = set_prims(&bp, plain, fine, r->set.refine_factor, 1.0, &info->cone_entries);
    }
}

gr_status gr_ref_render(gr_ref_renderer *r, gr_ref_result *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    gr_meta_init(&out->meta);
    double t0 = gr_ref_mono_s();
    ref_accum acc;
    acc.W = r->scene.camera.width;
    acc.H = r->scene.camera.height;
    acc.B = r->batches;
    size_t np = (size_t)acc.W * acc.H;
    acc.sum = calloc(np * acc.B * 3, sizeof *acc.sum);
    acc.count = calloc(np * acc.B, sizeof *acc.count);
    acc.aov = r->opt.aovs ? calloc(np * 2, sizeof *acc.aov) : NULL;
    gr_progress *prog = gr_progress_create("reference", r->opt.progress);
    gr_ref_pool *pool = gr_ref_pool_create(r->threads);
    gr_ref_sums *keep = r->opt.keep_sums ? calloc(1, sizeof *keep) : NULL;
    if (!acc.sum || !acc.count || (r->opt.aovs && !acc.aov) || !prog || !pool || (r->opt.keep_sums && !keep)) {
        free(acc.sum); free(acc.count); free(acc.aov); gr_ref_pool_destroy(pool); free(keep); gr_progress_destroy(prog);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %dx%d pixels x %d batches", acc.W, acc.H, acc.B);
    }
    gr_ref_phases_start(&r->phases, REF_PH_OTHER);
    int P = r->passes_per_round;
    int rounds = r->set.target_error > 0.0 ? r->opt.max_rounds : 1;
    gr_status st = GR_OK;
    ref_errors e;
    memset(&e, 0, sizeof e);
    int pass = 0;
    r->rendering = 1;
    /* the plain set's primitives at half a cell, for the slabs' choice (render_slab_cells):
     * sampled here unless gr_ref_sample_sets did (the memory check before the render) */
    r->lookups_next = 0.0;
    if (!(r->slab_prims > 0.0) && !r->flat && plain_cell(r, r->set.surface_res) > 0.0) {
        gr_beam_params bp;
        double entries;
        r->slab_prims = plain_prims_half(r, &bp, &entries);
    }
    int probe = r->set.bias_probe && !r->flat && r->opt.batch0 == 0; /* a part: the one with batch 0 */
    double mainw = probe ? 0.95 : 1.0; /* share of the progress bar for the main passes */
    ref_march_totals tot = {0.0, 0, 0, 0};
    /* the probe's level h, taken during the main passes 0 .. PROBE_PASSES - 1, and where the
     * probe holds the near cells its fourth level (them 2x finer): those passes also build the
     * finer near set and march the probe pixels with it (probe.c) */
    ref_accum cap, capf;
    memset(&capf, 0, sizeof capf);
    r->probe_captured_fine = 0;
    memset(&cap, 0, sizeof cap);
    r->probe_captured = 0;
    if (probe) {
        int poff;
        gr_ref_probe_grid(r, &poff, &cap.W, &cap.H);
        cap.B = 1;
        cap.sum = calloc((size_t)cap.W * cap.H * 3, sizeof *cap.sum);
        cap.count = calloc((size_t)cap.W * cap.H, sizeof *cap.count);
        r->probe_capture_off = poff;
        if (!cap.sum || !cap.count) { /* the probe then renders level h itself */
            free(cap.sum); free(cap.count);
            cap.sum = NULL; cap.count = NULL;
        }
        if (cap.sum && gr_ref_probe_holds_near(r)) {
            capf = cap;
            capf.sum = calloc((size_t)cap.W * cap.H * 3, sizeof *capf.sum);
            capf.count = calloc((size_t)cap.W * cap.H, sizeof *capf.count);
            if (!capf.sum || !capf.count) { /* the probe then renders it itself */
                free(capf.sum); free(capf.count);
                capf.sum = NULL; capf.count = NULL;
            }
        }
    }
    /* adaptive steps: the pilot sets every pixel's steps before the first pass */
    int pilot_done = 1;
    gr_ref_phases_switch(&r->phases, REF_PH_PILOT);
    st = gr_ref_step_pilot(r, pool, prog, &pilot_done, err);
    if (st == GR_OK && !pilot_done) out->partial = 1;
    gr_ref_phases_switch(&r->phases, REF_PH_MARCH);
    /* a pass's lookups: one per stratum, the pixels' steps per camera sample, this part's rows */
    double lookups = 0.0;
    for (int y = r->opt.row0; y < r->opt.row1; y++)
        for (int x = 0; x < acc.W; x++) lookups += r->steps_px ? r->steps_px[(size_t)y * acc.W + x] : r->set.steps;
    lookups *= r->spp_pass;
    for (int round = 0; round < rounds && st == GR_OK && !out->partial; round++) {
        for (int pp = 0; pp < P && st == GR_OK; pp++, pass++) {
            if (pass % acc.B < r->opt.batch0 || pass % acc.B >= r->opt.batch1) continue; /* another part's batch */
            if (r->opt.interrupt && *r->opt.interrupt) { out->partial = 1; break; }
            r->lookups_next = lookups;
            st = gr_ref_prepare_pass(r, pass, err);
            if (st == GR_E_INTERRUPTED) { st = GR_OK; out->partial = 1; break; }
            if (st != GR_OK) break;
            char note[64];
            snprintf(note, sizeof note, "pass %d/%d%s", pp + 1, P, rounds > 1 ? " (refining)" : "");
            int complete = 0;
            /* the probe's passes: the first min(P, PROBE_PASSES) (gr_ref_probe_run, probe.c) */
            r->probe_capture = cap.sum && pass < (P < PROBE_PASSES ? P : PROBE_PASSES) ? &cap : NULL;
            st = gr_ref_march_pass(r, &acc, pass, pass % acc.B, 1, 0, r->opt.row0, r->opt.row1, pool, prog,
                                mainw * (rounds > 1 ? pp : pass) / P, mainw / P, note, &tot, &complete, err);
            if (r->probe_capture && st == GR_OK && complete) r->probe_captured |= 1u << pass;
            r->probe_capture = NULL;
            if (st == GR_OK && complete && capf.sum && pass < (P < PROBE_PASSES ? P : PROBE_PASSES)) {
                /* the probe's fourth level: its pixels with the near set 2x finer in place of the
                 * near set, on this pass's plain set (the probe's own march arguments, so the
                 * same sums as when it renders the level itself: probe.c) */
                ref_march_totals ftot = {0.0, 0, 0, 0};
                gr_ref_phases_switch(&r->phases, REF_PH_PROBE);
                st = gr_ref_near_fine(r, pass, 2 * r->near_F, err);
                if (st == GR_OK)
                    st = gr_ref_probe_march(r, &capf, pass, r->probe_capture_off, pool, prog,
                                            mainw * (rounds > 1 ? pp + 1 : pass + 1) / P, 0.0, note, &ftot, &complete, err);
                gr_ref_phases_switch(&r->phases, REF_PH_MARCH);
                if (st == GR_E_INTERRUPTED) { st = GR_OK; complete = 0; }
                if (st == GR_OK && complete) r->probe_captured_fine |= 1u << pass;
            }
            if (st != GR_OK) break;
            if (!complete) { out->partial = 1; break; }
            out->passes++;
        }
        if (st != GR_OK || out->partial) break;
        if (rounds > 1) {
            gr_status est = GR_OK;
            r->phases.par_total += gr_ref_image_errors(&acc, r->threads, 0, &e, &est);
            if (est != GR_OK) { st = gr_fail(err, GR_E_NOMEM, "reference: out of memory"); break; }
            if (gr_ref_target_met(&e, acc.B, r->set.target_error)) break;
        }
    }
    gr_ref_phases_switch(&r->phases, REF_PH_OTHER);
    /* the tessellation's bias, measured on this scene (flat water has none: closed form) */
    r->bias_rel = r->flat ? 0.0 : -1.0;
    /* the main passes' last beam set (the probe builds others) */
    gr_ref_sums *t = &r->tally;
    r->have_main_beams = r->beams != NULL;
    t->beam_cell_m = t->beam_refine_radius_m = 0.0;
    t->beam_prims = t->beam_refined_cells = t->beam_transition_cells = t->beam_triangles = 0;
    t->beam_refine_factor = 0;
    t->beam_near_factor = 1;
    t->beam_near_radius_m = 0.0;
    t->beam_near_cells = t->beam_near_transition_cells = t->beam_near_triangles = 0;
    if (r->beams) {
        /* the refinements of the camera cone's set and of the set near the camera
         * (docs/reference.md 2.2) */
        const gr_beam_stats *bs = gr_beams_stats(r->beams), *rs = r->cone ? gr_beams_stats(r->cone) : NULL;
        t->beam_cell_m = bs->cell_m;
        t->beam_prims = (long long)bs->prims;
        t->beam_refine_factor = rs ? rs->refine_factor : 1;
        if (rs) {
            t->beam_refine_radius_m = rs->refine_radius_m;
            t->beam_refined_cells = (long long)rs->refined_cells;
            t->beam_transition_cells = (long long)rs->transition_cells;
            t->beam_triangles = (long long)rs->triangles;
        }
        if (r->near_stats_valid) { /* as prepare_pass built it (the probe's level may have replaced it) */
            const gr_beam_stats *ns = &r->near_stats;
            t->beam_near_factor = ns->refine_factor;
            t->beam_near_radius_m = ns->refine_radius_m;
            t->beam_near_cells = (long long)ns->refined_cells;
            t->beam_near_transition_cells = (long long)ns->transition_cells;
            t->beam_near_triangles = (long long)ns->triangles;
        }
    }
    ref_march_totals ptot = {0.0, 0, 0, 0};
    if (st == GR_OK && probe && !out->partial) {
        double tp = gr_ref_mono_s();
        gr_ref_phases_switch(&r->phases, REF_PH_PROBE);
        r->lookups_next = lookups / (PROBE_STRIDE * PROBE_STRIDE); /* every PROBE_STRIDE-th pixel and row */
        st = gr_ref_probe_run(r, keep, &cap, capf.sum ? &capf : NULL, pool, prog, mainw, 1.0 - mainw, &ptot, err);
        gr_ref_phases_switch(&r->phases, REF_PH_OTHER);
        t->probe_s = gr_ref_mono_s() - tp;
    }
    r->rendering = 0;
    gr_progress_finish(prog);
    gr_progress_destroy(prog);
    gr_ref_pool_destroy(pool);
    if (st == GR_OK && (r->flat || out->partial || !probe)) { free(r->bias_px); r->bias_px = NULL; }
    t->passes = out->passes;
    t->march_s = tot.march_s; /* the main passes' (the probe's march is its own time) */
    t->queries = tot.queries;
    t->shadows = tot.shadows;
    t->overflows = 0; /* nothing overflows: the hit list grows */
    if (st == GR_OK) st = gr_ref_finish(r, &acc, &tot, gr_ref_mono_s() - t0, out, err);
    r->phases.on = 0;
    if (st == GR_OK && keep) { /* the raw sums for a part file (src/farm/parts.h) */
        gr_ref_sums_copy_tallies(keep, t);
        keep->W = acc.W;
        keep->H = acc.H;
        keep->B = acc.B;
        keep->sum = acc.sum;
        keep->count = acc.count;
        acc.sum = NULL;
        acc.count = NULL;
        out->sums = keep;
        keep = NULL;
    }
    gr_ref_sums_destroy(keep);
    free(cap.sum);
    free(cap.count);
    free(capf.sum);
    free(capf.count);
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
    const int plevels = 3 + gr_ref_probe_holds_near(r);
    if (sums->probe && sums->probe_levels != plevels)
        return gr_fail(err, GR_E_INPUT, "reference: sums with %d probe levels; this integrator's probe has %d for this scene",
                       sums->probe_levels, plevels);
    if (sums->probe && !r->flat) {
        int off, pw, ph;
        gr_ref_probe_grid(r, &off, &pw, &ph);
        if (gr_ref_probe_stats(r, sums->probe_sum, sums->probe_count, sums->probe_levels, (size_t)sums->probe_w * sums->probe_h,
                               sums->probe_w, sums->probe_h, off) != 0)
            return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the bias probe");
        r->bias_probe_passes = sums->probe_passes;
    }
    /* times, counters, the last beam set, the steps and the pilot: as the render tallied them */
    gr_ref_sums_copy_tallies(&r->tally, sums);
    r->have_main_beams = sums->beam_prims > 0;
    out->passes = sums->passes;
    ref_march_totals tot = {sums->march_s, sums->queries, sums->shadows, -1};
    gr_status st = gr_ref_finish(r, &acc, &tot, wall_s, out, err);
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
    double t0 = gr_ref_mono_s();
    for (int i = 0; i < n; i++) {
        double y = box[4] + (box[5] - box[4]) * gr_rng_double(&g);
        double u = box[0] + (box[1] - box[0]) * gr_rng_double(&g), w = box[2] + (box[3] - box[2]) * gr_rng_double(&g);
        gr_vec3 p = gr_v3((float)(u + r->sx * y), (float)y, (float)(w + r->sz * y));
        found += gr_beams_lookup(r->beams, p, &hits);
    }
    double dt = gr_ref_mono_s() - t0;
    gr_beam_hits_free(&hits);
    (void)found;
    return dt > 0.0 ? n / dt : 0.0;
}
