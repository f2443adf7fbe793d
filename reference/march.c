#include "reference/march.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

#include "core/optics.h"

typedef struct ref_job {
    gr_ref_renderer *r;
    ref_accum *acc;
    int pass, batch;
    /* accumulator pixel (x, y) is image pixel (x stride + off, y stride + off): stride 1 for
     * the image, a sparse grid for the surface-bias probe */
    int stride, off, img_w;
    int y0, y1;         /* accumulator rows [y0, y1), */
    int tiles_x, tiles; /* in tiles of MARCH_TILE^2 pixels (w.next_row counts them) */
    gr_ref_work w;      /* the rows, stop, and per-thread counters summed after the pass */
} ref_job;

/* An nx x ny grid of n cells (nx the largest divisor of n not above sqrt(n)). */
static void cell_grid(int n, int *nx, int *ny)
{
    *nx = 1;
    for (int d = 1; d * d <= n; d++)
        if (n % d == 0) *nx = d;
    *ny = n / *nx;
}

void gr_ref_scratch_free(ref_scratch *sc)
{
    gr_beam_hits_free(&sc->hits);
    free(sc->lights);
    free(sc->t);
    free(sc->w);
    free(sc->tf);
}

int gr_ref_scratch_alloc(ref_scratch *sc, int steps)
{
    memset(sc, 0, sizeof *sc);
    sc->lights = malloc(64 * sizeof *sc->lights);
    sc->lcap = 64;
    sc->t = malloc((size_t)steps * sizeof *sc->t);
    sc->w = malloc((size_t)steps * sizeof *sc->w);
    sc->tf = malloc((size_t)steps * sizeof *sc->tf);
    if (sc->lights && sc->t && sc->w && sc->tf) return 0;
    gr_ref_scratch_free(sc);
    memset(sc, 0, sizeof *sc);
    return -1;
}

/* Where the camera ray (o, d) ends on the set's displaced surface, before De (occluder,
 * seabed, cutoff); past the tessellated patch (or on flat water), the rest plane. */
static float ray_end(const gr_ref_renderer *r, const gr_beams *bs, gr_vec3 o, gr_vec3 d, float De)
{
    unsigned hit = RTC_INVALID_GEOMETRY_ID;
    float D = r->flat ? De : gr_rtc_intersect(gr_beams_surface(bs), o, d, 0.0f, De, &hit, NULL);
    if (hit == RTC_INVALID_GEOMETRY_ID && d.y > 0.0f && -o.y / d.y < D) D = -o.y / d.y;
    return D;
}

/* Whether the local point p lies in the box of the set near the camera (sheared coordinates;
 * docs/reference.md 2.2, "Near the camera"). */
static int in_near(const gr_ref_renderer *r, gr_vec3 p)
{
    float u = p.x - (float)r->sx * p.y, w = p.z - (float)r->sz * p.y;
    const double *b = r->near_box;
    return u >= b[0] && u <= b[1] && w >= b[2] && w <= b[3];
}

/* One camera ray's geometry: its direction, the beam set it looks up, where it ends and its
 * march density exp(-lam t) on [0, D] (om: the density's mass, wbase: a stratum's weight). */
typedef struct ref_ray_geo {
    gr_vec3 d;
    const gr_beams *bs;
    float D;
    double lam, om, wbase;
} ref_ray_geo;

/* The ray through the image point (fx, fy) (pixels) for a march of n steps; *trans and *len
 * get its transmittance (RGB mean) and length to its end. */
static void ray_geometry(const gr_ref_renderer *r, double fx, double fy, int n, ref_ray_geo *rg, double *trans,
                         double *len)
{
    const gr_camera *c = &r->scene.camera;
    double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), aspect = (double)c->width / (double)c->height;
    gr_dvec3 dd = cam_dir(r, (2.0 * fx / c->width - 1.0) * tf * aspect, (1.0 - 2.0 * fy / c->height) * tf);
    gr_vec3 d = gr_d3_to_f(dd), o = r->cam;
    /* where the camera ray ends: occluder or seabed, the water surface, the cutoff */
    float De = gr_rtc_intersect(r->geom->ends, o, d, 0.0f, (float)gr_ref_cutoff_d(r, dd.y), NULL, NULL), D = -1.0f;
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
    if (bs == r->beams) {
        D = ray_end(r, r->beams, o, d, De);
        /* where it ends near the camera, on that set's finer surface */
        if (r->near && D > 0.0f && in_near(r, gr_v3_madd(o, d, D))) D = ray_end(r, r->near, o, d, De);
    }
    if (!(D > 0.0f)) D = 0.0f;
    *len = D;
    *trans = (exp(-r->sig_t[0] * D) + exp(-r->sig_t[1] * D) + exp(-r->sig_t[2] * D)) / 3.0;
    rg->d = d;
    rg->bs = bs;
    rg->D = D;
    /* March density ~ exp(-lam t) on [0, D], lam = sig_ref (1 - w_y / mu_t0): the camera
     * ray's extinction times the sunlight's extinction down to the point on flat water, so
     * the flat-water integrand is sampled exactly in proportion (Oracle 1) and the waves
     * only add their caustic modulation. Stratified in the density's CDF, jittered. */
    double lam = r->sig_ref * (1.0 - (double)d.y / -r->T0.y), lD = lam * D;
    if (fabs(lD) > 1e-6) {
        rg->lam = lam;
        rg->om = -expm1(-lD);
        rg->wbase = rg->om / (lam * n);
    } else {
        rg->lam = 0.0;
        rg->om = 0.0;
        rg->wbase = (double)D / n;
    }
}

