#include "reference/stats.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stdatomic.h>

#include "core/student.h"
#include "reference/beam_grid.h"
#include "reference/probe.h"
#include "scene/settings.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double gr_ref_percentile(double *v, size_t n, double q)
{
    if (!n) return 0.0;
    qsort(v, n, sizeof *v, cmp_double);
    double pos = q * (double)(n - 1);
    size_t i = (size_t)pos;
    if (i + 1 >= n) return v[n - 1];
    double f = pos - (double)i;
    return v[i] * (1.0 - f) + v[i + 1] * f;
}

/* A pixel's value and index, ranked by value, ties by index (the order a stable sort of the
 * indices by value gives; no shared state, so the quantities may rank on several threads). */
typedef struct ranked {
    double v;
    size_t i;
} ranked;
static int cmp_ranked(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->v != y->v) return (x->v > y->v) - (x->v < y->v);
    return (x->i > y->i) - (x->i < y->i);
}

int gr_ref_target_met(const ref_errors *e, int batches, double target)
{
    double k = gr_student_t975(batches - 1) / GR_NORMAL_Q975;
    int met = k * e->rel_mean < target && k * e->rel_p95 < target;
    for (int c = 0; c < 3; c++) met = met && k * e->ch_rel_mean[c] < target && k * e->ch_rel_p95[c] < target; /* issue 30 */
    return met;
}

/* One quantity's image errors: channel ch (0..2) or the RGB mean (ch = -1). */
static gr_status quantity_errors(const ref_accum *acc, int ch, ref_errors *e)
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
            tmp[k++] = ch < 0 ? (s[0] + s[1] + s[2]) / (3.0 * c) : s[ch] / c;
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
            double mb = ch < 0 ? (sm[0] + sm[1] + sm[2]) / (3.0 * c) : sm[ch] / c;
            s += mb;
            s2 += mb * mb;
            kb++;
            n += c;
            tot += ch < 0 ? sm[0] + sm[1] + sm[2] : sm[ch];
        }
        v[p] = n ? tot / ((ch < 0 ? 3.0 : 1.0) * n) : 0.0;
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
    e->p95 = gr_ref_percentile(tmp, np, 0.95);
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
        ranked *ord = malloc(np * sizeof *ord);
        if (!ord) { free(tmp); free(Mb); free(Qb); free(v); free(se); return GR_E_NOMEM; }
        for (size_t p = 0; p < np; p++) ord[p] = (ranked){v[p], p};
        qsort(ord, np, sizeof *ord, cmp_ranked);
        size_t c = (size_t)(0.95 * (double)(np - 1)), band = np / 100;
        size_t lo = c > band ? c - band : 0, hi = c + band < np ? c + band : np - 1;
        double sv = 0.0, ss = 0.0;
        for (size_t i = lo; i <= hi; i++) { sv += v[ord[i].i] * v[ord[i].i]; ss += se[ord[i].i] * se[ord[i].i]; }
        free(ord);
        e->rel_p95 = sv > 0.0 ? sqrt(ss / sv) : (ss > 0.0 ? INFINITY : 0.0);
    } else {
        e->rel_mean = e->rel_p95 = INFINITY;
    }
    free(tmp); free(Mb); free(Qb); free(v); free(se);
    return GR_OK;
}

static void block_noise(const ref_accum *acc, double q[3], double *p99, int at[2]);

/* The statistics' jobs (issue 30: no serial phase): the RGB mean's errors, each channel's,
 * and (optionally) the block noise, taken from a counter by `threads` threads; each job
 * writes only its own result, so the values do not depend on the thread count. */
typedef struct stats_work {
    const ref_accum *acc;
    ref_errors q[4];          /* [0] the RGB mean, [1 + c] channel c */
    gr_status st[4];
    int blocks;               /* 1: also the block noise, into block8 */
    double block8[3], block8_p99;
    int block8_at[2];
    atomic_int next;
} stats_work;
typedef struct stats_thread {
    stats_work *w;
} stats_thread;

static void *stats_job(void *arg)
{
    stats_work *w = ((stats_thread *)arg)->w;
    for (;;) {
        int k = atomic_fetch_add(&w->next, 1);
        if (k < 4) w->st[k] = quantity_errors(w->acc, k - 1, &w->q[k]);
        else if (k == 4 && w->blocks) block_noise(w->acc, w->block8, &w->block8_p99, w->block8_at);
        else break;
    }
    return NULL;
}

