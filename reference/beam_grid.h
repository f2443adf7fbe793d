/* The beam sets' internals (internal to reference/), shared by the build (beams.c: the
 * surface, its refinement, the beams and their slabs) and the lookups (beam_grid.c: the
 * slab boxes, the uniform grid over them, the exact per-beam test with the sun-disc kernel).
 * The public API: reference/beams.h. */
#ifndef GR_REF_BEAM_GRID_H
#define GR_REF_BEAM_GRID_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include "reference/beams.h"

/* Per grid vertex, in the sheared local frame: surface point (pu, py, pw); the beam edge
 * through it is (pu + au (y - py), y, pw + aw (y - py)); path length (y - py) * ity. */
typedef struct beam_vertex {
    float pu, py, pw;
    float au, aw;        /* Tx/Ty - shear_x, Tz/Ty - shear_z: drift per metre of height */
    float ity;           /* 1 / T_y (< 0) */
    float tx, ty, tz;    /* refracted direction T */
    float ft;            /* Fresnel transmittance; < 0 marks an unusable vertex */
} beam_vertex;

/* Per triangle, packed in two cache lines for the lookups' exact test. */
typedef struct beam_tri {
    float phi;               /* F_t |I . a| (0 = no beam) */
    float ytop, dy;          /* top of the beam, slab height */
    float ys;                /* top of its slabs: ytop, or the region's top below it */
    /* sun-disc kernel (zero without it): M = R J (2x2, row-major: shift in u, w per unit
     * depth for a unit offset in the disc frame); ybar = the mean height of the surface
     * vertices, from which the kernel's depth d = ybar - y is measured; kr = rho |M|_F, a
     * bound of the kernel's radius per unit depth */
    float kern[4], ybar, kr;
    uint32_t vi[3];          /* its vertices, wound so that the area vector points down */
    uint32_t first, nslab;   /* its primitives: first, count */
    /* the cross-section at height y, d = y - ytop (the lookups' test reads no vertex): vertex
     * 0 at (c[0] + c[2] d, c[1] + c[3] d), vertices 1 and 2 relative to it at
     * (c[4] + c[6] d, c[5] + c[7] d) and (c[8] + c[10] d, c[9] + c[11] d), the differences
     * taken in double (edges a few cm long, positions tens of metres from the origin) */
    float c[12];
    float pad_[5];
} beam_tri;
_Static_assert(sizeof(beam_tri) == 128, "beam_tri fills two cache lines (aligned_alloc needs a multiple of 64)");

/* The cell-local box units (docs/reference.md 2.2, "Lookups"): a grid coordinate f (cells
 * from the grid's corner, f >= 0) in 1/GRID_QUNITS of a cell, rounded down. Monotone in f, so
 * an entry's ends and a point quantized by it keep their order: the byte test is a superset of
 * the float box test. */
#define GRID_QUNITS 255
static inline int32_t grid_qcoord(float f)
{
    float g = f * (float)GRID_QUNITS;
    return g > 0.0f ? (g < 2.0e9f ? (int32_t)g : 2000000000) : 0;
}
/* The byte of quantized coordinate g in cell i: clamped to [0, 255] (monotone in g). */
static inline uint8_t grid_qbyte(int32_t g, int i)
{
    int64_t d = (int64_t)g - (int64_t)i * GRID_QUNITS;
    return (uint8_t)(d < 0 ? 0 : d > 255 ? 255 : d);
}

struct gr_beams {
    gr_beam_stats stats;
    int nu, nw;              /* cells of the base grid */
    size_t nv, ntri;         /* vertices (the grid's (nu + 1) (nw + 1) first), triangles */
    beam_vertex *v;          /* per vertex */
    beam_tri *tri;           /* per triangle */
    int disc;                /* 1: the sun-disc kernel is on */

    uint32_t *prim_tri;      /* per primitive: its triangle (read for the box test's passes) */
    float *box;              /* per primitive: its box, sheared {u, y, w} lower then upper */
    double y_min;
    float sx, sz;            /* shear: T0x / T0y, T0z / T0y */
    /* the lookup grid (docs/reference.md 2.2, "Lookups"): a uniform grid over the primitives'
     * boxes in sheared {u, y, w}; cell c lists the primitives whose boxes overlap it,
     * cell_prim[cell_first[c] .. cell_first[c + 1]), in increasing primitive id */
    float g0[3], ginv[3];    /* lower corner, 1 / cell size */
    int gn[3];               /* cells per axis */
    uint32_t *cell_first;    /* gn[0] gn[1] gn[2] + 1 */
    uint32_t *cell_prim;
    /* each entry's box clipped to its cell, in cell-local bytes (grid_qbyte): six arrays of
     * cell_q_stride bytes (lower u, upper u, lower y, upper y, lower w, upper w), entry i at
     * [i] of each, padded by 16 so that the lookups read 16 entries at a time; streamed with
     * the list (the boxes per primitive were a cache miss per candidate) */
    uint8_t *cell_q;
    size_t cell_q_stride;
    RTCScene surface;
};

/* Triangle t's vertices (explicit: the regular grid's cells, refined cells and the
 * transition fans around them, section 2.2 "Local refinement"). */
static inline void tri_vertices(const gr_beams *b, uint32_t t, uint32_t idx[3])
{
    const beam_tri *bt = &b->tri[t];
    idx[0] = bt->vi[0];
    idx[1] = bt->vi[1];
    idx[2] = bt->vi[2];
}

