/* The table of the raw sums' fields (reference/sums.h), against expectations written here:
 * (a) every scalar key a part file's header has carried maps to the gr_ref_sums member of
 *     that meaning (values set through the table land in the members named here, and back);
 *     every member is in the table once (no two rows share an offset);
 * (b) the merge rules, on three hand-made parts of a 4-row, 2-batch render: rows [0, 2)
 *     batch 0 (with the probe), rows [2, 4) batch 0 (with the probe), rows [0, 4) batch 1:
 *     the totals a single render of the whole would tally, worked out by hand;
 * (c) copying the tallies leaves the sizes, the probe's layout and the arrays alone. */
#include <string.h>
#include "check.h"
#include "reference/sums.h"

static const gr_ref_sums_field *field(const char *name)
{
    for (size_t i = 0; i < gr_ref_sums_nfields; i++)
        if (strcmp(gr_ref_sums_fields[i].name, name) == 0) return &gr_ref_sums_fields[i];
    return NULL;
}

static void set(gr_ref_sums *s, const char *name, double v)
{
    const gr_ref_sums_field *f = field(name);
    CHECK_MSG(f != NULL, "no field %s", name);
    if (f) gr_ref_sums_set(s, f, v);
}

static void test_members(void)
{
    gr_ref_sums s;
    memset(&s, 0, sizeof s);
    /* the part file's header keys (docs/farm.md) and distinct values */
    static const char *const keys[] = {"width", "height", "batches", "passes", "probe", "probe_levels", "probe_w",
                                       "probe_h", "probe_stride", "probe_off", "probe_passes", "probe_s", "beam_cell_m",
                                       "beam_prims", "beam_refine_factor", "beam_refine_radius_m", "beam_refined_cells",
                                       "beam_transition_cells", "beam_triangles", "beam_build_s", "march_s", "queries",
                                       "shadows", "overflows", "steps_sum", "steps_pixels", "steps_min", "steps_max",
                                       "pilot_steps", "pilot_s", "steps_capped", "steps_wanted_sum", "beam_near_factor",
                                       "beam_near_radius_m", "beam_near_cells", "beam_near_transition_cells",
                                       "beam_near_triangles"};
    const size_t nk = sizeof keys / sizeof keys[0];
    for (size_t i = 0; i < nk; i++) set(&s, keys[i], 10.0 + (double)i);
    CHECK(s.W == 10 && s.H == 11 && s.B == 12 && s.passes == 13 && s.probe == 14 && s.probe_levels == 15);
    CHECK(s.probe_w == 16 && s.probe_h == 17 && s.probe_stride == 18 && s.probe_off == 19 && s.probe_passes == 20);
    CHECK(s.probe_s == 21.0 && s.beam_cell_m == 22.0 && s.beam_prims == 23 && s.beam_refine_factor == 24);
    CHECK(s.beam_refine_radius_m == 25.0 && s.beam_refined_cells == 26 && s.beam_transition_cells == 27);
    CHECK(s.beam_triangles == 28 && s.beam_build_s == 29.0 && s.march_s == 30.0 && s.queries == 31);
    CHECK(s.shadows == 32 && s.overflows == 33 && s.steps_sum == 34.0 && s.steps_pixels == 35.0);
    CHECK(s.steps_min == 36 && s.steps_max == 37 && s.pilot_steps == 38 && s.pilot_s == 39.0);
    CHECK(s.steps_capped == 40.0 && s.steps_wanted_sum == 41.0);
    CHECK(s.beam_near_factor == 42 && s.beam_near_radius_m == 43.0 && s.beam_near_cells == 44);
    CHECK(s.beam_near_transition_cells == 45 && s.beam_near_triangles == 46);
    /* a 64-bit counter beyond int range survives */
    set(&s, "queries", 6e12);
    CHECK(s.queries == 6000000000000LL);
    CHECK(gr_ref_sums_get(&s, field("queries")) == 6e12);
    /* scalars: exactly these keys; arrays: sum and count per (pixel, batch), probe_sum and
     * probe_count per probe pixel and level; no offset twice */
    size_t nscalar = 0;
    for (size_t i = 0; i < gr_ref_sums_nfields; i++) {
        const gr_ref_sums_field *f = &gr_ref_sums_fields[i];
        nscalar += f->shape == GR_SUMS_SCALAR;
        for (size_t j = 0; j < i; j++) CHECK_MSG(gr_ref_sums_fields[j].offset != f->offset, "%s", f->name);
    }
    CHECK(nscalar == nk);
    CHECK(field("sum")->offset == offsetof(gr_ref_sums, sum) && field("sum")->shape == GR_SUMS_PIXEL_BATCH);
    CHECK(gr_ref_sums_elem_bytes(field("sum")) == 3 * sizeof(double));
    CHECK(field("count")->offset == offsetof(gr_ref_sums, count) && gr_ref_sums_elem_bytes(field("count")) == 4);
    CHECK(field("probe_sum")->offset == offsetof(gr_ref_sums, probe_sum) && field("probe_sum")->shape == GR_SUMS_PROBE_PIXEL);
    CHECK(field("probe_count")->offset == offsetof(gr_ref_sums, probe_count));
    gr_ref_sums *a = gr_ref_sums_create(2, 2, 2, 3, 1, 1);
    CHECK(a != NULL);
    if (a) {
        CHECK(gr_ref_sums_array(a, field("count"), 0) == (void *)a->count);
        CHECK(gr_ref_sums_array(a, field("probe_sum"), 2) == (void *)a->probe_sum[2]);
    }
    gr_ref_sums_destroy(a);
}