int gr_ref_march_ray(const gr_ref_renderer *r, int nrays, const double *fx, const double *fy, int n, const uint16_t *alloc,
                     int anti, ref_rng *g, double L[3], double *trans, double *len, ref_counters *cnt, ref_scratch *sc,
                     double *ck)
{
    ref_ray_geo rg[REF_MAX_RAYS];
    const gr_vec3 o = r->cam;
    L[0] = L[1] = L[2] = 0.0;
    *trans = *len = 0.0;
    int any = 0;
    for (int i = 0; i < nrays; i++) {
        double tr, ln;
        ray_geometry(r, fx[i], fy[i], n, &rg[i], &tr, &ln);
        *trans += tr / nrays;
        *len += ln / nrays;
        any |= rg[i].D > 0.0f;
    }
    if (ck)
        for (int k = 0; k < 3 * n; k++) ck[k] = 0.0;
    if (!any) return 0;
    const gr_hg hg = gr_hg_make(r->scene.medium.g); /* seed eq. 5.5.4 */
    /* segment sg of the CDF range, [sg, sg + 1) / nseg, holds a >= 1 jittered strata; a point
     * there stands for 1 / (nseg a) of the range (the weight wbase n / (nseg a)); n = the sum
     * of alloc (docs/reference.md 2.5). Without an allotment: one segment of n strata, each
     * of weight wbase. Stratum k is marched on ray k mod nrays (the caller places the rays in
     * the pixel in a random rotation of its sub-cells, so that every stratum's ray is uniform
     * over the pixel: docs/reference.md 2.5, "Rays per camera sample") */
    const int nseg = alloc ? SEGMENTS : 1;
    for (int sg = 0, k = 0; sg < nseg; sg++) {
        int a = alloc ? alloc[sg] : n;
        for (int j = 0; j < a; j++, k++) {
            const ref_ray_geo *q = &rg[k % nrays];
            double xi = rng_u(g);
            if (anti) xi = xi < 0.5 ? xi + 0.5 : xi - 0.5; /* the pair's other half of the stratum */
            double u = (sg + (j + xi) / a) / nseg;
            sc->t[k] = q->lam != 0.0 ? -log1p(-u * q->om) / q->lam : u * q->D;
            sc->tf[k] = (float)sc->t[k];
            sc->w[k] = q->D > 0.0f ? (alloc ? q->wbase * n / ((double)SEGMENTS * a) : q->wbase) : 0.0;
        }
    }
    for (int k = 0; k < n; k++) {
        if (sc->w[k] == 0.0) continue; /* a ray that ends at once (D = 0) */
        const ref_ray_geo *q = &rg[k % nrays];
        const gr_vec3 d = q->d;
        const double lam = q->lam;
        double t = sc->t[k];
        gr_vec3 x = gr_v3_madd(o, d, sc->tf[k]);
        /* a point of a plain-set ray near the camera looks up the finer set there */
        const gr_beams *bs = q->bs == r->beams && r->near && in_near(r, x) ? r->near : q->bs;
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
                if (ck) ck[3 * k + ch] += v;
            }
        }
    }
    return 0;
}

/* Where a pixel's camera samples and their rays go: the samples' strata an nx x ny grid of
 * cells of the pixel, each cell's rays a kx x ky grid of sub-cells (cell_grid; fixed for a
 * render, set once per worker). */
typedef struct ref_sample_grid { int nx, ny, kx, ky; } ref_sample_grid;

/* One camera sample of pixel (px, py) with n march steps: stratum j of the camera samples its
 * batch takes in this round (a cell of the pixel), marched on the kx ky rays, one jittered in
 * each of the cell's sub-cells, in a random rotation (docs/reference.md 2.5, "Rays per
 * camera sample"). anti: the second sample of an antithetic pair, g the first's stream. */
static int render_sample(const gr_ref_renderer *r, int px, int py, int j, const ref_sample_grid *sg, int n,
                         const uint16_t *alloc, int anti, ref_rng *g, double L[3], double *trans, double *len, ref_counters *cnt,
                         ref_scratch *sc)
{
    const int nrays = sg->kx * sg->ky;
    double fx[REF_MAX_RAYS], fy[REF_MAX_RAYS];
    int rot = nrays > 1 ? (int)(rng_u(g) * nrays) : 0;
    if (rot >= nrays) rot = nrays - 1;
    for (int i = 0; i < nrays; i++) {
        int sub = (i + rot) % nrays;
        double ux = rng_u(g), uy = rng_u(g);
        if (anti) { /* the pair's second sample: the first's place mirrored in its sub-cell */
            ux = 1.0 - ux;
            uy = 1.0 - uy;
        }
        fx[i] = px + ((j % sg->nx) + ((sub % sg->kx) + ux) / sg->kx) / sg->nx;
        fy[i] = py + ((j / sg->nx) + ((sub / sg->kx) + uy) / sg->ky) / sg->ny;
    }
    return gr_ref_march_ray(r, nrays, fx, fy, n, alloc, anti, g, L, trans, len, cnt, sc, NULL);
}

