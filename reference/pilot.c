#include "reference/pilot.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "reference/beam_grid.h"
#include "reference/march.h"

typedef struct pilot_job {
    gr_ref_renderer *r;
    int pw, ph;         /* the pilot grid: one ray per PILOT_STRIDE^2 block of pixels */
    int jb0, jb1;       /* pilot rows needed in full (a part's rows and their neighbours) */
    int n0;             /* the pilot's steps (even) */
    int tiles;          /* the work: tiles of (MARCH_TILE / PILOT_STRIDE)^2 pilot pixels */
    double *pl, *pv;    /* per pilot pixel and channel [q * 3 + c]: L, the step-noise variance estimate V */
    double *pvs;        /* per pilot pixel, segment and channel [(q * SEGMENTS + s) * 3 + c]: the part
                           of V from the segment's strata */
    gr_ref_work w;      /* the pilot rows, stop, counters */
} pilot_job;

/* Pilot rows [jb0, jb1) in full; elsewhere every PILOT_MEAN_STRIDE-th row and column (the
 * image mean). Each pilot pixel's ray is keyed by (seed, STREAM_PILOT, its index), so every
 * part computes the same values. */
static void *pilot_worker(void *arg)
{
    pilot_job *job = arg;
    const gr_ref_renderer *r = job->r;
    const int W = r->scene.camera.width, H = r->scene.camera.height, n0 = job->n0;
    ref_scratch sc;
    ref_counters cnt = {0, 0, 0};
    double *ck = malloc((size_t)n0 * 3 * sizeof *ck);
    if (!ck || gr_ref_scratch_alloc(&sc, n0) != 0) {
        free(ck);
        atomic_store(&job->w.stop, 2);
        return NULL;
    }
    for (;;) {
        if (atomic_load(&job->w.stop) || (r->opt.interrupt && *r->opt.interrupt)) break;
        /* bands of pilot rows in square tiles, as the march's (worker) */
        const int pt = MARCH_TILE / PILOT_STRIDE, tx = (job->pw + pt - 1) / pt;
        int tile = atomic_fetch_add(&job->w.next_row, 1), oom = 0;
        if (tile >= job->tiles) break;
        int jb = (tile / tx) * pt, ib = (tile % tx) * pt;
        int je = job->ph - jb < pt ? job->ph : jb + pt;
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
            if (gr_ref_march_ray(r, 1, &fx, &fy, n0, NULL, 0, &g, L, &tr, &len, &cnt, &sc, ck) != 0) { oom = 1; break; }
            /* collapsed strata: the strata 2i and 2i + 1 merged into one holding two samples,
             * whose variance (c_2i - c_2i+1)^2 estimates without bias and that of the stratified
             * pair at most (docs/reference.md 2.5) */
            double v[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k + 1 < n0; k += 2)
                for (int c = 0; c < 3; c++) v[c] += (ck[3 * k + c] - ck[3 * k + 3 + c]) * (ck[3 * k + c] - ck[3 * k + 3 + c]);
            /* per segment (where along the ray the noise is): every stratum's squared differences
             * to both neighbours, halved twice (each difference is counted by two strata, and
             * the expectation of a difference holds two strata's variances), so that a jump
             * between merged pairs is seen as well as one inside a pair */
            double *vs = job->pvs + q * SEGMENTS * 3;
            for (int k = 0; k < n0; k++)
                for (int c = 0; c < 3; c++) {
                    const double *x = ck + c;
                    double dl = k > 0 ? x[3 * k] - x[3 * k - 3] : x[3 * k] - x[3 * k + 3];
                    double dr = k + 1 < n0 ? x[3 * k] - x[3 * k + 3] : dl;
                    vs[((size_t)k * SEGMENTS / (size_t)n0) * 3 + (size_t)c] += 0.25 * (dl * dl + dr * dr);
                }
            for (int c = 0; c < 3; c++) {
                job->pl[q * 3 + (size_t)c] = L[c];
                job->pv[q * 3 + (size_t)c] = v[c];
            }
        }
        if (oom) { atomic_store(&job->w.stop, 2); break; }
        if (r->opt.interrupt && *r->opt.interrupt) break;
        atomic_fetch_add(&job->w.rows_done, 1);
    }
    atomic_fetch_add(&job->w.queries, cnt.queries);
    atomic_fetch_add(&job->w.shadow_rays, cnt.shadow_rays);
    gr_ref_scratch_free(&sc);
    free(ck);
    return NULL;
}