static void test_merge(void)
{
    gr_ref_sums *m = gr_ref_sums_create(3, 4, 2, 3, 1, 1);
    CHECK(m != NULL);
    if (!m) return;
    gr_ref_sums p[3];
    memset(p, 0, sizeof p);
    const gr_ref_sums_rect rc[3] = {{0, 2, 0, 1, 1, 0, 1}, {2, 4, 0, 1, 1, 1, 1}, {0, 4, 1, 2, 0, 0, 0}};
    /* passes: every batch's, from the parts holding row 0: 3 in batch 0, 3 in batch 1 */
    p[0].passes = 3; p[1].passes = 3; p[2].passes = 3;
    p[0].probe = p[1].probe = 1;
    p[0].probe_stride = p[1].probe_stride = 5;
    p[0].probe_off = p[1].probe_off = 2;
    p[0].probe_passes = p[1].probe_passes = 4;
    p[0].probe_s = 1.5; p[1].probe_s = 2.0; p[2].probe_s = 100.0; /* part 2 ran no probe */
    /* the last beam set: the part with row 0 and the last batch (part 2) */
    p[0].beam_cell_m = 0.1; p[1].beam_cell_m = 0.2; p[2].beam_cell_m = 0.3;
    p[0].beam_prims = 10; p[1].beam_prims = 20; p[2].beam_prims = 30;
    p[0].march_s = 1.0; p[1].march_s = 2.0; p[2].march_s = 4.0;
    p[0].queries = 5; p[1].queries = 6; p[2].queries = 7;
    /* steps: each row range once, from its batch-0 part: rows [0, 2) and [2, 4) */
    p[0].steps_sum = 60; p[0].steps_pixels = 6; p[0].steps_min = 8; p[0].steps_max = 12;
    p[1].steps_sum = 90; p[1].steps_pixels = 6; p[1].steps_min = 9; p[1].steps_max = 20;
    p[2].steps_sum = 150; p[2].steps_pixels = 12; p[2].steps_min = 1; p[2].steps_max = 99;
    p[0].steps_capped = 2; p[1].steps_capped = 3; p[2].steps_capped = 12;
    p[0].steps_wanted_sum = 200; p[1].steps_wanted_sum = 330; p[2].steps_wanted_sum = 9999;
    p[0].pilot_steps = p[1].pilot_steps = p[2].pilot_steps = 16;
    p[0].pilot_s = 0.5; p[1].pilot_s = 0.25; p[2].pilot_s = 0.125;
    int b0 = 0;
    for (int i = 0; i < 3; i++) gr_ref_sums_merge_scalars(m, &p[i], &rc[i], &b0);
    CHECK(b0 == 2);
    CHECK(m->W == 3 && m->H == 4 && m->B == 2 && m->probe_levels == 3); /* sizes untouched */
    CHECK(m->passes == 6);
    CHECK(m->probe == 1 && m->probe_stride == 5 && m->probe_off == 2 && m->probe_passes == 4);
    CHECK(m->probe_s == 3.5);
    CHECK(m->beam_cell_m == 0.3 && m->beam_prims == 30);
    CHECK(m->march_s == 7.0 && m->queries == 18);
    CHECK(m->steps_sum == 150.0 && m->steps_pixels == 12.0 && m->steps_min == 8 && m->steps_max == 20);
    CHECK(m->steps_capped == 5.0 && m->steps_wanted_sum == 530.0);
    CHECK(m->pilot_steps == 16 && m->pilot_s == 0.875);
    gr_ref_sums_destroy(m);
}

static void test_copy(void)
{
    gr_ref_sums *dst = gr_ref_sums_create(2, 3, 4, 3, 1, 2), src;
    CHECK(dst != NULL);
    if (!dst) return;
    double *sum = dst->sum;
    memset(&src, 0, sizeof src);
    src.W = 99; src.probe_w = 99; src.probe = 1; src.probe_stride = 7;
    src.passes = 5; src.beam_triangles = 1234567; src.steps_min = 3; src.pilot_s = 0.5; src.overflows = 2;
    gr_ref_sums_copy_tallies(dst, &src);
    CHECK(dst->W == 2 && dst->H == 3 && dst->B == 4 && dst->probe_w == 1 && dst->probe_h == 2);
    CHECK(dst->probe == 0 && dst->probe_stride == 0 && dst->sum == sum);
    CHECK(dst->passes == 5 && dst->beam_triangles == 1234567 && dst->steps_min == 3 && dst->pilot_s == 0.5);
    CHECK(dst->overflows == 2);
    gr_ref_sums_destroy(dst);
}

int main(void)
{
    test_members();
    test_merge();
    test_copy();
    CHECK(gr_ref_probe_row(0, 5, 2, 10) == 0 && gr_ref_probe_row(3, 5, 2, 10) == 1 && gr_ref_probe_row(7, 5, 2, 10) == 1);
    CHECK(gr_ref_probe_row(8, 5, 2, 10) == 2 && gr_ref_probe_row(90, 5, 2, 10) == 10);
    CHECK_DONE();
}