double gr_ref_image_errors(const ref_accum *acc, int threads, int blocks, ref_errors *e, gr_status *st)
{
    stats_work *w = calloc(1, sizeof *w);
    if (!w) {
        *st = GR_E_NOMEM;
        return 0.0;
    }
    w->acc = acc;
    w->blocks = blocks;
    w->block8_at[0] = w->block8_at[1] = -1;
    atomic_init(&w->next, 0);
    stats_thread th[5];
    int n = threads < 1 ? 1 : threads > 5 ? 5 : threads;
    for (int i = 0; i < n; i++) th[i].w = w;
    double par = gr_beams_run_jobs(stats_job, th, sizeof th[0], n);
    *e = w->q[0];
    memcpy(e->block8, w->block8, sizeof e->block8);
    e->block8_p99 = w->block8_p99;
    e->block8_at[0] = w->block8_at[0];
    e->block8_at[1] = w->block8_at[1];
    *st = GR_OK;
    for (int k = 0; k < 4; k++)
        if (w->st[k] != GR_OK) *st = w->st[k];
    for (int c = 0; c < 3; c++) {
        e->ch_rel_mean[c] = w->q[1 + c].rel_mean;
        e->ch_rel_p95[c] = w->q[1 + c].rel_p95;
        e->ch_frac_1pct[c] = w->q[1 + c].frac_1pct;
    }
    free(w);
    return par;
}

/* 8 x 8 blocks (issue 30): each block's mean per batch (the mean of its pixels' batch means),
 * its standard error from the spread of those B means (so that what the pixels share, the
 * passes' beam sets, is counted), relative to max(block mean, image mean) per channel, the
 * largest channel's. Its 50th, 95th and 99th percentiles and maximum over the whole blocks,
 * and where the worst block is (its first pixel). */
