/* The surface-bias probe (internal to reference/; docs/reference.md section 4): a sparse grid
 * of pixels rendered again with coarser surface tessellations, the bias at the render's
 * resolution by Richardson extrapolation, per pixel (the bias.* channels) and over blocks. */
#ifndef GR_REF_PROBE_H
#define GR_REF_PROBE_H

#include "reference/march.h"
#include "reference/renderer.h"

/* The probe's figures from its nl per-level sums (np probe pixels, [pixel * 3 + c]; level k < 3
 * has cells 2^k h; a fourth level, where the probe holds the near set's cells, is h with those
 * cells 2x finer): the estimate (order 2), the figure with the measured order, the order, and
 * the per-pixel signed estimates (bias channels). Shared by gr_ref_render and
 * gr_ref_assemble, so that merged parts give the same bytes. 0, or -1 when out of memory. */
int gr_ref_probe_stats(gr_ref_renderer *r, double *const sum[], uint32_t *const cnt[], int nl, size_t np, int pw, int ph,
                       int off);
/* The probe's pixel grid: its offset in the image and its size. */
void gr_ref_probe_grid(const gr_ref_renderer *r, int *off, int *pw, int *ph);
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
/* Whether the probe's coarser levels keep the cells near the camera (docs/reference.md 2.2,
 * "Near the camera") at their size at h (factor near_F 2^k at level k over the same disc) and
 * a fourth level measures their own error (h with factor 2 near_F): where the near set reaches
 * its near_cells_per_wavelength. Halving those cells would take them past the point where a
 * wave has too few cells to be seen, and Richardson's extrapolation from there reads 3-30x high
 * (docs/reference.md 4, "The probe and the cells near the camera"); where the cap
 * (near_max_factor) keeps them short of the target, they are coarsened with the rest (the
 * figure then leans high, never low). */
int gr_ref_probe_holds_near(const gr_ref_renderer *r);
/* One probe level's march of pass `pass` (its sets prepared) over the probe pixels (every
 * PROBE_STRIDE-th pixel from the grid's offset `off`, gr_ref_probe_grid) in the part's rows,
 * into a (batch 0): the one call of the probe's own passes and of the fourth level the main
 * passes take (gr_ref_render), so both give the same sums. */
gr_status gr_ref_probe_march(gr_ref_renderer *r, ref_accum *a, int pass, int off, gr_ref_pool *pool, gr_progress *prog,
                             double frac0, double span, const char *note, ref_march_totals *tot, int *complete,
                             gr_error *err);
/* The probe's passes over the part's rows (the first min(passes per round, PROBE_PASSES)),
 * level h taken from `captured` and the fourth level from `captured_fine` when the main
 * passes took all of it (gr_ref_render); with keep, its sums are handed over. The progress bar goes from frac0 to frac0 + span. */
gr_status gr_ref_probe_run(gr_ref_renderer *r, gr_ref_sums *keep, ref_accum *captured, ref_accum *captured_fine,
                           gr_ref_pool *pool, gr_progress *prog, double frac0, double span, ref_march_totals *tot,
                           gr_error *err);

/* The surface-bias estimate of image pixel (x, y), channel c: that of its probe pixel (the
 * PROBE_STRIDE x PROBE_STRIDE block it lies in). */
static inline float bias_at(const gr_ref_renderer *r, int x, int y, int c)
{
    int i = x / PROBE_STRIDE, j = y / PROBE_STRIDE;
    if (i >= r->bias_pw) i = r->bias_pw - 1;
    if (j >= r->bias_ph) j = r->bias_ph - 1;
    return r->bias_px[((size_t)j * r->bias_pw + (size_t)i) * 3 + c];
}

/* Block bias: over blocks of 2 x 2 probe pixels (10 x 10 image pixels), the mean of the probe
 * pixels' signed estimates relative to max(block mean, image mean) (the same normalization as
 * the 1 % standard-error figure), in the block's worst channel (channels with less than 1e-3
 * of the brightest one's light left out); the 95th percentile of its magnitude. The probe's
 * residual noise enters the magnitude: an overestimate, not an underestimate. */
void gr_ref_block_bias(gr_ref_renderer *r, const gr_image *img);

#endif
