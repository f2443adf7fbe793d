/* Beam prisms (illumination volumes) of refracted sunlight under a Gerstner surface, for
 * one sun direction (docs/reference.md, "Beam prisms"). The rest grid of a surface patch is
 * displaced (seed eq. 5.5.7), the sun is refracted at every vertex with the exact Fresnel
 * transmittance, and each surface triangle's refracted beam carries the flux
 * F_t |I . a| (a = the displaced triangle's area vector, per unit sun irradiance). The
 * horizontal cross-section of a beam at height y has vertices linear in y, so its area is
 * a quadratic in y and the horizontal irradiance inside is flux / |A(y)|: flux is
 * conserved by construction, through foci and folds.
 *
 * The sun's disc (docs/reference.md, "The sun's disc: analytic convolution"): a direction
 * delta (angular offset from the pass's central direction, in the disc frame e1, e2) moves
 * the beam's cross-section at depth d rigidly, to first order, by d J delta, J the Jacobian
 * of the refracted ray's horizontal slope T_xz / T_y with respect to delta (per beam: the
 * mean of its vertices' J). Averaged over the disc, the horizontal irradiance at p is
 *   E(p) = flux * area(triangle(y) n (p - K(y))) / (|A(y)| area(K(y))),  K = d J disc,
 * computed exactly (K an ellipse: segment and sector areas in the kernel's own units).
 *
 * Lookups go through a uniform grid over boxes: one primitive per beam and depth slab, in
 * coordinates sheared along the mean refracted direction T0 (u = x - T0x/T0y y,
 * w = z - T0z/T0y y), where beams are nearly vertical and slabs keep tight boxes; each
 * grid cell lists the primitives whose boxes overlap it, in increasing id. (Camera rays,
 * shadows and the displaced surface stay in Embree: embree_scene.h.)
 * All positions are in the local frame (world - origin), origin.y = the rest height. */
#ifndef GR_REF_BEAMS_H
#define GR_REF_BEAMS_H

#include <signal.h>
#include <stddef.h>
#include "reference/embree_scene.h"

typedef struct gr_beam_region {
    double u0, u1, w0, w1;   /* sheared horizontal bounds of the lit volume (local, m) */
    double y_min;            /* local height of its bottom (<= 0) */
    /* has_top: no lookup asks above y_top (local), so the beams' slabs stop there (the
     * frustum's highest point: docs/reference.md 2.2, "The region's top"); 0: the whole
     * column up to the surface */
    int has_top;
    double y_top;
} gr_beam_region;

typedef struct gr_beam_params {
    const gr_water *water;
    gr_dvec3 origin;         /* world position of the local origin; origin.y = rest height */
    gr_dvec3 sun_dir;        /* I for this beam set: unit, I_y < 0 */
    double ior;              /* water IOR (air = 1) */
    int fresnel;             /* 1: exact Fresnel transmittance; 0: F_t = 1 (flux oracle) */
    double shear_x, shear_z; /* T0x / T0y and T0z / T0y */
    gr_beam_region region;   /* where lookups must be complete */
    double pad_m;            /* margin of the rest patch around the region */
    int res;                 /* patch cells = res^2 (square cells) */
    double jitter[2];        /* grid offset in cells, each in [0, 1) */
    size_t max_prims;        /* budget of beam-slab primitives (memory bound) */
    /* Sun-disc convolution: disc_radius = the disc's angular radius in air (rad), 0 = none
     * (a point sun, or the disc sampled by passes instead); e1, e2: unit vectors spanning
     * the disc, perpendicular to sun_dir. */
    double disc_radius;
    gr_dvec3 disc_e1, disc_e2;
    int surface_mesh;        /* 1: also build the displaced surface as an Embree mesh */
    double slab_cells;       /* drift of a beam per depth slab, in cells; 0 = 1. Thinner slabs
                                (0.5) give tighter boxes: fewer candidates per lookup for a
                                render's march, twice the primitives to build */
    int threads;             /* threads for the boxes and the lookup grid (< 1: one); the
                                result does not depend on it */
    volatile sig_atomic_t *interrupt; /* nonzero (SIGINT/SIGTERM): the build stops, GR_E_INTERRUPTED */
    /* Local refinement (docs/reference.md 2.2, "Local refinement"): the rest cells whose beams
     * camera rays run along are split into refine_factor^2 sub-cells (all vertices exact
     * surface points), with crack-free transition cells around them. Those cells: within
     * gr_beam_refine_radius of the camera's sheared position (P_s, where the line through
     * the camera along T0 meets the rest plane). refine_factor <= 1, no camera or
     * refine_angle <= 0: off (the regular grid, as before). */
    int refine_factor;
    double refine_angle;     /* rad: camera rays within this angle of +T0 or -T0 count */
    const gr_camera *camera; /* its frustum (forward, right, up, fov, aspect) */
    gr_vec3 eye;             /* the camera's local position */
    /* On another set's grid (the camera cone's set, docs/reference.md 2.2): cell_m > 0 gives
     * the cell size (res and jitter are then unused) and the grid's lines pass through
     * (anchor_u, anchor_w), that set's gr_beam_stats.grid_u0, grid_w0. 0: from res. */
    double cell_m, anchor_u, anchor_w;
    double refine_radius_m; /* > 0: refine within this radius of P_s instead of gr_beam_refine_radius */
} gr_beam_params;

