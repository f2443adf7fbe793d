#include "reference/sums.h"

#include <stdlib.h>
#include <string.h>

#define SCALAR(name, field, type, rule) {name, offsetof(gr_ref_sums, field), type, GR_SUMS_SCALAR, 1, rule}
#define ARRAY(name, field, type, shape, per) {name, offsetof(gr_ref_sums, field), type, shape, per, GR_SUMS_SIZE}

/* Every field of gr_ref_sums. The arrays' order is the part files' payload order (per pixel
 * and batch: sum, then count; per probe level: sum, then count); the scalars' names are their
 * header keys (docs/farm.md). */
const gr_ref_sums_field gr_ref_sums_fields[] = {
    SCALAR("width", W, GR_SUMS_INT, GR_SUMS_SIZE),
    SCALAR("height", H, GR_SUMS_INT, GR_SUMS_SIZE),
    SCALAR("batches", B, GR_SUMS_INT, GR_SUMS_SIZE),
    ARRAY("sum", sum, GR_SUMS_DOUBLE, GR_SUMS_PIXEL_BATCH, 3),
    ARRAY("count", count, GR_SUMS_U32, GR_SUMS_PIXEL_BATCH, 1),
    /* passes: every batch's passes, counted once per batch (the parts holding row 0) */
    SCALAR("passes", passes, GR_SUMS_INT, GR_SUMS_ADD_ROW0),
    SCALAR("probe", probe, GR_SUMS_INT, GR_SUMS_PROBE),
    SCALAR("probe_levels", probe_levels, GR_SUMS_INT, GR_SUMS_SIZE),
    SCALAR("probe_w", probe_w, GR_SUMS_INT, GR_SUMS_SIZE),
    SCALAR("probe_h", probe_h, GR_SUMS_INT, GR_SUMS_SIZE),
    SCALAR("probe_stride", probe_stride, GR_SUMS_INT, GR_SUMS_PROBE),
    SCALAR("probe_off", probe_off, GR_SUMS_INT, GR_SUMS_PROBE),
    SCALAR("probe_passes", probe_passes, GR_SUMS_INT, GR_SUMS_PROBE),
    ARRAY("probe_sum", probe_sum, GR_SUMS_DOUBLE, GR_SUMS_PROBE_PIXEL, 3),
    ARRAY("probe_count", probe_count, GR_SUMS_U32, GR_SUMS_PROBE_PIXEL, 1),
    SCALAR("probe_s", probe_s, GR_SUMS_DOUBLE, GR_SUMS_ADD_PROBE),
    /* the main passes' last beam set: the last batch's */
    SCALAR("beam_cell_m", beam_cell_m, GR_SUMS_DOUBLE, GR_SUMS_LAST),
    SCALAR("beam_prims", beam_prims, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_refine_factor", beam_refine_factor, GR_SUMS_INT, GR_SUMS_LAST),
    SCALAR("beam_refine_radius_m", beam_refine_radius_m, GR_SUMS_DOUBLE, GR_SUMS_LAST),
    SCALAR("beam_refined_cells", beam_refined_cells, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_transition_cells", beam_transition_cells, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_triangles", beam_triangles, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_near_factor", beam_near_factor, GR_SUMS_INT, GR_SUMS_LAST),
    SCALAR("beam_near_radius_m", beam_near_radius_m, GR_SUMS_DOUBLE, GR_SUMS_LAST),
    SCALAR("beam_near_cells", beam_near_cells, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_near_transition_cells", beam_near_transition_cells, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_near_triangles", beam_near_triangles, GR_SUMS_LLONG, GR_SUMS_LAST),
    SCALAR("beam_build_s", beam_build_s, GR_SUMS_DOUBLE, GR_SUMS_ADD),
    SCALAR("march_s", march_s, GR_SUMS_DOUBLE, GR_SUMS_ADD),
    SCALAR("queries", queries, GR_SUMS_LLONG, GR_SUMS_ADD),
    SCALAR("shadows", shadows, GR_SUMS_LLONG, GR_SUMS_ADD),
    SCALAR("overflows", overflows, GR_SUMS_LLONG, GR_SUMS_ADD),
    /* adaptive steps: every part with the same rows has the same steps (the pilot depends on
     * the seed and the pixel only): each row range once, from its batch-0 part */
    SCALAR("steps_sum", steps_sum, GR_SUMS_DOUBLE, GR_SUMS_ADD_BATCH0),
    SCALAR("steps_pixels", steps_pixels, GR_SUMS_DOUBLE, GR_SUMS_ADD_BATCH0),
    SCALAR("steps_capped", steps_capped, GR_SUMS_DOUBLE, GR_SUMS_ADD_BATCH0),
    SCALAR("steps_wanted_sum", steps_wanted_sum, GR_SUMS_DOUBLE, GR_SUMS_ADD_BATCH0),
    SCALAR("steps_min", steps_min, GR_SUMS_INT, GR_SUMS_MIN_BATCH0),
    SCALAR("steps_max", steps_max, GR_SUMS_INT, GR_SUMS_MAX_BATCH0),
    SCALAR("pilot_steps", pilot_steps, GR_SUMS_INT, GR_SUMS_ANY),
    SCALAR("pilot_s", pilot_s, GR_SUMS_DOUBLE, GR_SUMS_ADD),
};
const size_t gr_ref_sums_nfields = sizeof gr_ref_sums_fields / sizeof gr_ref_sums_fields[0];

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

static void *at(const gr_ref_sums *s, const gr_ref_sums_field *f) { return (char *)s + f->offset; }

static size_t type_bytes(gr_ref_sums_type t)
{
    return t == GR_SUMS_INT ? sizeof(int) : t == GR_SUMS_LLONG ? sizeof(long long) : t == GR_SUMS_U32 ? sizeof(uint32_t)
                                                                                                      : sizeof(double);
}

double gr_ref_sums_get(const gr_ref_sums *s, const gr_ref_sums_field *f)
{
    const void *p = at(s, f);
    switch (f->type) {
    case GR_SUMS_INT: return *(const int *)p;
    case GR_SUMS_LLONG: return (double)*(const long long *)p;
    case GR_SUMS_U32: return *(const uint32_t *)p;
    default: return *(const double *)p;
    }
}

void gr_ref_sums_set(gr_ref_sums *s, const gr_ref_sums_field *f, double v)
{
    void *p = at(s, f);
    switch (f->type) {
    case GR_SUMS_INT: *(int *)p = (int)v; break;
    case GR_SUMS_LLONG: *(long long *)p = (long long)v; break;
    case GR_SUMS_U32: *(uint32_t *)p = (uint32_t)v; break;
    default: *(double *)p = v; break;
    }
}

int gr_ref_sums_is_tally(const gr_ref_sums_field *f)
{
    return f->shape == GR_SUMS_SCALAR && f->rule != GR_SUMS_SIZE && f->rule != GR_SUMS_PROBE;
}

void gr_ref_sums_copy_tallies(gr_ref_sums *dst, const gr_ref_sums *src)
{
    for (size_t i = 0; i < gr_ref_sums_nfields; i++) {
        const gr_ref_sums_field *f = &gr_ref_sums_fields[i];
        if (!gr_ref_sums_is_tally(f)) continue;
        memcpy(at(dst, f), at(src, f), type_bytes(f->type));
    }
}

size_t gr_ref_sums_elem_bytes(const gr_ref_sums_field *f)
{
    return type_bytes(f->type) * (size_t)f->per;
}

void *gr_ref_sums_array(const gr_ref_sums *s, const gr_ref_sums_field *f, int k)
{
    return ((void *const *)at(s, f))[f->shape == GR_SUMS_PROBE_PIXEL ? k : 0];
}

/* dst's field += part's, in the field's own type (integer sums stay exact). */
static void add(gr_ref_sums *dst, const gr_ref_sums *part, const gr_ref_sums_field *f)
{
    void *d = at(dst, f);
    const void *p = at(part, f);
    switch (f->type) {
    case GR_SUMS_INT: *(int *)d += *(const int *)p; break;
    case GR_SUMS_LLONG: *(long long *)d += *(const long long *)p; break;
    case GR_SUMS_U32: *(uint32_t *)d += *(const uint32_t *)p; break;
    default: *(double *)d += *(const double *)p; break;
    }
}

void gr_ref_sums_merge_scalars(gr_ref_sums *dst, const gr_ref_sums *part, const gr_ref_sums_rect *rect,
                               int *batch0_parts)
{
    const int batch0 = rect->batch0 == 0, first0 = batch0 && *batch0_parts == 0;
    for (size_t i = 0; i < gr_ref_sums_nfields; i++) {
        const gr_ref_sums_field *f = &gr_ref_sums_fields[i];
        if (f->shape != GR_SUMS_SCALAR) continue;
        double v = gr_ref_sums_get(part, f);
        switch (f->rule) {
        case GR_SUMS_SIZE: break;
        case GR_SUMS_PROBE: if (rect->probe) gr_ref_sums_set(dst, f, v); break;
        case GR_SUMS_ADD: add(dst, part, f); break;
        case GR_SUMS_ADD_PROBE: if (rect->probe) add(dst, part, f); break;
        case GR_SUMS_ADD_ROW0: if (rect->row0 == 0) add(dst, part, f); break;
        case GR_SUMS_ADD_BATCH0: if (batch0) add(dst, part, f); break;
        case GR_SUMS_MIN_BATCH0: if (batch0 && (first0 || v < gr_ref_sums_get(dst, f))) gr_ref_sums_set(dst, f, v); break;
        case GR_SUMS_MAX_BATCH0: if (batch0 && v > gr_ref_sums_get(dst, f)) gr_ref_sums_set(dst, f, v); break;
        case GR_SUMS_LAST: if (rect->batch1 == dst->B && rect->row0 == 0) gr_ref_sums_set(dst, f, v); break;
        case GR_SUMS_ANY: gr_ref_sums_set(dst, f, v); break;
        }
    }
    if (batch0) (*batch0_parts)++;
}

int gr_ref_probe_row(int row, int stride, int off, int h)
{
    int y = row <= off ? 0 : (row - off + stride - 1) / stride;
    return y < h ? y : h;
}
