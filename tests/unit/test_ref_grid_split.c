/* The beam lookup grid split among threads (reference/beam_grid.c, build_grid; docs/
 * reference.md 2.2, "Lookups"): each box's cell range is computed by ranges of primitives,
 * the cell layers are split among the threads by a histogram of their entries, and each
 * cell's list is counted and filled by one thread. The lists must not depend on the split:
 * the grid built by one thread (no split at all) is the reference, and the grids built by
 * 2, 3, 8 and 64 threads (uneven splits, threads with no layers) must equal it entry for
 * entry; every list must be strictly increasing in primitive id (the order the lookups'
 * sums rely on), and the lookups at points through a focus must return the same hits. One
 * wave, the sun's disc on, surface_res 96: about 0.1 s a build. The set's own arrays (vertices,
 * triangles, boxes: built in chunks taken by whichever thread is free) must equal one thread's
 * byte for byte too (and the entries' cell-local byte boxes), gr_beams_run_chunks must run
 * every chunk once over its range, and the grid's lookups must equal every primitive's exact
 * test (gr_beams_lookup_brute, no grid, no box) bit for bit: the byte boxes are a superset. */
#include "check.h"
#include "test_ref_util.h"

#include <string.h>
#include "core/optics.h"
#include "reference/beam_grid.h"
#include "reference/embree_scene.h"

/* gr_beams_run_chunks' bookkeeping: how often each chunk ran, its range, each thread's items */
typedef struct chunk_seen {
    int *runs;
    size_t *lo, *hi;
    size_t items;
} chunk_seen;

static void note_chunk(void *job, int chunk, size_t k0, size_t k1)
{
    chunk_seen *s = job;
    __atomic_fetch_add(&s->runs[chunk], 1, __ATOMIC_RELAXED);
    s->lo[chunk] = k0;
    s->hi[chunk] = k1;
    s->items += k1 - k0;
}

static gr_beams *build(gr_rtc *rtc, gr_beam_params *p, int threads)
{
    gr_error err = {GR_OK, ""};
    gr_beams *b = NULL;
    p->threads = threads;
    CHECK_OK(gr_beams_build(rtc, p, &b, &err), err);
    if (!b) exit(1);
    return b;
}