static void block_noise(const ref_accum *acc, double q[3], double *p99, int at[2])
{
    enum { BS = 8 };
    int bw = acc->W / BS, bh = acc->H / BS, B = acc->B;
    q[0] = q[1] = q[2] = *p99 = -1.0;
    double chm[3] = {0.0, 0.0, 0.0};
    size_t np = (size_t)acc->W * acc->H;
    for (size_t p = 0; p < np; p++) {
        uint32_t n = 0;
        double t[3] = {0.0, 0.0, 0.0};
        for (int b = 0; b < B; b++) {
            n += acc->count[p * B + b];
            for (int c = 0; c < 3; c++) t[c] += acc->sum[(p * B + b) * 3 + c];
        }
        for (int c = 0; c < 3; c++) chm[c] += n ? t[c] / n : 0.0;
    }
    for (int c = 0; c < 3; c++) chm[c] /= (double)(np ? np : 1);
    if (bw < 1 || bh < 1 || B < 2) return;
    double *rel = malloc((size_t)bw * bh * sizeof *rel), *m = malloc((size_t)B * 3 * sizeof *m);
    if (!rel || !m) { free(rel); free(m); return; }
    size_t nb = 0;
    double top = -1.0;
    for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++) {
            int ok = 1;
            for (int b = 0; b < B; b++)
                for (int c = 0; c < 3; c++) m[b * 3 + c] = 0.0;
            for (int y = by * BS; y < by * BS + BS && ok; y++)
                for (int x = bx * BS; x < bx * BS + BS && ok; x++) {
                    size_t p = (size_t)y * acc->W + x;
                    for (int b = 0; b < B; b++) {
                        uint32_t k = acc->count[p * B + b];
                        if (!k) { ok = 0; break; }
                        for (int c = 0; c < 3; c++) m[b * 3 + c] += acc->sum[(p * B + b) * 3 + c] / k / (BS * BS);
                    }
                }
            if (!ok) continue; /* not rendered in full (interrupted) */
            double worst = 0.0;
            for (int c = 0; c < 3; c++) {
                double s = 0.0, s2 = 0.0;
                for (int b = 0; b < B; b++) { s += m[b * 3 + c]; s2 += m[b * 3 + c] * m[b * 3 + c]; }
                double mm = s / B, se = sqrt(fmax(0.0, (s2 - B * mm * mm) / (B - 1)) / B), norm = fmax(mm, chm[c]);
                double r = norm > 0.0 ? se / norm : 0.0;
                if (r > worst) worst = r;
            }
            rel[nb++] = worst;
            if (worst > top) {
                top = worst;
                at[0] = bx * BS;
                at[1] = by * BS;
            }
        }
    if (nb) {
        *p99 = gr_ref_percentile(rel, nb, 0.99);
        q[2] = gr_ref_percentile(rel, nb, 1.0);
        q[1] = gr_ref_percentile(rel, nb, 0.95);
        q[0] = gr_ref_percentile(rel, nb, 0.5);
    }
    free(rel);
    free(m);
}

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
    char key[64], buf[512];
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
    for (int c = 0; c < 3; c++) { /* per channel (issue 30): the same figures for R, G and B */
        snprintf(key, sizeof key, "godrays:frac_pixels_stderr_le_1pct.%c", "RGB"[c]);
        SET(gr_meta_set_double(m, key, e->ch_frac_1pct[c]));
        snprintf(key, sizeof key, "godrays:rel_stderr_mean.%c", "RGB"[c]);
        SET(gr_meta_set_double(m, key, finite_or(e->ch_rel_mean[c], -1.0)));
        snprintf(key, sizeof key, "godrays:rel_stderr_p95.%c", "RGB"[c]);
        SET(gr_meta_set_double(m, key, finite_or(e->ch_rel_p95[c], -1.0)));
    }
    /* 8 x 8 block noise (block_noise): median, 95th percentile, worst block */
    SET(gr_meta_set_double(m, "godrays:block8_rel_stderr_median", e->block8[0]));
    SET(gr_meta_set_double(m, "godrays:block8_rel_stderr_p95", e->block8[1]));
    SET(gr_meta_set_double(m, "godrays:block8_rel_stderr_p99", e->block8_p99));
    SET(gr_meta_set_double(m, "godrays:block8_rel_stderr_max", e->block8[2]));
    SET(gr_meta_set_int(m, "godrays:block8_rel_stderr_max_x", e->block8_at[0]));
    SET(gr_meta_set_int(m, "godrays:block8_rel_stderr_max_y", e->block8_at[1]));
    SET(gr_meta_set_double(m, "godrays:cutoff_distance_m", r->cutoff_d));
    SET(gr_meta_set_double(m, "godrays:preview_exposure", out->preview_exposure));
    SET(gr_meta_set_double(m, "godrays:queries_per_s", qps));
    SET(gr_meta_set_double(m, "godrays:beam_build_s", r->tally.beam_build_s));
    char top[48] = "";
    if (r->region.has_top) snprintf(top, sizeof top, " y_top %.3f", r->region.y_top);
    snprintf(buf, sizeof buf, "u [%.3f, %.3f] w [%.3f, %.3f] y_min %.3f%s pad %.3f (local sheared, m)", r->region.u0,
             r->region.u1, r->region.w0, r->region.w1, r->region.y_min, top, r->pad);
    SET(gr_meta_set_string(m, "godrays:lit_region", buf));
    if (r->have_main_beams) {
        const gr_ref_sums *bs = &r->tally;
        SET(gr_meta_set_double(m, "godrays:surface_cell_m", bs->beam_cell_m));
        SET(gr_meta_set_int(m, "godrays:beam_prims", bs->beam_prims));
        if (bs->beam_refine_factor > 1) { /* local refinement (docs/reference.md 2.2) */
            snprintf(buf, sizeof buf, "camera rays within %g deg of +-T0: factor %d within %.3f m of P_s, %lld cells refined, "
                     "%lld transition cells, %lld triangles; the other rays: the plain grid",
                     r->set.refine_angle_deg, bs->beam_refine_factor, bs->beam_refine_radius_m, bs->beam_refined_cells,
                     bs->beam_transition_cells, bs->beam_triangles);
            SET(gr_meta_set_string(m, "godrays:surface_refine", buf));
        }
        /* the plain grid's cells across the shortest wave, and the refinement near the camera
         * they call for (docs/reference.md 2.2, "Near the camera") */
        if (r->near_cpw > 0.0) SET(gr_meta_set_double(m, "godrays:surface_cells_per_wave", r->near_cpw));
        if (bs->beam_near_factor > 1) {
            snprintf(buf, sizeof buf, "plain grid %.2f cells across the shortest wave (%g m), under %g: factor %d within %.3f m of "
                     "P_s (%g cells), %lld cells refined, %lld transition cells, %lld triangles",
                     r->near_cpw, r->near_lambda, r->set.near_cells_per_wavelength, bs->beam_near_factor,
                     bs->beam_near_radius_m, r->set.near_radius_cells, bs->beam_near_cells, bs->beam_near_transition_cells,
                     bs->beam_near_triangles);
            SET(gr_meta_set_string(m, "godrays:surface_refine_near", buf));
        }
    }
    /* bias next to the noise (docs/reference.md section 4): the surface tessellation is the
     * only discretization bias; measured on this scene by the probe (gr_ref_probe_run, probe.c) */
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
                 "%.2f, measured order %.2f (clamped to [1, 2]), %.2f s%s",
                 r->bias_probe_pixels, PROBE_STRIDE, r->bias_probe_passes, r->set.surface_res,
                 r->set.surface_res / 2 > 2 ? r->set.surface_res / 2 : 2, r->set.surface_res / 4 > 2 ? r->set.surface_res / 4 : 2,
                 r->bias_ratio, r->bias_order, r->tally.probe_s,
                 r->near_F <= 1 ? ""
                 : gr_ref_probe_holds_near(r)
                     ? "; the cells near the camera held at their size there, and their own error from a fourth level "
                       "with them 2x finer (p = 2; p = 1 in the conservative figures)"
                     : "; the cells near the camera coarsened with the rest (under their target: leans high)");
    else
        snprintf(buf, sizeof buf, "not estimated (reference.bias_probe = false or interrupted); -1");
    SET(gr_meta_set_string(m, "godrays:bias_surface_probe", buf));
    /* where there is a near set: 1 when the probe held its cells at their size and measured their
     * own error with them 2x finer, 0 when it coarsened them with the rest (it leans high) */
    if (r->bias_rel >= 0.0 && !r->flat && r->near_F > 1)
        SET(gr_meta_set_int(m, "godrays:bias_probe_near_held", gr_ref_probe_holds_near(r)));
    /* per-block bias next to the mean's (bias.R/G/B channels; 10 x 10 pixel blocks) */
    SET(gr_meta_set_double(m, "godrays:bias_block_p95_rel", r->bias_px ? finite_or(r->bias_block_p95, -1.0) : (r->flat ? 0.0 : -1.0)));
    SET(gr_meta_set_int(m, "godrays:stderr_dof", r->batches - 1));
    /* adaptive steps (docs/reference.md 2.5): march steps per camera ray over the pixels, the
     * pilot's steps (0: no pilot, the same steps everywhere) and its share of the wall time */
    const gr_ref_sums *ty = &r->tally;
    SET(gr_meta_set_double(m, "godrays:steps_mean", out->steps_mean));
    SET(gr_meta_set_int(m, "godrays:steps_min", ty->steps_min));
    SET(gr_meta_set_int(m, "godrays:steps_max", ty->steps_max));
    /* where the cap (reference.steps) held the pilot's steps back: those pixels miss step_error */
    SET(gr_meta_set_double(m, "godrays:steps_capped_frac", out->steps_capped_frac));
    SET(gr_meta_set_double(m, "godrays:steps_wanted_mean_capped", out->steps_wanted_capped));
    SET(gr_meta_set_int(m, "godrays:pilot_steps", ty->pilot_steps));
    SET(gr_meta_set_double(m, "godrays:pilot_s", ty->pilot_s));
    SET(gr_meta_set_double(m, "godrays:pilot_share", out->wall_s > 0.0 ? ty->pilot_s / out->wall_s : 0.0));
    SET(gr_meta_set_string(m, "godrays:bias_note",
                           "bias_surface_rel_est = mean |pixel bias| / image mean, in the worst channel, from the surface tessellation "
                           "(measured here with order 2, see bias_surface_probe; bound = max(2x the estimate, the figure with "
                           "the measured order, bias_surface_rel_measured_order); bias.* channels and bias_block_p95_rel "
                           "use the measured order; march steps: unbiased (jittered strata; per-pixel counts "
                           "from an independent pilot), noise only; sun disc: convolved to first order, error "
                           "below 0.3 % L1 (sun_disc = sample: unbiased); cutoff: each ray's distance drops at most "
                           "transmittance_cutoff of each channel on flat water (camera and sun paths' attenuation; "
                           "docs/reference.md 1)"));
    SET(gr_meta_set_string(m, "godrays:error_bars",
                           r->bias_px ? "stderr.* channels: batch-mean spread (noise only; Student t with stderr_dof "
                                        "degrees of freedom); bias.* channels: the surface bias of the pixel's 5x5 block "
                                        "(signed Richardson estimate from the probe; |bias| + t stderr bounds the error)"
                                      : "stderr.* channels: batch-mean spread (noise only; Student t with stderr_dof "
                                        "degrees of freedom); discretization bias: docs/reference.md"));