static void *worker(void *arg)
{
    ref_job *job = arg;
    const gr_ref_renderer *r = job->r;
    ref_accum *acc = job->acc;
    ref_scratch sc;
    ref_counters cnt = {0, 0, 0};
    int oom = 0;
    /* camera samples are stratified over the pixel within a batch (like the passes' strata):
     * this pass is the k-th of its batch in the round */
    int per_batch, k_in_batch = pass_in_batch(r, job->pass, &per_batch);
    /* the second pass of an antithetic pair (docs/reference.md 2.5): the first's random numbers,
     * its rays' places mirrored in their sub-cells (of its own cell of the pixel), every step
     * moved by half a stratum */
    int anti = pass_antithetic(r, job->pass), rng_pass = pass_stream(r, job->pass);
    ref_sample_grid sgrid;
    cell_grid(per_batch * r->spp_pass, &sgrid.nx, &sgrid.ny);
    cell_grid(r->camera_rays, &sgrid.kx, &sgrid.ky);
    if (gr_ref_scratch_alloc(&sc, r->set.steps) != 0) {
        atomic_store(&job->w.stop, 2);
        return NULL;
    }
    for (;;) {
        if (atomic_load(&job->w.stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        /* a band of MARCH_TILE rows, in tiles of MARCH_TILE x MARCH_TILE pixels: neighbouring
         * rays look up the same beams while they are still in cache (docs/reference.md 2.2,
         * "Lookups"); the pixels' sums do not depend on the order */
        int tile = atomic_fetch_add(&job->w.next_row, 1); /* tiles, band by band: the last ones balance the threads */
        if (tile >= job->tiles) break;
        int yb = job->y0 + (tile / job->tiles_x) * MARCH_TILE, xb = (tile % job->tiles_x) * MARCH_TILE;
        int ye = job->y1 - yb < MARCH_TILE ? job->y1 : yb + MARCH_TILE;
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
                uint64_t sample = (uint64_t)rng_pass * (uint64_t)r->spp_pass + (uint64_t)s;
                ref_rng g = rng_make(r->set.seed, STREAM_PIXEL0 + pix, sample);
                double L[3], tr, len;
                if (render_sample(r, px, py, k_in_batch * r->spp_pass + s, &sgrid, n, alloc, anti, &g, L, &tr, &len,
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
            atomic_store(&job->w.stop, 2); /* out of memory: the pass fails, nothing is dropped */
            break;
        }
        if (r->opt.interrupt && *r->opt.interrupt) break; /* the band may be unfinished: not counted */
        atomic_fetch_add(&job->w.rows_done, 1);
    }
    atomic_fetch_add(&job->w.queries, cnt.queries);
    atomic_fetch_add(&job->w.shadow_rays, cnt.shadow_rays);
    long long mh = atomic_load(&job->w.max_hits);
    while (cnt.max_hits > mh && !atomic_compare_exchange_weak(&job->w.max_hits, &mh, cnt.max_hits)) {}
    gr_ref_scratch_free(&sc);
    return NULL;
}

gr_status gr_ref_march_pass(gr_ref_renderer *r, ref_accum *acc, int pass, int batch, int stride, int off, int y0, int y1,
                            gr_ref_pool *pool, gr_progress *prog, double frac0, double span, const char *note,
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
    job.y0 = y0;
    job.y1 = y1;
    job.tiles_x = (acc->W + MARCH_TILE - 1) / MARCH_TILE;
    job.tiles = job.tiles_x * ((y1 - y0 + MARCH_TILE - 1) / MARCH_TILE);
    gr_ref_work_init(&job.w, 0);
    *complete = 0;
    double tm = gr_ref_mono_s();
    gr_status st = gr_ref_pool_run(pool, worker, &job, &job.w, job.tiles, r->opt.interrupt, prog, frac0, span, note, err);
    if (st == GR_E_RUNTIME) return st; /* no worker started */
    r->phases.par_total += job.w.par_s;
    tot->march_s += gr_ref_mono_s() - tm;
    tot->queries += atomic_load(&job.w.queries);
    tot->shadows += atomic_load(&job.w.shadow_rays);
    if (atomic_load(&job.w.max_hits) > tot->max_hits) tot->max_hits = atomic_load(&job.w.max_hits);
    if (st != GR_OK) return st;
    *complete = atomic_load(&job.w.rows_done) >= job.tiles;
    return GR_OK;
}