/* Slab k of nslab of a beam whose slabs start at ys, each dy high, spans [lo, hi); the top
 * slab is open upward and the bottom one downward, so each point of the beam belongs to
 * exactly one slab (no double counting). slab_range: triangle t's. */
static inline void slab_bounds(float ys, float dy, uint32_t k, uint32_t nslab, float *lo, float *hi)
{
    *hi = k == 0 ? INFINITY : ys - (float)k * dy;
    *lo = k + 1 == nslab ? -INFINITY : ys - (float)(k + 1) * dy;
}
static inline void slab_range(const gr_beams *b, uint32_t t, uint32_t k, uint32_t nslab, float *lo, float *hi)
{
    slab_bounds(b->tri[t].ys, b->tri[t].dy, k, nslab, lo, hi);
}

/* min and max of non-NaN floats without the libm calls that fminf/fmaxf are here (no
 * -ffinite-math-only): a NaN b gives a, as fminf/fmaxf do, so the boxes keep their bytes */
static inline float min_f(float a, float b) { return b < a ? b : a; }
static inline float max_f(float a, float b) { return b > a ? b : a; }

/* The box, in sheared coordinates lo/hi = {u, y, w}, of a beam (vertices v, its triangle's
 * disc kernel kern and ybar when disc) over the slab [ylo, yhi]: the lookups' boxes
 * (beam_grid.c) and the memory estimate's sampled ones (beams.c). */
static inline void beam_slab_box(const beam_vertex *const v[3], const float kern[4], float ybar, int disc, float ylo,
                                 float yhi, float lo3[3], float hi3[3])
{
    float u0 = FLT_MAX, u1 = -FLT_MAX, w0 = FLT_MAX, w1 = -FLT_MAX;
    for (int c = 0; c < 3; c++) {
        for (int e = 0; e < 2; e++) {
            float y = e ? yhi : ylo;
            float u = v[c]->pu + v[c]->au * (y - v[c]->py), w = v[c]->pw + v[c]->aw * (y - v[c]->py);
            u0 = min_f(u0, u); u1 = max_f(u1, u);
            w0 = min_f(w0, w); w1 = max_f(w1, w);
        }
    }
    if (disc) {
        /* the disc kernel reaches d J disc around the cross-section, d up to ybar - ylo */
        const float *M = kern;
        float dmax = ybar - ylo;
        if (dmax > 0.0f) {
            /* the unit disc's image: half widths |row of M| (slightly widened for rounding) */
            float ku = 1.0001f * dmax * sqrtf(M[0] * M[0] + M[1] * M[1]), kw = 1.0001f * dmax * sqrtf(M[2] * M[2] + M[3] * M[3]);
            u0 -= ku; u1 += ku;
            w0 -= kw; w1 += kw;
        }
    }
    /* widen by a few ulps of the coordinates so float rounding in the test cannot fall outside */
    float eu = 1e-5f * (1.0f + max_f(fabsf(u0), fabsf(u1))), ew = 1e-5f * (1.0f + max_f(fabsf(w0), fabsf(w1)));
    float ey = 1e-5f * (1.0f + max_f(fabsf(ylo), fabsf(yhi)));
    lo3[0] = u0 - eu; hi3[0] = u1 + eu;
    lo3[1] = ylo - ey; hi3[1] = yhi + ey;
    lo3[2] = w0 - ew; hi3[2] = w1 + ew;
}

/* The lookup structure of b's np primitives (b->prim_tri and the triangles set): their
 * boxes, then the grid over them, on up to `threads` threads (the result does not depend on
 * them). GR_E_NOMEM naming the grid. */
gr_status gr_beams_index(gr_beams *b, uint32_t np, int threads, gr_error *err);

/* gr_beams_lookup without the grid: every primitive's exact test (the checks' oracle for the
 * grid and its byte boxes, which may only drop primitives that cannot hold the point). */
int gr_beams_lookup_brute(const gr_beams *b, gr_vec3 p, gr_beam_hits *out);

/* Runs fn on n jobs (each `size` bytes apart; at most GRID_MAX_THREADS), job 0 on the calling
 * thread and the others on their own threads (serially if a thread cannot be started: the
 * same result). Returns the time during which at least two jobs ran (the serial part's
 * complement, reference/phase.h). */
#define GRID_MAX_THREADS 64
double gr_beams_run_jobs(void *(*fn)(void *), void *jobs, size_t size, int n);

/* Runs fn(job, c, k0, k1) for the chunks c = 0 .. nchunks - 1 of [0, total) (chunk c:
 * [total c / nchunks, total (c + 1) / nchunks)), taken from a shared counter by n threads,
 * thread i passing job i (each `size` bytes apart: its own accumulators). Which thread runs a
 * chunk varies; what a chunk writes must not (disjoint outputs, integer sums). Many chunks per
 * thread keep the last one's tail short (equal ranges end a millisecond apart on a shared
 * machine: time with one thread busy). Returns the time with at least two threads busy. */
typedef void (*gr_chunk_fn)(void *job, int chunk, size_t k0, size_t k1);
double gr_beams_run_chunks(gr_chunk_fn fn, void *jobs, size_t size, int n, size_t total, int nchunks);
/* The threads a build step runs on: `threads` within [1, GRID_MAX_THREADS]. */
int gr_beams_threads(int threads);
/* The chunks for `total` items on n threads: 16 per thread, at most `total` and GRID_CHUNKS_MAX. */
#define GRID_CHUNKS_MAX 1024
int gr_beams_chunks(size_t total, int n);

#endif
