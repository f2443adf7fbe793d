/* The march (internal to reference/): the camera rays of a pass, marched through the beams
 * (docs/reference.md 2.3-2.5), and the sunlight at a point. The hot helpers stay static
 * inline here so that the march's loop keeps them inlined. */
#ifndef GR_REF_MARCH_H
#define GR_REF_MARCH_H

#include <stdlib.h>
#include "reference/renderer.h"

typedef struct ref_counters { long long queries, shadow_rays, max_hits; } ref_counters;

/* Per-thread scratch memory of the march. */
typedef struct ref_scratch {
    gr_beam_hits hits;   /* grow as needed */
    ref_light *lights;
    int lcap;
    double *t;     /* march points along the ray (m) */
    double *w;     /* their weights, with a steps allocation along the ray */
    float *tf;     /* the same in float, as the points are placed */
} ref_scratch;
/* For up to `steps` march points; 0, or -1 when out of memory. */
int gr_ref_scratch_alloc(ref_scratch *sc, int steps);
void gr_ref_scratch_free(ref_scratch *sc);

/* Sunlight arriving at the local point x: every beam through it under waves, the closed
 * form on flat water (and outside the lit region, where the waves' mean is used). The
 * lists grow as needed (no beam is ever dropped); returns the number of lights in
 * *lights, or -1 when out of memory. */
static inline int light_at(const gr_ref_renderer *r, const gr_beams *bs, gr_vec3 x, ref_light **lights, int *lcap, gr_beam_hits *hits)
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
        if (x.y >= g->y_min && (!g->has_top || x.y <= g->y_top) && u >= g->u0 && u <= g->u1 && w >= g->w0 &&
            w <= g->w1) {
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

/* L (RGB) of one camera sample: n march steps (n <= the scratch's) shared by the nrays
 * (1..REF_MAX_RAYS) camera rays through the image points (fx[i], fy[i]) (pixels), stratum k
 * on ray k mod nrays; *trans and *len are the rays' mean transmittance and length. With ck,
 * ck[3 k + c] receives channel c of march point k's contribution to L (the step pilot).
 * anti: every stratum's jitter moved by half a stratum (mod one), the second of an antithetic
 * pair drawing the first's numbers (docs/reference.md 2.5, "Antithetic pairs").
 * Returns 0, or -1 when out of memory (a growing hit list). */
int gr_ref_march_ray(const gr_ref_renderer *r, int nrays, const double *fx, const double *fy, int n, const uint16_t *alloc,
                     int anti, ref_rng *g, double L[3], double *trans, double *len, ref_counters *cnt, ref_scratch *sc,
                     double *ck);

typedef struct ref_march_totals { double march_s; long long queries, shadows, max_hits; } ref_march_totals;

/* Marches one pass over the rows [y0, y1) of acc with the pool's workers, the progress bar
 * going from frac0 to frac0 + span; its time and counters are added to tot. Accumulator pixel
 * (x, y) is image pixel (x stride + off, y stride + off). *complete = 0 when interrupted. */
gr_status gr_ref_march_pass(gr_ref_renderer *r, ref_accum *acc, int pass, int batch, int stride, int off, int y0, int y1,
                            gr_ref_pool *pool, gr_progress *prog, double frac0, double span, const char *note,
                            ref_march_totals *tot, int *complete, gr_error *err);

#endif