/* Steps along the ray (docs/reference.md 2.5, "Steps along the ray"). Segment s holds m[s]
 * pilot strata whose step noise was V[s]; with n_s strata its noise is V[s] (m[s] / n_s)^2
 * (the model, alpha = 2), and the least total sum n_s for sum V[s] (m[s] / n_s)^2 <= T is
 * n_s = c (V[s] m[s]^2)^(1/3), c = sqrt(sum (V m^2)^(1/3) / T) (Lagrange). Rounded up, at
 * least one stratum per segment (unbiased), the total clamped to [nmin, nmax]. Returns the
 * total; *wanted gets the total before the cap. */
static int allot_segments(const double V[SEGMENTS], const int m[SEGMENTS], double T, int nmin, int nmax, double floor_n,
                          uint16_t n[SEGMENTS], double *wanted)
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
    *wanted = tot;
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
 * n = n0 (V / (N step_error^2 norm^2))^(1 / alpha), clamped to [min_steps, steps]; per
 * channel, the pixel taking the most any channel needs. Rows split among the threads (each
 * pixel's steps depend on the pilot only: the same map for any thread count). */
typedef struct map_job {
    gr_ref_renderer *r;
    const pilot_job *job;
    double mean[3];
    int y0, y1;                 /* image rows */
    double sum, pixels;         /* the steps' tallies over the rows */
    double capped, wanted;      /* pixels the cap held back, and the steps they asked for */
    int smin, smax;
} map_job;

static void *steps_map_rows(void *arg)
{
    map_job *mj = arg;
    gr_ref_renderer *r = mj->r;
    const pilot_job *job = mj->job;
    const double *mean = mj->mean;
    const int W = r->scene.camera.width, pw = job->pw, ph = job->ph;
    double N = (double)r->passes_per_round * r->spp_pass, tau = r->set.step_error;
    int nmax = r->set.steps, nmin = r->set.min_steps < nmax ? r->set.min_steps : nmax;
    /* antithetic pairs (docs/reference.md 2.5): a pair's two samples with their steps half a
     * stratum apart act as one sample of 2n strata, whose step noise is a quarter of one of n
     * (alpha = 2): the mean of P pairs and U unpaired samples has the step noise of N^2 / (P + U)
     * independent samples. Per batch in a round: P = per_batch / 2 pairs, U = per_batch mod 2. */
    if (antithetic_pairs(r)) {
        int per_batch = r->passes_per_round / r->batches, P = antithetic_pairs(r), U = per_batch - 2 * P;
        N = N * per_batch / (P + U);
    }
    int m[SEGMENTS] = {0}; /* pilot strata per segment (pairs assigned by their first stratum) */
    for (int k = 0; k + 1 < job->n0; k += 2) m[(size_t)k * SEGMENTS / (size_t)job->n0] += 2;
    mj->sum = mj->pixels = mj->capped = mj->wanted = 0.0;
    mj->smin = INT_MAX;
    mj->smax = 0;
    for (int py = mj->y0; py < mj->y1; py++)
        for (int px = 0; px < W; px++) {
            /* the pilot neighbourhood, clamped to the pilot grid: its means of V, L and (with
             * the allotment) the segments' V, per channel */
            int i0 = px / PILOT_STRIDE, j0 = py / PILOT_STRIDE;
            int ia = i0 - PILOT_RADIUS > 0 ? i0 - PILOT_RADIUS : 0, ib = i0 + PILOT_RADIUS < pw - 1 ? i0 + PILOT_RADIUS : pw - 1;
            int ja = j0 - PILOT_RADIUS > 0 ? j0 - PILOT_RADIUS : 0, jb = j0 + PILOT_RADIUS < ph - 1 ? j0 + PILOT_RADIUS : ph - 1;
            int nq = (ib - ia + 1) * (jb - ja + 1);
            double vsum[3] = {0.0, 0.0, 0.0}, lsum[3] = {0.0, 0.0, 0.0}, Vc[SEGMENTS][3] = {{0}};
            for (int j = ja; j <= jb; j++)
                for (int i = ia; i <= ib; i++) {
                    size_t q = (size_t)j * pw + i;
                    for (int c = 0; c < 3; c++) {
                        vsum[c] += job->pv[q * 3 + (size_t)c];
                        lsum[c] += job->pl[q * 3 + (size_t)c];
                    }
                    if (r->alloc_px)
                        for (int k = 0; k < SEGMENTS; k++)
                            for (int c = 0; c < 3; c++) Vc[k][c] += job->pvs[(q * SEGMENTS + (size_t)k) * 3 + (size_t)c];
                }
            /* Per channel (issue 30: the target holds in each of R, G and B, not their mean): the
             * step noise relative to the channel's own norm, max(L_c, image mean_c); the
             * pixel takes the steps its worst channel needs, and each segment the largest of
             * the channels' relative noise there (so every channel's sum is within the
             * target). A channel with no light (norm 0) asks for nothing. */
            double v = 0.0, V[SEGMENTS] = {0};
            for (int c = 0; c < 3; c++) {
                double norm = fmax(lsum[c] / nq, mean[c]);
                if (!(norm > 0.0)) continue;
                double rc = vsum[c] / nq / (norm * norm);
                v = rc > v || isnan(rc) ? rc : v;
                if (r->alloc_px)
                    for (int k = 0; k < SEGMENTS; k++) {
                        double vk = Vc[k][c] / nq / (norm * norm);
                        V[k] = vk > V[k] || isnan(vk) ? vk : V[k];
                    }
            }
            /* the even spread's steps (its floor below, or the pixel's steps without the allotment) */
            double n = job->n0 * pow(v / (N * tau * tau), 1.0 / PILOT_ALPHA);
            int ni;
            double want; /* the steps the target asks for, before the cap */
            if (r->alloc_px) {
                /* the steps along the ray, segment by segment */
                /* the floor: ALLOT_FLOOR of the uniform allocation's steps per pilot stratum (a part
                 * the pilot saw as quiet keeps some strata: its noise is at most 1 / ALLOT_FLOOR^2
                 * times what the uniform march would leave there) */
                double nu = v > 0.0 ? (n < nmax ? n : nmax) : nmin; /* also NaN: the most */
                ni = allot_segments(V, m, N * tau * tau, nmin, nmax, ALLOT_FLOOR * nu / job->n0,
                                    r->alloc_px + ((size_t)py * W + px) * SEGMENTS, &want);
            } else {
                want = n;
                if (v == 0.0) ni = nmin;
                else if (!(n < (double)nmax)) ni = nmax; /* also NaN: the most steps */
                else ni = n > nmin ? (int)ceil(n) : nmin;
            }
            r->steps_px[(size_t)py * W + px] = ni;
            if (!(want <= (double)nmax)) { /* also NaN: the target needs more than the cap allows */
                mj->capped += 1.0;
                mj->wanted += want < 65536.0 ? ceil(want) : 65536.0;
            }
            mj->sum += ni;
            mj->pixels += 1.0;
            if (ni < mj->smin) mj->smin = ni;
            if (ni > mj->smax) mj->smax = ni;
        }
    return NULL;
}

static void pilot_steps_map(gr_ref_renderer *r, const pilot_job *job)
{
    const int pw = job->pw, ph = job->ph;
    double msum[3] = {0.0, 0.0, 0.0};
    long long mn = 0;
    for (int j = 0; j < ph; j += PILOT_MEAN_STRIDE)
        for (int i = 0; i < pw; i += PILOT_MEAN_STRIDE) {
            for (int c = 0; c < 3; c++) msum[c] += job->pl[((size_t)j * pw + i) * 3 + (size_t)c];
            mn++;
        }
    map_job mj[GRID_MAX_THREADS];
    int nt = r->threads < GRID_MAX_THREADS ? r->threads : GRID_MAX_THREADS, rows = r->opt.row1 - r->opt.row0;
    if (nt > rows) nt = rows;
    if (nt < 1) nt = 1;
    for (int i = 0; i < nt; i++) {
        mj[i].r = r;
        mj[i].job = job;
        for (int c = 0; c < 3; c++) mj[i].mean[c] = mn ? msum[c] / (double)mn : 0.0;
        mj[i].y0 = r->opt.row0 + (int)((long)rows * i / nt);
        mj[i].y1 = r->opt.row0 + (int)((long)rows * (i + 1) / nt);
    }
    r->phases.par_total += gr_beams_run_jobs(steps_map_rows, mj, sizeof mj[0], nt);
    r->tally.steps_sum = r->tally.steps_pixels = r->tally.steps_capped = r->tally.steps_wanted_sum = 0.0;
    r->tally.steps_min = INT_MAX;
    r->tally.steps_max = 0;
    for (int i = 0; i < nt; i++) { /* integers in double: exact, the same sums in any split */
        r->tally.steps_sum += mj[i].sum;
        r->tally.steps_capped += mj[i].capped;
        r->tally.steps_wanted_sum += mj[i].wanted;
        r->tally.steps_pixels += mj[i].pixels;
        if (mj[i].smin < r->tally.steps_min) r->tally.steps_min = mj[i].smin;
        if (mj[i].smax > r->tally.steps_max) r->tally.steps_max = mj[i].smax;
    }
}

/* Adaptive steps: the pilot rays and the steps map, or r->steps_px = NULL (fixed steps:
 * adaptive_steps off, or steps no more than min_steps). *complete = 0 when interrupted. */
gr_status gr_ref_step_pilot(gr_ref_renderer *r, gr_ref_pool *pool, gr_progress *prog, int *complete, gr_error *err)
{
    const int W = r->scene.camera.width, H = r->scene.camera.height;
    free(r->steps_px);
    r->steps_px = NULL;
    free(r->alloc_px);
    r->alloc_px = NULL;
    r->tally.pilot_steps = 0;
    r->tally.pilot_s = 0.0;
    r->tally.steps_min = r->tally.steps_max = r->set.steps;
    r->tally.steps_pixels = (double)W * (r->opt.row1 - r->opt.row0);
    r->tally.steps_sum = r->tally.steps_pixels * r->set.steps;
    r->tally.steps_capped = r->tally.steps_wanted_sum = 0.0;
    *complete = 1;
    if (!r->set.adaptive_steps || r->set.steps <= r->set.min_steps) return GR_OK;
    double t0 = gr_ref_mono_s();
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
    job.pl = calloc(nq * 3, sizeof *job.pl);
    job.pv = calloc(nq * 3, sizeof *job.pv);
    job.pvs = calloc(nq * SEGMENTS * 3, sizeof *job.pvs);
    r->steps_px = calloc((size_t)W * H, sizeof *r->steps_px);
    /* steps along the ray: when every segment can take a stratum within [min_steps, steps]
     * and the pilot has one per segment at least */
    int allot = r->set.steps_along_ray && r->set.min_steps >= SEGMENTS && job.n0 >= 2 * SEGMENTS;
    if (allot) r->alloc_px = calloc((size_t)W * H * SEGMENTS, sizeof *r->alloc_px);
    if (!job.pl || !job.pv || !job.pvs || !r->steps_px || (allot && !r->alloc_px)) {
        free(job.pl); free(job.pv); free(job.pvs);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the step pilot (%dx%d)", W, H);
    }
    r->lookups_next = (double)job.pw * (job.jb1 - job.jb0) * job.n0; /* its rays' steps (the slabs' choice) */
    gr_status st = gr_ref_prepare_pass(r, PILOT_PASS, err);
    if (st == GR_E_INTERRUPTED) { *complete = 0; st = GR_OK; goto out; }
    if (st != GR_OK) goto out;
    gr_ref_work_init(&job.w, 0);
    {
        const int pt = MARCH_TILE / PILOT_STRIDE;
        job.tiles = ((job.pw + pt - 1) / pt) * ((job.ph + pt - 1) / pt);
    }
    st = gr_ref_pool_run(pool, pilot_worker, &job, &job.w, job.tiles, r->opt.interrupt, prog, 0.0, 0.0, "step pilot", err);
    r->phases.par_total += job.w.par_s;
    if (st != GR_OK) goto out;
    if (atomic_load(&job.w.rows_done) < job.tiles) { *complete = 0; goto out; } /* interrupted: partial */
    r->tally.pilot_steps = job.n0;
    pilot_steps_map(r, &job);
out:
    if (st != GR_OK || !*complete) { /* no steps map: nothing is rendered after this */
        free(r->steps_px);
        r->steps_px = NULL;
        free(r->alloc_px);
        r->alloc_px = NULL;
        r->tally.steps_sum = r->tally.steps_pixels = 0.0; /* steps_mean -1: none taken */
        r->tally.steps_min = r->tally.steps_max = 0;
    }
    free(job.pl);
    free(job.pv);
    free(job.pvs);
    r->tally.pilot_s = gr_ref_mono_s() - t0;
    return st;
}