/* The radius (m, horizontal, in sheared coordinates at the rest plane) around P_s of the
 * surface whose beams camera rays within refine_angle of +-T0 meet: the largest sheared
 * drift |g| (per metre of height) of such a ray in the frustum times its height span in
 * the water (up to the rest plane, or down to the region's bottom). 0 when no camera
 * direction is that close to the beams, or refinement is off. */
double gr_beam_refine_radius(const gr_beam_params *p);

typedef struct gr_beams gr_beams;

typedef struct gr_beam_stats {
    int nu, nw;              /* cells of the rest patch */
    double cell_m;           /* cell size (m) */
    size_t triangles, lit_triangles, prims;
    size_t bytes;            /* own arrays, the lookup grid included */
    size_t grid_cells, grid_entries; /* the lookup grid: cells, (cell, primitive) entries */
    size_t vertices;         /* surface vertices (grid + refinement) */
    int refine_factor;       /* the factor used (1 = none) */
    size_t refined_cells, transition_cells; /* cells split F x F; cells fanned around them */
    double refine_radius_m;  /* gr_beam_refine_radius */
    double grid_u0, grid_w0; /* the rest grid's corner (sheared local, m; the jitter included) */
    double build_s;          /* wall time of the build */
    double par_s;            /* of it, the time with at least two threads busy (reference/phase.h) */
    double index_s, index_cpu_s, index_par_s; /* the lookup grid's part (boxes, grid fill): wall, CPU, parallel */
} gr_beam_stats;

gr_status gr_beams_build(gr_rtc *rtc, const gr_beam_params *p, gr_beams **out, gr_error *err);
/* A sample of a set's beam-slab primitives, without building the set (the memory estimate,
 * reference/memory.h): both triangles of one cell per stratum of a samples x samples
 * partition of the patch, computed as the build computes them (vertices, drift, slab count,
 * disc kernel, slab boxes); fine = F > 1: of the F x F sub-cells of a refined cell instead
 * (their drift in plain cells F times larger). Sums over the sampled triangles: */
typedef struct gr_beam_prim_sample {
    double tris;             /* triangles sampled (a triangle without a beam counts, with no primitive) */
    double prims;            /* their primitives (slabs) */
    double e1[3];            /* over those primitives: their boxes' extents along u, y, w, */
    double e2[3];            /* the products e_u e_y, e_u e_w, e_y e_w, */
    double e3;               /* and e_u e_y e_w */
} gr_beam_prim_sample;
void gr_beams_sample_prims(const gr_beam_params *p, int fine, int samples, gr_beam_prim_sample *out);
/* The expected lookup-grid entries per primitive of a set made of n classes of primitives
 * (s[i] sampled, weight[i] = that class's primitives in the set per sampled one): the grid's
 * cells are GRID_CELL_BOX times the boxes' mean extent c per axis, and a box of extents e
 * at a random offset meets prod_a (1 + e_a / c_a) cells on average; at most the grid's
 * budget per primitive (beam_grid.c). 0 when nothing was sampled. */
double gr_beams_entries_per_prim(const gr_beam_prim_sample *s, const double *weight, int n);
void gr_beams_destroy(gr_beams *b); /* accepts NULL */
const gr_beam_stats *gr_beams_stats(const gr_beams *b);
/* The tessellation, for tests: the number of triangles; vertex k's displaced local position
 * (float); triangle t's vertices (wound so that the area vector points down), returning
 * its flux F_t |I . a| per unit sun irradiance (0: no beam). */
size_t gr_beams_triangle_count(const gr_beams *b);
gr_vec3 gr_beams_vertex(const gr_beams *b, unsigned k);
float gr_beams_triangle(const gr_beams *b, size_t t, unsigned idx[3]);
/* The displaced surface mesh (NULL unless params.surface_mesh). */
RTCScene gr_beams_surface(const gr_beams *b);

/* One beam through a point. */
typedef struct gr_beam_hit {
    unsigned prim;           /* for a deterministic summation order */
    float e_h;               /* horizontal irradiance per unit sun irradiance: F_t |I.a| / |A(y)| */
    float path_m;            /* distance travelled in water from the surface */
    gr_vec3 T;               /* unit refracted direction at the point (interpolated) */
} gr_beam_hit;

/* A growable list of hits (caller-owned, reused between lookups; zero-initialize it, free
 * it with gr_beam_hits_free). It grows as needed: no lookup ever drops a beam. */
typedef struct gr_beam_hits {
    gr_beam_hit *h;
    int n, cap;
} gr_beam_hits;
void gr_beam_hits_free(gr_beam_hits *h); /* accepts NULL */

/* Finds every beam containing the local point p (with the disc convolution: every beam
 * whose disc-blurred footprint reaches p, e_h being the disc average) into out->h[0..n-1],
 * sorted by primitive id; returns n, or -1 when out of memory. */
int gr_beams_lookup(const gr_beams *b, gr_vec3 p, gr_beam_hits *out);

/* The kernel's geometry in its own units (the disc of directions = the unit disc), exposed
 * for tests: the fraction of the unit disc on the side c . n >= -s of a line at signed
 * distance s from its centre; the fraction of the unit disc inside the triangle
 * v = {x0, y0, x1, y1, x2, y2} (either orientation). */
double gr_beam_disc_halfplane(double s);
double gr_beam_disc_triangle(const double v[6]);
/* The same two without libm calls, as the lookups use them (polynomial acos and atan2,
 * errors below 1e-6 of the disc: docs/reference.md 2.4), and their atan2 for the test. */
double gr_beam_disc_halfplane_fast(double s);
double gr_beam_disc_triangle_fast(const double v[6]);
float gr_beam_atan2_fast(float y, float x);

#endif
