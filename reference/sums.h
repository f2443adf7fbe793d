/* The raw sums of a ground-truth render (gr_ref_sums) and the one table that describes
 * their fields: what a part file carries (src/farm/parts.h writes and reads the table's
 * scalars as header keys and its arrays as the payload), how the parts' values merge, and
 * which scalars the renderer tallies (gr_ref_assemble takes them back through the same
 * table). A field added to gr_ref_sums gets one row in gr_ref_sums_fields, nothing else. */
#ifndef GR_REF_SUMS_H
#define GR_REF_SUMS_H

#include <stddef.h>
#include <stdint.h>

/* The raw sums a render's image, error bars and statistics are computed from: per pixel and
 * batch the RGB sums of the camera samples and their count, and the surface-bias probe's
 * sparse accumulators (surface_res, surface_res / 2, surface_res / 4). gr_ref_assemble turns
 * full sums back into the result a single render gives, bit for bit (src/farm/parts.h merges
 * them). */
#define GR_REF_PROBE_MAX_LEVELS 4
typedef struct gr_ref_sums {
    int W, H, B;            /* image size, batches */
    double *sum;            /* [(pixel * B + batch) * 3 + c] */
    uint32_t *count;        /* [pixel * B + batch] */
    int passes;             /* main passes done (every batch) */
    int probe;              /* 1: the probe ran (the probe_* fields are set) */
    int probe_w, probe_h, probe_stride, probe_off, probe_passes;
    int probe_levels;       /* its accumulators: surface_res, surface_res / 2 (, ...) */
    double *probe_sum[GR_REF_PROBE_MAX_LEVELS];   /* [probe pixel * 3 + c] per level */
    uint32_t *probe_count[GR_REF_PROBE_MAX_LEVELS];
    double probe_s;         /* probe time */
    double beam_cell_m;     /* the main passes' last beam set (0: none) */
    long long beam_prims;
    /* its local refinement (docs/reference.md 2.2; factor 1: none) */
    int beam_refine_factor;
    double beam_refine_radius_m;
    long long beam_refined_cells, beam_transition_cells, beam_triangles;
    /* the plain set's refinement near the camera (docs/reference.md 2.2; factor 1: none) */
    int beam_near_factor;
    double beam_near_radius_m;
    long long beam_near_cells, beam_near_transition_cells, beam_near_triangles;
    double beam_build_s, march_s;
    long long queries, shadows, overflows;
    /* adaptive steps (docs/reference.md 2.5): the sum of the pixels' march steps over the
     * pixels counted, their extremes, the pilot's steps (0: none) and time */
    double steps_sum, steps_pixels;
    /* the pixels whose pilot asked for more than the cap (reference.steps: they take the cap and
     * miss step_error) and the steps those asked for, summed (each at most 65536) */
    double steps_capped, steps_wanted_sum;
    int steps_min, steps_max, pilot_steps;
    double pilot_s;
} gr_ref_sums;
/* Zeroed sums; probe_levels accumulators of probe_w x probe_h (0: none). NULL if no memory. */
gr_ref_sums *gr_ref_sums_create(int W, int H, int B, int probe_levels, int probe_w, int probe_h);
void gr_ref_sums_destroy(gr_ref_sums *s); /* accepts NULL */

/* ---- the table ---- */
typedef enum gr_ref_sums_type { GR_SUMS_INT, GR_SUMS_LLONG, GR_SUMS_DOUBLE, GR_SUMS_U32 } gr_ref_sums_type;
typedef enum gr_ref_sums_shape {
    GR_SUMS_SCALAR,         /* one value */
    GR_SUMS_PIXEL_BATCH,    /* an array: `per` values per (pixel, batch), [(pixel * B + batch) * per + i] */
    GR_SUMS_PROBE_PIXEL     /* one array per probe level: `per` values per probe pixel */
} gr_ref_sums_shape;
/* How a scalar of several parts merges (every part is one rectangle of rows x batches). */
typedef enum gr_ref_sums_rule {
    GR_SUMS_SIZE,           /* a size: the same in every part (gr_ref_sums_create sets it) */
    GR_SUMS_PROBE,          /* the probe's layout: from the parts that ran it */
    GR_SUMS_ADD,            /* added up over every part */
    GR_SUMS_ADD_PROBE,      /* added up over the parts that ran the probe */
    GR_SUMS_ADD_ROW0,       /* added up over the parts holding row 0 (each batch range once) */
    GR_SUMS_ADD_BATCH0,     /* added up over the parts holding batch 0 (each row range once) */
    GR_SUMS_MIN_BATCH0,     /* the least over the parts holding batch 0 */
    GR_SUMS_MAX_BATCH0,     /* the largest over the parts holding batch 0 */
    GR_SUMS_LAST,           /* the part holding row 0 and the last batch's (the last beam set) */
    GR_SUMS_ANY             /* the same in every part (from the settings): the last part's */
} gr_ref_sums_rule;
typedef struct gr_ref_sums_field {
    const char *name;       /* the part file's header key (scalars) */
    size_t offset;          /* in gr_ref_sums: the value, the array pointer, or the first level's */
    gr_ref_sums_type type;  /* of a value (an array's elements) */
    gr_ref_sums_shape shape;
    int per;                /* arrays: values per element (3: RGB) */
    gr_ref_sums_rule rule;  /* scalars: the merge; SIZE and PROBE are layout, the rest tallies */
} gr_ref_sums_field;
extern const gr_ref_sums_field gr_ref_sums_fields[];
extern const size_t gr_ref_sums_nfields;

/* A scalar field's value as a double (exact for every value a render produces) and back
 * (converted to the field's type). */
double gr_ref_sums_get(const gr_ref_sums *s, const gr_ref_sums_field *f);
void gr_ref_sums_set(gr_ref_sums *s, const gr_ref_sums_field *f, double v);
/* 1: f is a tally (a counter or a time the renderer keeps, not a size or the probe's layout). */
int gr_ref_sums_is_tally(const gr_ref_sums_field *f);
/* Every tally of src into dst (arrays, sizes and the probe's layout untouched). */
void gr_ref_sums_copy_tallies(gr_ref_sums *dst, const gr_ref_sums *src);
/* The bytes of one element of an array field (per values). */
size_t gr_ref_sums_elem_bytes(const gr_ref_sums_field *f);
/* Array field f of s: its (first) array; level k of a probe array. */
void *gr_ref_sums_array(const gr_ref_sums *s, const gr_ref_sums_field *f, int k);

/* A part of the work: image rows [row0, row1), batches [batch0, batch1), and the probe rows
 * [probe_row0, probe_row1) it carries (probe = 1: it ran the probe). */
typedef struct gr_ref_sums_rect {
    int row0, row1, batch0, batch1;
    int probe, probe_row0, probe_row1;
} gr_ref_sums_rect;
/* Merges a part's scalars (part: its header's values; rect: its rectangle) into dst by the
 * table's rules; parts merge in the caller's order (the same sums, the same bytes).
 * *batch0_parts counts the parts holding batch 0 merged so far (0 before the first). */
void gr_ref_sums_merge_scalars(gr_ref_sums *dst, const gr_ref_sums *part, const gr_ref_sums_rect *rect,
                               int *batch0_parts);

/* First probe row at or below image row `row` (probe rows are y stride + off, h of them):
 * the probe rows of a part's image rows. */
int gr_ref_probe_row(int row, int stride, int off, int h);

#endif