#undef SET
    return st;
}

/* The render's phases (reference/phase.h), the statistics' own included: into the result and
 * the metadata (godrays:phase.NAME.wall_s, .cpu_s, .serial_s; godrays:serial_s, serial_fraction).
 * Nothing when not measured (assembled parts). */
static gr_status record_phases(gr_ref_renderer *r, gr_ref_result *out)
{
    if (!r->phases.on) return GR_OK;
    gr_ref_phases_switch(&r->phases, REF_PH_OTHER);
    gr_metadata *m = &out->meta;
    gr_status st = GR_OK;
    double wall = 0.0, serial = 0.0, cpu = 0.0;
    char key[64];
    out->phases = 1;
    for (int i = 0; i < REF_PH_COUNT; i++) {
        double w = r->phases.wall_s[i], s = fmax(0.0, w - r->phases.par_s[i]);
        out->phase_wall_s[i] = w;
        out->phase_cpu_s[i] = r->phases.cpu_s[i];
        out->phase_serial_s[i] = s;
        wall += w;
        serial += s;
        cpu += r->phases.cpu_s[i];
        snprintf(key, sizeof key, "godrays:phase.%s.wall_s", gr_ref_phase_names[i]);
        if (st == GR_OK) st = gr_meta_set_double(m, key, w);
        snprintf(key, sizeof key, "godrays:phase.%s.cpu_s", gr_ref_phase_names[i]);
        if (st == GR_OK) st = gr_meta_set_double(m, key, r->phases.cpu_s[i]);
        snprintf(key, sizeof key, "godrays:phase.%s.serial_s", gr_ref_phase_names[i]);
        if (st == GR_OK) st = gr_meta_set_double(m, key, s);
    }
    out->serial_frac = wall > 0.0 ? serial / wall : 0.0;
    if (st == GR_OK) st = gr_meta_set_double(m, "godrays:phases_wall_s", wall);
    if (st == GR_OK) st = gr_meta_set_double(m, "godrays:phases_cpu_s", cpu);
    if (st == GR_OK) st = gr_meta_set_double(m, "godrays:serial_s", serial);
    if (st == GR_OK) st = gr_meta_set_double(m, "godrays:serial_fraction", out->serial_frac);
    return st;
}