int main(void)
{
    gr_scene *s = ref_scene("{\"water\":{\"waves\":[{\"amplitude_m\":0.05,\"wavelength_m\":2,\"direction_deg\":0}]},"
                            "\"sun\":{\"elevation_deg\":50,\"azimuth_deg\":20},\"camera\":{\"position_m\":[0,-1,0]}}");
    gr_error err = {GR_OK, ""};
    gr_rtc *rtc = NULL;
    CHECK_OK(gr_rtc_create(0, &rtc, &err), err);
    if (!rtc) return 1;
    gr_beam_params p;
    ref_beam_params(s, 1.5, -7.0, 96, 0.5, &p);

    gr_beams *ref = build(rtc, &p, 1);
    size_t nc = (size_t)ref->gn[0] * ref->gn[1] * ref->gn[2], ne = ref->cell_first[nc];
    CHECK_MSG(ne > 1000 && ne == ref->stats.grid_entries, "the reference grid has %zu entries (stats %zu)", ne,
              ref->stats.grid_entries);
    CHECK_MSG(ref->gn[2] > 8, "the grid has %d w-layers: too few to split unevenly", ref->gn[2]);
    size_t unsorted = 0;
    for (size_t c = 0; c < nc; c++)
        for (uint32_t i = ref->cell_first[c] + 1; i < ref->cell_first[c + 1]; i++) unsorted += ref->cell_prim[i - 1] >= ref->cell_prim[i];
    CHECK_MSG(unsorted == 0, "%zu list entries out of order", unsorted);

    const int threads[] = {2, 3, 8, 64};
    gr_beam_hits h1 = {NULL, 0, 0}, h2 = {NULL, 0, 0};
    for (int k = 0; k < 4; k++) {
        gr_beams *b = build(rtc, &p, threads[k]);
        int same_shape = b->gn[0] == ref->gn[0] && b->gn[1] == ref->gn[1] && b->gn[2] == ref->gn[2];
        CHECK_MSG(same_shape, "%d threads: grid %dx%dx%d against %dx%dx%d", threads[k], b->gn[0], b->gn[1], b->gn[2],
                  ref->gn[0], ref->gn[1], ref->gn[2]);
        if (!same_shape) continue;
        CHECK_MSG(memcmp(b->cell_first, ref->cell_first, (nc + 1) * sizeof *b->cell_first) == 0,
                  "%d threads: the cells' list bounds differ from one thread's", threads[k]);
        CHECK_MSG(b->cell_first[nc] == ne && memcmp(b->cell_prim, ref->cell_prim, ne * sizeof *b->cell_prim) == 0,
                  "%d threads: the cells' lists differ from one thread's", threads[k]);
        CHECK_MSG(b->cell_q_stride == ref->cell_q_stride && memcmp(b->cell_q, ref->cell_q, 6 * ref->cell_q_stride) == 0,
                  "%d threads: the entries' cell-local boxes differ from one thread's", threads[k]);
        /* the set's own arrays, built in chunks taken by whichever thread is free: vertices,
         * triangles (with their slabs' first primitive and count), the primitives' boxes */
        int same_set = b->nv == ref->nv && b->ntri == ref->ntri && b->stats.prims == ref->stats.prims &&
                       b->stats.lit_triangles == ref->stats.lit_triangles;
        CHECK_MSG(same_set, "%d threads: %zu vertices, %zu triangles, %zu primitives, %zu lit against %zu, %zu, %zu, %zu",
                  threads[k], b->nv, b->ntri, b->stats.prims, b->stats.lit_triangles, ref->nv, ref->ntri, ref->stats.prims,
                  ref->stats.lit_triangles);
        if (same_set) {
            CHECK_MSG(memcmp(b->v, ref->v, ref->nv * sizeof *b->v) == 0, "%d threads: the vertices differ", threads[k]);
            CHECK_MSG(memcmp(b->tri, ref->tri, ref->ntri * sizeof *b->tri) == 0, "%d threads: the triangles differ", threads[k]);
            CHECK_MSG(memcmp(b->prim_tri, ref->prim_tri, ref->stats.prims * sizeof *b->prim_tri) == 0,
                      "%d threads: the primitives' triangles differ", threads[k]);
        }
        /* lookups along a vertical line through the focus (about 5.5 m down) and off it */
        int diff = 0, hits = 0;
        for (int i = 0; i < 400; i++) {
            gr_vec3 q = gr_v3(-0.3f + 0.3f * (float)(i % 3), -0.5f - 0.016f * (float)i, -0.9f + 0.0045f * (float)i);
            int n1 = gr_beams_lookup(ref, q, &h1), n2 = gr_beams_lookup(b, q, &h2);
            hits += n1;
            diff += n1 != n2;
            for (int j = 0; j < n1 && n1 == n2; j++) diff += h1.h[j].prim != h2.h[j].prim || h1.h[j].e_h != h2.h[j].e_h;
        }
        CHECK_MSG(hits > 400 && diff == 0, "%d threads: %d of the lookups' hits (%d) differ", threads[k], diff, hits);
        gr_beams_destroy(b);
    }
    printf("grid %dx%dx%d, %zu entries (%.1f per primitive), the same lists and set for 1, 2, 3, 8 and 64 threads\n", ref->gn[0],
           ref->gn[1], ref->gn[2], ne, (double)ne / (double)ref->stats.prims);

    /* the grid and its entries' cell-local byte boxes against every primitive's exact test:
     * the same hits, bit for bit (a box test that dropped a primitive holding the point, or a
     * cell list missing one, shows here); points on the line through the focus and spread
     * over the lit volume, some on cell faces */
    {
        int diff = 0, hits = 0, pts = 0;
        uint32_t x = 12345u;
        for (int i = 0; i < 600; i++) {
            gr_vec3 q;
            if (i < 200) q = gr_v3(-0.3f + 0.3f * (float)(i % 3), -0.5f - 0.032f * (float)i, -0.9f + 0.009f * (float)i);
            else {
                float r[3];
                for (int a = 0; a < 3; a++) { x = x * 1664525u + 1013904223u; r[a] = (float)(x >> 8) / 16777216.0f; }
                q = gr_v3(-1.6f + 3.2f * r[0], -0.2f - 6.6f * r[1], -1.6f + 3.2f * r[2]);
                if (i % 4 == 0) { /* on a cell face of the grid (u and y), exactly */
                    float fu = floorf((q.x - ref->sx * q.y - ref->g0[0]) * ref->ginv[0]);
                    q.x = ref->g0[0] + fu / ref->ginv[0] + ref->sx * q.y;
                }
            }
            int n1 = gr_beams_lookup(ref, q, &h1), n2 = gr_beams_lookup_brute(ref, q, &h2);
            pts++;
            hits += n2;
            diff += n1 != n2;
            for (int j = 0; j < n1 && n1 == n2; j++)
                diff += h1.h[j].prim != h2.h[j].prim || h1.h[j].e_h != h2.h[j].e_h || h1.h[j].path_m != h2.h[j].path_m;
        }
        CHECK_MSG(hits > 600 && diff == 0, "the grid's lookups differ from every primitive's test at %d of %d points (%d hits)",
                  diff, pts, hits);
        printf("the grid's lookups equal every primitive's exact test at %d points (%d hits)\n", pts, hits);
    }

    /* gr_beams_run_chunks: every chunk once, the chunks tiling [0, total) as documented */
    const int ns[] = {1, 2, 7}, cs[] = {1, 5, 64, 1000};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 4; c++) {
            chunk_seen seen[8];
            memset(seen, 0, sizeof seen);
            static int runs[1000];
            static size_t lo[1000], hi[1000];
            memset(runs, 0, sizeof runs);
            for (int i = 0; i < 8; i++) { seen[i].runs = runs; seen[i].lo = lo; seen[i].hi = hi; }
            size_t total = 12345;
            gr_beams_run_chunks(note_chunk, seen, sizeof seen[0], ns[a], total, cs[c]);
            int bad = 0;
            size_t sum = 0;
            for (int k = 0; k < cs[c]; k++) {
                bad += runs[k] != 1 || lo[k] != total * (size_t)k / (size_t)cs[c] || hi[k] != total * (size_t)(k + 1) / (size_t)cs[c];
                sum += hi[k] - lo[k];
            }
            size_t items = 0;
            for (int i = 0; i < ns[a]; i++) items += seen[i].items;
            CHECK_MSG(bad == 0 && sum == total && items == total, "run_chunks, %d threads, %d chunks: %d chunks wrong, %zu of %zu items",
                      ns[a], cs[c], bad, items, total);
        }
    gr_beam_hits_free(&h1);
    gr_beam_hits_free(&h2);
    gr_beams_destroy(ref);
    gr_rtc_destroy(rtc);
    free(s);
    CHECK_DONE();
}