gr_status gr_ref_finish(gr_ref_renderer *r, const ref_accum *acc, const ref_march_totals *tot, double wall_s,
                        gr_ref_result *out, gr_error *err)
{
    gr_ref_phases_switch(&r->phases, REF_PH_STATS);
    size_t np = (size_t)acc->W * acc->H;
    int P = r->passes_per_round;
    ref_errors e;
    memset(&e, 0, sizeof e);
    gr_status st = GR_OK;
    gr_status est = GR_OK;
    r->phases.par_total += gr_ref_image_errors(acc, r->threads, 1, &e, &est);
    if (est != GR_OK) st = gr_fail(err, GR_E_NOMEM, "reference: out of memory");
    if (st == GR_OK) st = build_image(r, acc, out, err);
    if (st != GR_OK) return st;
    gr_ref_block_bias(r, out->image);
    out->bias_block_p95 = r->bias_block_p95;
    out->target_met = r->set.target_error > 0.0 ? gr_ref_target_met(&e, acc->B, r->set.target_error) : 1;
    out->wall_s = wall_s;
    out->rel_se_mean = e.rel_mean;
    out->rel_se_p95 = e.rel_p95;
    out->frac_se_1pct = e.frac_1pct;
    out->block8_rel_se_max = e.block8[2];
    out->queries_per_s = tot->march_s > 0.0 ? (double)tot->queries / tot->march_s : 0.0;
    out->shadow_rays_per_s = tot->march_s > 0.0 ? (double)tot->shadows / tot->march_s : 0.0;
    out->beam_build_s = r->tally.beam_build_s;
    out->bias_surface_rel = r->bias_rel;
    out->steps_mean = r->tally.steps_pixels > 0.0 ? r->tally.steps_sum / r->tally.steps_pixels : -1.0;
    out->steps_capped_frac = r->tally.steps_pixels > 0.0 ? r->tally.steps_capped / r->tally.steps_pixels : 0.0;
    out->steps_wanted_capped = r->tally.steps_capped > 0.0 ? r->tally.steps_wanted_sum / r->tally.steps_capped : 0.0;
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
        double p99 = gr_ref_percentile(v, np, 0.99);
        if (p99 > 0.0 && isfinite(p99)) out->preview_exposure = 0.8 / p99;
        free(v);
    }
    if (fill_metadata(r, out, &e, out->queries_per_s) != GR_OK)
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for metadata");
    gr_meta_set_double(&out->meta, "godrays:shadow_rays_per_s", out->shadow_rays_per_s);
    /* the most beams at one march point (the list grows; -1: not carried through parts) */
    gr_meta_set_int(&out->meta, "godrays:beam_max_hits", tot->max_hits);
    return record_phases(r, out) == GR_OK ? GR_OK : gr_fail(err, GR_E_NOMEM, "reference: out of memory for metadata");
}
