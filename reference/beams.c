#include "reference/beams.h"

#include <float.h>
#include <pthread.h>
#include <stdbool.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/gerstner.h"
#include "core/optics.h"

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
    float pad_[6];
} beam_tri;
_Static_assert(sizeof(beam_tri) == 128, "beam_tri fills two cache lines (aligned_alloc needs a multiple of 64)");

/* A primitive as the lookups read it: its box in 16-bit units {u, y, w} lower then upper, and
 * its triangle (in the same 16 bytes: one load serves the box test and the triangle's address). */
typedef struct beam_qbox {
    uint16_t q[6];
    uint32_t tri;
} beam_qbox;

struct gr_beams {
    gr_beam_stats stats;
    int nu, nw;              /* cells of the base grid */
    size_t nv, ntri;         /* vertices (the grid's (nu + 1) (nw + 1) first), triangles */
    beam_vertex *v;          /* per vertex */
    beam_tri *tri;           /* per triangle */
    int disc;                /* 1: the sun-disc kernel is on */

    uint32_t *prim_tri;      /* per primitive: its triangle */
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
    /* the boxes as the lookups test them: 16-bit units of the grid's span per axis, lower
     * ends rounded down and upper ends up, one unit wider each side (half the bytes of the
     * float boxes: fewer cache misses in the candidate loop) */
    beam_qbox *qbox;         /* per primitive */
    float q0[3], qinv[3];
    RTCScene surface;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the sun-disc kernel ----
 * In the kernel's own coordinates c (x = p + d M c) the disc of directions is the unit
 * disc, and the cross-section a triangle. The fraction of the disc inside the triangle is
 * computed exactly: by the segment formula when one edge crosses the disc, else by summing
 * the signed areas of disc n triangle(0, c_i, c_i+1) over the three edges. */

/* Fraction of the unit disc on the side c . n >= -s of a line at signed distance s from
 * its centre (s > 0: the centre is inside): 1 - (acos s - s sqrt(1 - s^2)) / pi. */
double gr_beam_disc_halfplane(double s)
{
    if (s >= 1.0) return 1.0;
    if (s <= -1.0) return 0.0;
    return 1.0 - (acos(s) - s * sqrt(1.0 - s * s)) / GR_PI;
}

/* Signed area of the unit disc n triangle(0, a, b) (the sign of cross(a, b)): the parts of
 * the segment ab inside the disc contribute triangles, the parts outside circular sectors,
 * whose angles come from at2 (atan2f, or atan2_fast in the lookups). */
static inline double disc_wedge_with(double ax, double ay, double bx, double by, float (*at2)(float, float))
{
    double dx = bx - ax, dy = by - ay;
    double A = dx * dx + dy * dy, B = ax * dx + ay * dy, C = ax * ax + ay * ay - 1.0;
    double t0 = 1.0, t1 = 0.0; /* the part of the segment inside the disc: [t0, t1] */
    double disc = B * B - A * C;
    if (A > 0.0 && disc > 0.0) {
        double sq = sqrt(disc);
        /* the roots of A t^2 + 2 B t + C, without cancellation */
        double q = B >= 0.0 ? -(B + sq) : -(B - sq);
        double r0 = q / A, r1 = q != 0.0 ? C / q : r0;
        if (r0 > r1) { double x = r0; r0 = r1; r1 = x; }
        t0 = r0 > 0.0 ? r0 : 0.0;
        t1 = r1 < 1.0 ? r1 : 1.0;
    }
    /* sectors: float atan2 (1e-7 of the disc's area, far below any other error here) */
    if (!(t0 < t1)) return 0.5 * at2((float)(ax * by - ay * bx), (float)(ax * bx + ay * by)); /* all outside */
    double px = ax + t0 * dx, py = ay + t0 * dy, qx = ax + t1 * dx, qy = ay + t1 * dy;
    double area = 0.5 * (px * qy - py * qx);
    if (t0 > 0.0) area += 0.5 * at2((float)(ax * py - ay * px), (float)(ax * px + ay * py));
    if (t1 < 1.0) area += 0.5 * at2((float)(qx * by - qy * bx), (float)(qx * bx + qy * by));
    return area;
}

static double disc_wedge(double ax, double ay, double bx, double by)
{
    return disc_wedge_with(ax, ay, bx, by, atan2f);
}

double gr_beam_disc_triangle(const double v[6])
{
    double a = disc_wedge(v[0], v[1], v[2], v[3]) + disc_wedge(v[2], v[3], v[4], v[5]) + disc_wedge(v[4], v[5], v[0], v[1]);
    return fabs(a) / GR_PI;
}

/* ---- the same areas without libm calls (the march's hot loop; docs/reference.md 2.4,
 * "Fast kernel areas") ----
 * acos by Abramowitz & Stegun 4.4.46: acos(x) = sqrt(1 - x) sum_k a_k x^k on [0, 1], |error|
 * <= 2e-8 rad; acos(-x) = pi - acos(x). */
static inline double acos_poly(double ax)
{
    double p = -0.0012624911;
    p = p * ax + 0.0066700901;
    p = p * ax - 0.0170881256;
    p = p * ax + 0.0308918810;
    p = p * ax - 0.0501743046;
    p = p * ax + 0.0889789874;
    p = p * ax - 0.2145988016;
    return p * ax + 1.5707963050;
}

static inline double acos_fast(double x)
{
    double ax = fabs(x);
    double r = sqrt(1.0 - ax) * acos_poly(ax);
    return x >= 0.0 ? r : GR_PI - r;
}

double gr_beam_disc_halfplane_fast(double s)
{
    if (s >= 1.0) return 1.0;
    if (s <= -1.0) return 0.0;
    return 1.0 - (acos_fast(s) - s * sqrt(1.0 - s * s)) / GR_PI;
}

/* atan2 in float: octant reduction to a = min / max in [0, 1], then a further reduction past
 * tan(pi/8) (atan a = pi/4 + atan((a - 1) / (a + 1))) and Cephes' atanf polynomial on
 * [0, tan(pi/8)] (relative error ~1e-7); measured against libm in unit.ref_kernel. */
static inline float atan2_fast(float y, float x)
{
    float ax = fabsf(x), ay = fabsf(y);
    float mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
    if (!(mx > 0.0f)) return 0.0f;
    float a = mn / mx, base = 0.0f;
    if (a > 0.41421356f) {
        a = (a - 1.0f) / (a + 1.0f);
        base = 0.78539816f;
    }
    float z = a * a;
    float r = base + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * a + a);
    if (ay > ax) r = 1.57079633f - r;
    if (x < 0.0f) r = 3.14159265f - r;
    return y < 0.0f ? -r : r;
}

/* disc_wedge with atan2_fast */
static double disc_wedge_fast(double ax, double ay, double bx, double by)
{
    return disc_wedge_with(ax, ay, bx, by, atan2_fast);
}

/* Angle of the arc from q to p (points on the unit circle, up to rounding) turning in the
 * sense o (+-1), in [0, 2 pi). Both are first put back on the circle (one Newton step for
 * 1 / |q|, error O((|q| - 1)^2)), since the chord formula below turns a radial error e into
 * an angle error sqrt(e) near half a turn. The minor arc is acos(q . p), with 1 - q . p =
 * |p - q|^2 / 2 = w taken from the chord (no cancellation near 0) and 1 + q . p = 2 - w; the
 * sign of o (q x p) tells minor from major (2 pi - minor). *bad is set where that sign is not
 * trustworthy: q and p within sqrt(tol2) of each other, the arc near 0 or 2 pi. */
static inline double arc_angle(double qx, double qy, double px, double py, double o, double tol2, int *bad)
{
    double nq = 1.5 - 0.5 * (qx * qx + qy * qy), np = 1.5 - 0.5 * (px * px + py * py);
    qx *= nq; qy *= nq; px *= np; py *= np;
    double cr = o * (qx * py - qy * px), dx = px - qx, dy = py - qy;
    double w = 0.5 * (dx * dx + dy * dy), x = 1.0 - w, ax = fabs(x), u = 1.0 - ax;
    *bad |= w < tol2;
    double m = sqrt(u > 0.0 ? u : 0.0) * acos_poly(ax < 1.0 ? ax : 1.0);
    /* the two choices by sign, without branches (they are hard to predict here): acos(x)
     * = m or pi - m, the arc = acos or 2 pi - acos; a signed zero only where both agree */
    double sx = copysign(1.0, x), sc = copysign(1.0, cr);
    m = 0.5 * GR_PI + sx * (m - 0.5 * GR_PI);
    return GR_PI + sc * (m - GR_PI);
}

/* The roots r0 <= r1 of |a + t d|^2 = 1, i.e. A t^2 + 2 B t + C = 0 with C = |a|^2 - 1, in
 * double, with the discriminant B^2 - A C written as A - (a x b)^2 (Lagrange's identity;
 * c = a x b = a x d): B^2 and A C cancel to O(ulp(|a|^2 |d|^2)) for far vertices, c is
 * rounded to O(ulp(|a| |b|)) only. The roots' absolute error, which the clipped points a + t d
 * inherit, is then a few ulps of |a| + 1, the same as the rounding of those points. Returns
 * r1 - r0 (2 sqrt(disc) / A). With both ends outside (cross != 0), returns -1 without the
 * roots where the segment misses the disc: unless its nearest point to the centre, t = -B / A,
 * lies in (0, 1) and the line's distance is below 1 (disc > 0). */
static inline double unit_roots(double ax, double ay, double dx, double dy, double c, int cross, double *r0, double *r1)
{
    double A = dx * dx + dy * dy, B = ax * dx + ay * dy, disc = A - c * c;
    if (cross && !(B < 0.0 && A + B > 0.0 && disc > 0.0)) return -1.0;
    double sq = sqrt(disc > 0.0 ? disc : 0.0), iA = 1.0 / A;
    *r0 = (-B - sq) * iA;
    *r1 = (-B + sq) * iA;
    return 2.0 * sq * iA;
}

/* The boundary of disc n triangle is made of chords (the parts of the edges inside the disc)
 * and arcs (the parts of the circle inside the triangle), so (Green) twice its area is
 * sum_chords p x q + o sum_arcs angle, with o the triangle's orientation. Each edge is
 * clipped to the disc once (vertex radii shared by the two edges at a vertex); walking the
 * boundary, the points where it leaves (q) and re-enters (p) the disc alternate, and each
 * exit is joined to the next entry by an arc: one acos per arc (none when the triangle lies
 * inside the disc, or no edge meets the circle), against up to six atan2 in the sum of the
 * three wedges. The vertices are rotated so that one pattern of inside/outside vertices
 * covers its three rotations. docs/reference.md 2.4, "Fast kernel areas". */
double gr_beam_disc_triangle_fast(const double v[6])
{
    double r2[3];
    unsigned in = 0; /* bit i: vertex i lies in the closed disc */
    for (int i = 0; i < 3; i++) {
        r2[i] = v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1];
        in |= (r2[i] <= 1.0 ? 1u : 0u) << i;
    }
    double area2 = (v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0]);
    if (in == 7u) return fabs(area2) * (0.5 / GR_PI); /* the triangle lies inside the disc */
    if (!(area2 != 0.0)) goto wedges;
    double o = area2 > 0.0 ? 1.0 : -1.0;
    /* tol2 = (1e-9 |v|)^2, far above the squared rounding of the points, (1e-16 |v|)^2 */
    double rmax2 = r2[0] > r2[1] ? (r2[0] > r2[2] ? r2[0] : r2[2]) : (r2[1] > r2[2] ? r2[1] : r2[2]);
    double tol2 = 1e-18 * (1.0 + rmax2), chord = 0.0, arcs = 0.0;
    int bad = 0;
    /* rotation: the lone inside vertex (one in) or the lone outside one (two in) first */
    double x0 = v[0], y0 = v[1], x1 = v[2], y1 = v[3], x2 = v[4], y2 = v[5];
    if (in == 2u || in == 5u) { /* vertex 1 first */
        double tx = x0, ty = y0;
        x0 = x1; y0 = y1; x1 = x2; y1 = y2; x2 = tx; y2 = ty;
    } else if (in == 3u || in == 4u) { /* vertex 2 first */
        double tx = x2, ty = y2;
        x2 = x1; y2 = y1; x1 = x0; y1 = y0; x0 = tx; y0 = ty;
    }
    double c0 = x0 * y1 - y0 * x1, c1 = x1 * y2 - y1 * x2, c2 = x2 * y0 - y2 * x0; /* a x b per edge */
    double d0x = x1 - x0, d0y = y1 - y0, d1x = x2 - x1, d1y = y2 - y1, d2x = x0 - x2, d2y = y0 - y2;
    double r0, r1, len;
    unsigned nin = (in & 1u) + ((in >> 1) & 1u) + (in >> 2);
    if (nin == 1) {
        /* 0 in, 1 and 2 out: edge 0 leaves at q0, edge 2 enters at p2, edge 1 may cross */
        unit_roots(x0, y0, d0x, d0y, c0, 0, &r0, &r1);
        double t1 = r1 < 1.0 ? r1 : 1.0;
        double q0x = x0 + t1 * d0x, q0y = y0 + t1 * d0y;
        unit_roots(x2, y2, d2x, d2y, c2, 0, &r0, &r1);
        double t0 = r0 > 0.0 ? r0 : 0.0;
        double p2x = x2 + t0 * d2x, p2y = y2 + t0 * d2y;
        chord = t1 * c0 + (1.0 - t0) * c2;
        if ((len = unit_roots(x1, y1, d1x, d1y, c1, 1, &r0, &r1)) >= 0.0) {
            chord += len * c1;
            arcs = arc_angle(q0x, q0y, x1 + r0 * d1x, y1 + r0 * d1y, o, tol2, &bad) +
                   arc_angle(x1 + r1 * d1x, y1 + r1 * d1y, p2x, p2y, o, tol2, &bad);
        } else {
            arcs = arc_angle(q0x, q0y, p2x, p2y, o, tol2, &bad);
        }
    } else if (nin == 2) {
        /* 0 out, 1 and 2 in: edge 0 enters at p0, edge 1 inside, edge 2 leaves at q2 */
        unit_roots(x0, y0, d0x, d0y, c0, 0, &r0, &r1);
        double t0 = r0 > 0.0 ? r0 : 0.0;
        double p0x = x0 + t0 * d0x, p0y = y0 + t0 * d0y;
        unit_roots(x2, y2, d2x, d2y, c2, 0, &r0, &r1);
        double t1 = r1 < 1.0 ? r1 : 1.0;
        chord = (1.0 - t0) * c0 + c1 + t1 * c2;
        arcs = arc_angle(x2 + t1 * d2x, y2 + t1 * d2y, p0x, p0y, o, tol2, &bad);
    } else {
        /* all out: each edge crosses the disc or misses it; arcs from each crossing edge's
         * exit to the next crossing edge's entry */
        double px[3], py[3], qx[3], qy[3], xs[3] = {x0, x1, x2}, ys[3] = {y0, y1, y2};
        double dxs[3] = {d0x, d1x, d2x}, dys[3] = {d0y, d1y, d2y}, cs[3] = {c0, c1, c2};
        int n = 0;
        for (int i = 0; i < 3; i++) {
            if (!((len = unit_roots(xs[i], ys[i], dxs[i], dys[i], cs[i], 1, &r0, &r1)) >= 0.0)) continue;
            chord += len * cs[i];
            px[n] = xs[i] + r0 * dxs[i]; py[n] = ys[i] + r0 * dys[i];
            qx[n] = xs[i] + r1 * dxs[i]; qy[n] = ys[i] + r1 * dys[i];
            n++;
        }
        /* no edge meets the circle: the disc lies inside the triangle (the origin on the
         * inner side of all three edges) or outside it */
        if (n == 0) return o * c0 > 0.0 && o * c1 > 0.0 && o * c2 > 0.0 ? 1.0 : 0.0;
        for (int i = 0; i < n; i++) {
            int m = i + 1 < n ? i + 1 : 0;
            arcs += arc_angle(qx[i], qy[i], px[m], py[m], o, tol2, &bad);
        }
    }
    if (bad) goto wedges;
    return fabs(o * chord + arcs) * (0.5 / GR_PI);
wedges:
    /* degenerate or ambiguous (measure zero in practice): the sum of the three wedges */
    return fabs(disc_wedge_fast(v[0], v[1], v[2], v[3]) + disc_wedge_fast(v[2], v[3], v[4], v[5]) +
                disc_wedge_fast(v[4], v[5], v[0], v[1])) / GR_PI;
}

float gr_beam_atan2_fast(float y, float x) { return atan2_fast(y, x); }

/* Jacobian of the refracted ray's horizontal slope (T_x / T_y, T_z / T_y) with respect to
 * the sun direction's angular offset along e1 and e2 (rad), for the surface normal n:
 * central differences of Snell's law in double (step 1e-5 rad: truncation ~1e-10,
 * rounding ~1e-11 relative). J is row-major: {du/de1, du/de2, dw/de1, dw/de2}. */
static void slope_jacobian(gr_dvec3 I, gr_dvec3 n, double eta, gr_dvec3 e1, gr_dvec3 e2, double J[4])
{
    const double eps = 1e-5;
    const gr_dvec3 e[2] = {e1, e2};
    for (int k = 0; k < 2; k++) {
        double s[2][2];
        for (int sg = 0; sg < 2; sg++) {
            gr_dvec3 Id = gr_d3_norm(gr_d3_madd(I, e[k], sg ? -eps : eps));
            gr_dvec3 T = gr_refract_d(Id, n, eta);
            s[sg][0] = T.x / T.y;
            s[sg][1] = T.z / T.y;
        }
        J[k] = (s[0][0] - s[1][0]) / (2.0 * eps);
        J[2 + k] = (s[0][1] - s[1][1]) / (2.0 * eps);
    }
}

/* Triangle t's vertices (explicit: the regular grid's cells, refined cells and the
 * transition fans around them, section 2.2 "Local refinement"). */
static inline void tri_vertices(const gr_beams *b, uint32_t t, uint32_t idx[3])
{
    const beam_tri *bt = &b->tri[t];
    idx[0] = bt->vi[0];
    idx[1] = bt->vi[1];
    idx[2] = bt->vi[2];
}

/* Slab k of triangle t spans [lo, hi); the top slab is open upward and the bottom one
 * downward, so each point of the beam belongs to exactly one slab (no double counting). */
static inline void slab_range(const gr_beams *b, uint32_t t, uint32_t k, uint32_t nslab, float *lo, float *hi)
{
    *hi = k == 0 ? INFINITY : b->tri[t].ytop - (float)k * b->tri[t].dy;
    *lo = k + 1 == nslab ? -INFINITY : b->tri[t].ytop - (float)(k + 1) * b->tri[t].dy;
}

/* The box of primitive `prim` (a triangle's beam over one slab) in sheared coordinates:
 * lo/hi = {u, y, w}. */
static void prim_box(const gr_beams *b, uint32_t prim, float lo3[3], float hi3[3])
{
    uint32_t t = b->prim_tri[prim];
    uint32_t nslab = b->tri[t].nslab, k = prim - b->tri[t].first;
    float lo, hi;
    slab_range(b, t, k, nslab, &lo, &hi);
    float ylo = isinf(lo) ? (float)b->y_min : lo, yhi = isinf(hi) ? b->tri[t].ytop : hi;
    uint32_t idx[3];
    tri_vertices(b, t, idx);
    float u0 = FLT_MAX, u1 = -FLT_MAX, w0 = FLT_MAX, w1 = -FLT_MAX;
    for (int c = 0; c < 3; c++) {
        const beam_vertex *v = &b->v[idx[c]];
        for (int e = 0; e < 2; e++) {
            float y = e ? yhi : ylo;
            float u = v->pu + v->au * (y - v->py), w = v->pw + v->aw * (y - v->py);
            u0 = fminf(u0, u); u1 = fmaxf(u1, u);
            w0 = fminf(w0, w); w1 = fmaxf(w1, w);
        }
    }
    if (b->disc) {
        /* the disc kernel reaches d J disc around the cross-section, d up to ybar - ylo */
        const float *M = b->tri[t].kern;
        float dmax = b->tri[t].ybar - ylo;
        if (dmax > 0.0f) {
            /* the unit disc's image: half widths |row of M| (slightly widened for rounding) */
            float ku = 1.0001f * dmax * sqrtf(M[0] * M[0] + M[1] * M[1]), kw = 1.0001f * dmax * sqrtf(M[2] * M[2] + M[3] * M[3]);
            u0 -= ku; u1 += ku;
            w0 -= kw; w1 += kw;
        }
    }
    /* widen by a few ulps of the coordinates so float rounding in the test cannot fall outside */
    float eu = 1e-5f * (1.0f + fmaxf(fabsf(u0), fabsf(u1))), ew = 1e-5f * (1.0f + fmaxf(fabsf(w0), fabsf(w1)));
    float ey = 1e-5f * (1.0f + fmaxf(fabsf(ylo), fabsf(yhi)));
    lo3[0] = u0 - eu; hi3[0] = u1 + eu;
    lo3[1] = ylo - ey; hi3[1] = yhi + ey;
    lo3[2] = w0 - ew; hi3[2] = w1 + ew;
}

typedef struct lookup_state {
    float u, y, w;           /* the point, sheared */
    gr_beam_hits *out;       /* grows as needed */
    int oom;
} lookup_state;

/* The exact test of one primitive: is the point in the slab's height interval and in the
 * beam's (disc-blurred) cross-section? Appends the hit to s. */
static void beam_test(const gr_beams *b, uint32_t prim, uint32_t t, lookup_state *s)
{
    const beam_tri *bt = &b->tri[t];
    uint32_t k = prim - bt->first;
    float y = s->y;
    /* the slab's half-open height interval (top slab open upward, bottom one downward) */
    if (k > 0 && !(y < bt->ytop - (float)k * bt->dy)) return;
    if (k + 1 < bt->nslab && !(y >= bt->ytop - (float)(k + 1) * bt->dy)) return;
    /* cross-section vertices at height y, relative to vertex 0 */
    const float *cs = bt->c;
    float dt = y - bt->ytop;
    float x0 = cs[0] + cs[2] * dt, z0 = cs[1] + cs[3] * dt;
    float e1u = cs[4] + cs[6] * dt, e1w = cs[5] + cs[7] * dt;
    float e2u = cs[8] + cs[10] * dt, e2w = cs[9] + cs[11] * dt;
    float qu = s->u - x0, qw = s->w - z0;
    float det = e1u * e2w - e1w * e2u; /* twice the signed area: negative past a fold */
    /* barycentric coordinates times det (edge functions) of vertices 0, 1, 2 */
    float f1 = qu * e2w - qw * e2u, f2 = e1u * qw - e1w * qu, f0 = det - f1 - f2;
    float e_h;
    float dd = b->disc ? bt->ybar - y : 0.0f; /* depth below the beam's top: the kernel's scale */
    if (!(dd > 0.0f)) {
        /* a point sun (or the top of the beam): the point-in-triangle test */
        if (det == 0.0f) return; /* a measure-zero set: the exact focus */
        float inv = 1.0f / det;
        if (f0 * inv < 0.0f || f1 * inv < 0.0f || f2 * inv < 0.0f) return;
        e_h = bt->phi / (0.5f * fabsf(det));
    } else {
        /* Disc average (docs/reference.md, "The sun's disc"): the fraction of the kernel
         * K = dd M disc centred at p that lies inside the cross-section. With sg = sign(det),
         * edge i is sg f_i >= 0; moving by dd M c changes f_i by dd grad(f_i) . M c. */
        float sg = det < 0.0f ? -1.0f : 1.0f;
        float fa0 = sg * f0, fa1 = sg * f1, fa2 = sg * f2;
        /* grad f_i in (u, w) */
        float g0u = e1w - e2w, g0w = e2u - e1u, g1u = e2w, g1w = -e2u, g2u = -e1w, g2w = e1u;
        /* quick reject: the kernel's radius is at most kr dd (kr >= |M|_F), so a point farther
         * than that outside an edge is out (most candidates end here) */
        float kd = dd * bt->kr, kd2 = kd * kd;
        if (fa0 < 0.0f && fa0 * fa0 > kd2 * (g0u * g0u + g0w * g0w)) return;
        if (fa1 < 0.0f && fa1 * fa1 > kd2 * (g1u * g1u + g1w * g1w)) return;
        if (fa2 < 0.0f && fa2 * fa2 > kd2 * (g2u * g2u + g2w * g2w)) return;
        const float *M = bt->kern;
        float gs[3][2] = {{g0u, g0w}, {g1u, g1w}, {g2u, g2w}}, fa[3] = {fa0, fa1, fa2}, ext[3];
        unsigned cut = 0; /* edges that cross the kernel */
        for (int i = 0; i < 3; i++) {
            /* edge i in kernel units is fa_i + b_i . c >= 0, b_i = sg dd M^T grad f_i; the disc
             * being round, only |b_i| matters (fa_i / |b_i| = the centre's distance) */
            float bx = dd * (M[0] * gs[i][0] + M[2] * gs[i][1]), by = dd * (M[1] * gs[i][0] + M[3] * gs[i][1]);
            ext[i] = sqrtf(bx * bx + by * by);
            if (fa[i] < -ext[i]) return;     /* the kernel lies wholly outside edge i */
            if (fa[i] < ext[i]) cut |= 1u << i;
        }
        if (!cut) {
            /* the kernel lies wholly inside the cross-section: the beam's own irradiance */
            if (det == 0.0f) return;
            e_h = bt->phi / (0.5f * fabsf(det));
        } else {
            float detM = M[0] * M[3] - M[1] * M[2];
            float areaK = dd * dd * fabsf(detM) * (float)GR_PI; /* the kernel's area (m^2) */
            if (!(areaK > 0.0f)) return;
            double frac;
            if (!(cut & (cut - 1u))) {
                /* one edge crosses the disc: the segment formula, from the centre's distance */
                int i = cut == 1u ? 0 : cut == 2u ? 1 : 2;
                frac = gr_beam_disc_halfplane_fast((double)fa[i] / (double)ext[i]);
            } else {
                /* the cross-section's vertices in kernel units, c = M^-1 (V - p) / dd */
                double im = 1.0 / ((double)detM * dd), v[6];
                double vx[3] = {-qu, e1u - qu, e2u - qu}, vz[3] = {-qw, e1w - qw, e2w - qw};
                for (int i = 0; i < 3; i++) {
                    v[2 * i] = (M[3] * vx[i] - M[1] * vz[i]) * im;
                    v[2 * i + 1] = (M[0] * vz[i] - M[2] * vx[i]) * im;
                }
                frac = gr_beam_disc_triangle_fast(v);
            }
            if (!(frac > 0.0)) return;
            /* exact: flux area(tri n K) / (|A| area(K)) <= flux / area(K); the bound is the
             * limit of a cross-section collapsed inside the kernel and guards rounding. |A|
             * in double from the same float edges as the kernel-unit vertices above. */
            double cap = (double)bt->phi / areaK, a2 = fabs((double)e1u * e2w - (double)e1w * e2u);
            double ex = a2 > 0.0 ? (double)bt->phi * frac / (0.5 * a2) : cap;
            e_h = (float)(ex < cap ? ex : cap); /* not fmin: a libm call in this loop */
        }
    }
    uint32_t idx[3];
    tri_vertices(b, t, idx);
    const beam_vertex *v0 = &b->v[idx[0]], *v1 = &b->v[idx[1]], *v2 = &b->v[idx[2]];
    float d0 = y - v0->py, d1 = y - v1->py, d2 = y - v2->py;
    /* T and the path length at the nearest point of the cross-section (clamped barycentrics) */
    float l0 = 1.0f / 3.0f, l1 = l0, l2 = l0;
    if (det != 0.0f) {
        float inv = 1.0f / det;
        l0 = f0 * inv; l1 = f1 * inv; l2 = f2 * inv;
        l0 = l0 > 0.0f ? l0 : 0.0f; l1 = l1 > 0.0f ? l1 : 0.0f; l2 = l2 > 0.0f ? l2 : 0.0f;
        float sum = l0 + l1 + l2;
        if (sum > 0.0f) { l0 /= sum; l1 /= sum; l2 /= sum; }
        else l0 = l1 = l2 = 1.0f / 3.0f;
    }
    /* distance from the surface along the beam; negative above the surface (in air) */
    float path = l0 * d0 * v0->ity + l1 * d1 * v1->ity + l2 * d2 * v2->ity;
    if (path < 0.0f) return;
    if (!(e_h > 0.0f)) return;
    gr_beam_hits *o = s->out;
    if (o->n >= o->cap) {
        /* the list grows: a point near a strong focus under fine cells lies in thousands of
         * blurred footprints, and every one of them carries light */
        int cap = o->cap ? 2 * o->cap : 64;
        gr_beam_hit *nh = realloc(o->h, (size_t)cap * sizeof *nh);
        if (!nh) { s->oom = 1; return; }
        o->h = nh;
        o->cap = cap;
    }
    gr_beam_hit *h = &o->h[o->n++];
    h->prim = prim;
    h->e_h = e_h;
    h->path_m = path;
    h->T = gr_v3_norm(gr_v3(l0 * v0->tx + l1 * v1->tx + l2 * v2->tx,
                            l0 * v0->ty + l1 * v1->ty + l2 * v2->ty,
                            l0 * v0->tz + l1 * v1->tz + l2 * v2->tz));
}

/* sort by primitive id: the sum over beams then has one order whatever the lookup structure
 * (the grid's cell lists are already sorted: then a single pass) */
static int cmp_hit(const void *a, const void *b)
{
    unsigned x = ((const gr_beam_hit *)a)->prim, y = ((const gr_beam_hit *)b)->prim;
    return (x > y) - (x < y);
}

static void sort_hits(gr_beam_hit *hits, int n)
{
    /* primitive ids are unique: any sort gives the same order; long lists (near a focus)
     * must not cost n^2 */
    if (n > 32) {
        qsort(hits, (size_t)n, sizeof *hits, cmp_hit);
        return;
    }
    for (int i = 1; i < n; i++) {
        gr_beam_hit h = hits[i];
        int j = i - 1;
        while (j >= 0 && hits[j].prim > h.prim) { hits[j + 1] = hits[j]; j--; }
        hits[j + 1] = h;
    }
}

void gr_beam_hits_free(gr_beam_hits *h)
{
    if (!h) return;
    free(h->h);
    h->h = NULL;
    h->n = h->cap = 0;
}

/* The grid cell holding the sheared point (u, y, w), or -1 outside the grid. */
static inline long grid_cell(const gr_beams *b, float u, float y, float w)
{
    float fu = (u - b->g0[0]) * b->ginv[0], fy = (y - b->g0[1]) * b->ginv[1], fw = (w - b->g0[2]) * b->ginv[2];
    if (!(fu >= 0.0f && fy >= 0.0f && fw >= 0.0f)) return -1; /* also NaN */
    int iu = (int)fu, iy = (int)fy, iw = (int)fw;
    if (iu >= b->gn[0] || iy >= b->gn[1] || iw >= b->gn[2]) return -1;
    return ((long)iw * b->gn[1] + iy) * b->gn[0] + iu;
}

#define LOOKUP_CHUNK 64
int gr_beams_lookup(const gr_beams *b, gr_vec3 p, gr_beam_hits *out)
{
    out->n = 0;
    if (!b || !b->cell_first) return 0;
    lookup_state s;
    s.y = p.y;
    s.u = p.x - b->sx * p.y;
    s.w = p.z - b->sz * p.y;
    s.out = out;
    s.oom = 0;
    long c = grid_cell(b, s.u, s.y, s.w);
    if (c < 0) return 0;
    /* the point in the boxes' 16-bit units (clamped: a point past the span tests as at its
     * end, conservatively) */
    int qp[3];
    float pc[3] = {s.u, s.y, s.w};
    for (int a = 0; a < 3; a++) {
        float q = (pc[a] - b->q0[a]) * b->qinv[a];
        qp[a] = q <= 0.0f ? 0 : q >= 65535.0f ? 65535 : (int)q;
    }
    /* the cell's primitives in increasing id: the hits come out sorted, whatever the grid */
    const uint32_t *cp = b->cell_prim;
    const beam_qbox *qbox = b->qbox; /* locals: the hit list's writes cannot alias them */
    uint32_t pass[LOOKUP_CHUNK];
    for (uint32_t i0 = b->cell_first[c], e = b->cell_first[c + 1]; i0 < e; i0 += LOOKUP_CHUNK) {
        uint32_t e1 = e - i0 < LOOKUP_CHUNK ? e : i0 + LOOKUP_CHUNK;
        int np = 0;
        for (uint32_t i = i0; i < e1; i++) {
            const uint16_t *bx = qbox[cp[i]].q;
            /* the box test without branches (most candidates fail it, unpredictably) */
            int in = (qp[0] >= bx[0]) & (qp[0] <= bx[3]) & (qp[1] >= bx[1]) & (qp[1] <= bx[4]) & (qp[2] >= bx[2]) & (qp[2] <= bx[5]);
            pass[np] = cp[i];
            np += in;
        }
        for (int k = 0; k < np; k++) beam_test(b, pass[k], qbox[pass[k]].tri, &s);
    }
    if (s.oom) return -1;
    sort_hits(out->h, out->n);
    return out->n;
}

/* ---- local refinement (docs/reference.md 2.2, "Local refinement") ---- */

double gr_beam_refine_radius(const gr_beam_params *p)
{
    if (p->refine_factor <= 1 || !(p->refine_angle > 0.0) || !p->camera) return -1.0;
    const gr_camera *c = p->camera;
    /* T0 (unit, heading down) from the shear: T0 is parallel to (sx, 1, sz) T0_y */
    gr_dvec3 T0 = gr_d3_norm(gr_d3(-p->shear_x, -1.0, -p->shear_z));
    gr_dvec3 f = gr_d3(c->forward[0], c->forward[1], c->forward[2]);
    gr_dvec3 rt = gr_d3(c->right[0], c->right[1], c->right[2]), up = gr_d3(c->up[0], c->up[1], c->up[2]);
    double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), ta = tf * (double)c->width / (double)c->height;
    double ca = cos(p->refine_angle), sa = sin(p->refine_angle);
    double up_span = fmax(0.0, -(double)p->eye.y), down_span = fmax(0.0, (double)p->eye.y - p->region.y_min);
    /* a frame around T0 for the cone's rim */
    gr_dvec3 hlp = fabs(T0.x) < 0.9 ? gr_d3(1, 0, 0) : gr_d3(0, 0, 1);
    gr_dvec3 e1 = gr_d3_norm(gr_d3_cross(T0, hlp)), e2 = gr_d3_cross(T0, e1);
    enum { NG = 128, NR = 256 };
    double best = -1.0;
    for (int n = 0; n < (NG + 1) * (NG + 1) + 2 * NR + 2; n++) {
        gr_dvec3 d;
        if (n < (NG + 1) * (NG + 1)) { /* a grid over the frustum (its border included) */
            int ix = n % (NG + 1), iy = n / (NG + 1);
            d = gr_d3_norm(gr_d3_madd(gr_d3_madd(f, rt, (2.0 * ix / NG - 1.0) * ta), up, (1.0 - 2.0 * iy / NG) * tf));
        } else { /* the cone's axis and rim, +T0 then -T0, where the frustum holds them */
            int m = n - (NG + 1) * (NG + 1), sg = m < NR + 1 ? 1 : -1, k = m % (NR + 1);
            gr_dvec3 ax = gr_d3_scale(T0, sg);
            double ph = 2.0 * GR_PI * k / NR;
            d = k == NR ? ax : gr_d3_madd(gr_d3_scale(ax, ca), gr_d3_madd(gr_d3_scale(e1, cos(ph)), e2, sin(ph)), sa);
            double z = gr_d3_dot(d, f);
            if (!(z > 0.0) || fabs(gr_d3_dot(d, rt)) > ta * z * (1.0 + 1e-9) || fabs(gr_d3_dot(d, up)) > tf * z * (1.0 + 1e-9))
                continue;
        }
        if (fabs(gr_d3_dot(d, T0)) < ca * (1.0 - 1e-12) || fabs(d.y) < 1e-6) continue;
        /* sheared drift of the ray per metre of height: how fast it crosses beams of drift 0 */
        double gu = d.x / d.y - p->shear_x, gw = d.z / d.y - p->shear_z;
        double rr = sqrt(gu * gu + gw * gw) * (d.y > 0.0 ? up_span : down_span);
        if (rr > best) best = rr;
    }
    return best;
}

/* The surface's topology: the base grid's vertices (i + j (nu + 1)) first, then the extra
 * vertices of refined and transition cells, by their rest offsets from the patch corner. */
typedef struct topo {
    int nu, nw, F;
    double h;
    size_t nv0;              /* grid vertices */
    double *rx;              /* extra vertices: rest offsets (u, w) from the patch corner */
    size_t nx, capx;
    int ci0, cj0, mu, mw;    /* window of the fine lattice (in fine units) mapped by fmap */
    uint32_t *fmap;          /* fine lattice point -> vertex index, UINT32_MAX = none yet */
    int oom;
} topo;

static uint32_t topo_extra(topo *T, double ru, double rw)
{
    if (T->nx == T->capx) {
        size_t cap = T->capx ? 2 * T->capx : 1024;
        double *n = realloc(T->rx, 2 * cap * sizeof *n);
        if (!n) { T->oom = 1; return 0; }
        T->rx = n;
        T->capx = cap;
    }
    T->rx[2 * T->nx] = ru;
    T->rx[2 * T->nx + 1] = rw;
    return (uint32_t)(T->nv0 + T->nx++);
}

/* The vertex at fine lattice point (I, J) (cells of h / F): a grid vertex where it is one,
 * else an extra vertex made once and shared by every cell that touches it. */
static uint32_t topo_fine(topo *T, int I, int J)
{
    int F = T->F;
    if (I % F == 0 && J % F == 0) return (uint32_t)(I / F + (size_t)(J / F) * (size_t)(T->nu + 1));
    size_t k = (size_t)(I - T->ci0 * F) + (size_t)(J - T->cj0 * F) * (size_t)T->mu;
    if (T->fmap[k] == UINT32_MAX) T->fmap[k] = topo_extra(T, (double)I * T->h / F, (double)J * T->h / F);
    return T->fmap[k];
}

/* Cell (i, j)'s triangles into vi (3 per triangle, NULL: count only) and their kind into
 * lev (0 grid, 1 fine, 2 transition fan); returns their number. A refined cell: F x F
 * sub-cells of two triangles each, wound as the grid's (area vectors down). A cell beside
 * a refined one: a fan from an added centre vertex over its boundary, whose edges shared
 * with refined neighbours carry their F - 1 inner fine vertices (no T-junctions). */
static int cell_tris(topo *T, const uint8_t *ref, int i, int j, uint32_t *vi, uint8_t *lev)
{
    int nu = T->nu, nw = T->nw, F = T->F;
    size_t c = (size_t)i + (size_t)j * (size_t)nu;
    uint32_t row = (uint32_t)nu + 1, v00 = (uint32_t)(i + (size_t)j * row);
    if (ref && ref[c]) {
        if (!vi) return 2 * F * F;
        int n = 0;
        for (int sj = 0; sj < F; sj++)
            for (int si = 0; si < F; si++) {
                int I = i * F + si, J = j * F + sj;
                uint32_t a = topo_fine(T, I, J), b = topo_fine(T, I + 1, J), d = topo_fine(T, I + 1, J + 1), e = topo_fine(T, I, J + 1);
                uint32_t *o = vi + 6 * n;
                o[0] = a; o[1] = b; o[2] = d;
                o[3] = a; o[4] = d; o[5] = e;
                lev[2 * n] = lev[2 * n + 1] = 1;
                n++;
            }
        return 2 * F * F;
    }
    /* refined 4-neighbours: below (j - 1), right (i + 1), above (j + 1), left (i - 1) */
    int nb[4] = {ref && j > 0 && ref[c - (size_t)nu], ref && i + 1 < nu && ref[c + 1], ref && j + 1 < nw && ref[c + (size_t)nu],
                 ref && i > 0 && ref[c - 1]};
    if (!nb[0] && !nb[1] && !nb[2] && !nb[3]) {
        if (vi) {
            /* the grid's cell: (v00, v10, v11), (v00, v11, v01) */
            vi[0] = v00; vi[1] = v00 + 1; vi[2] = v00 + row + 1;
            vi[3] = v00; vi[4] = v00 + row + 1; vi[5] = v00 + row;
            lev[0] = lev[1] = 0;
        }
        return 2;
    }
    int nbound = 4;
    for (int e = 0; e < 4; e++) nbound += nb[e] ? F - 1 : 0;
    if (!vi) return nbound;
    /* the boundary counter-clockwise in (u, w) as the grid's triangles wind, from (i, j) */
    uint32_t poly[4 * 64 + 4];
    int np = 0, I0 = i * F, J0 = j * F;
    for (int k = 0; k < F; k++) if (k == 0 || nb[0]) poly[np++] = topo_fine(T, I0 + k, J0);
    for (int k = 0; k < F; k++) if (k == 0 || nb[1]) poly[np++] = topo_fine(T, I0 + F, J0 + k);
    for (int k = 0; k < F; k++) if (k == 0 || nb[2]) poly[np++] = topo_fine(T, I0 + F - k, J0 + F);
    for (int k = 0; k < F; k++) if (k == 0 || nb[3]) poly[np++] = topo_fine(T, I0, J0 + F - k);
    uint32_t ctr = topo_extra(T, (i + 0.5) * T->h, (j + 0.5) * T->h);
    for (int k = 0; k < np; k++) {
        vi[3 * k] = ctr;
        vi[3 * k + 1] = poly[k];
        vi[3 * k + 2] = poly[(k + 1) % np];
        lev[k] = 2;
    }
    return np;
}

static gr_status build_surface_mesh(gr_rtc *rtc, gr_beams *b, const gr_dvec3 *pos, gr_error *err)
{
    RTCDevice dev = rtc->device;
    size_t nv = b->nv, nt = b->ntri;
    b->surface = rtcNewScene(dev);
    if (!b->surface) return gr_rtc_check(rtc, "reference: surface mesh", err);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
    if (v && idx) {
        for (size_t i = 0; i < nv; i++) {
            v[3 * i] = (float)pos[i].x; v[3 * i + 1] = (float)pos[i].y; v[3 * i + 2] = (float)pos[i].z;
        }
        for (size_t t = 0; t < nt; t++) tri_vertices(b, (uint32_t)t, idx + 3 * t);
        rtcCommitGeometry(g);
        rtcAttachGeometry(b->surface, g);
    }
    rtcReleaseGeometry(g);
    rtcCommitScene(b->surface);
    return gr_rtc_check(rtc, "reference: building the surface mesh", err);
}

/* The lookup grid over the primitives' boxes (docs/reference.md 2.2, "Lookups"). Cells of
 * GRID_CELL_BOX times the mean box extent per axis (measured on the default scene: 0.35
 * against 0.25, 0.5, 1 and 2; a box then spans about 22 cells and a cell lists about 16
 * boxes), coarsened uniformly while the entries exceed GRID_ENTRIES_PER_PRIM per primitive. Filled in primitive order, so every
 * cell's list is sorted by primitive id. */
#define GRID_CELL_BOX 0.35
#define GRID_ENTRIES_PER_PRIM 32.0

static void grid_range(const gr_beams *b, const float *bx, int lo[3], int hi[3])
{
    for (int a = 0; a < 3; a++) {
        float f0 = (bx[a] - b->g0[a]) * b->ginv[a], f1 = (bx[3 + a] - b->g0[a]) * b->ginv[a];
        int i0 = f0 > 0.0f ? (int)f0 : 0, i1 = f1 > 0.0f ? (int)f1 : 0;
        lo[a] = i0 < b->gn[a] ? i0 : b->gn[a] - 1;
        hi[a] = i1 < b->gn[a] ? i1 : b->gn[a] - 1;
    }
}

/* Runs fn on n jobs (each `size` bytes apart), job 0 on the calling thread and the others on
 * their own threads (serially if a thread cannot be started: the same result). */
#define GRID_MAX_THREADS 64
static void run_jobs(void *(*fn)(void *), void *jobs, size_t size, int n)
{
    pthread_t th[GRID_MAX_THREADS];
    int started[GRID_MAX_THREADS] = {0};
    for (int i = 1; i < n; i++) started[i] = pthread_create(&th[i], NULL, fn, (char *)jobs + (size_t)i * size) == 0;
    fn(jobs);
    for (int i = 1; i < n; i++) {
        if (started[i]) pthread_join(th[i], NULL);
        else fn((char *)jobs + (size_t)i * size);
    }
}

typedef struct grid_job {
    gr_beams *b;
    uint32_t np;
    int w0, w1;   /* the w-layers of cells this worker owns */
    int fill;     /* 0: count the entries per cell; 1: fill them */
} grid_job;

static void *grid_work(void *arg)
{
    grid_job *j = arg;
    gr_beams *b = j->b;
    const int nu = b->gn[0], ny = b->gn[1];
    for (uint32_t k = 0; k < j->np; k++) {
        int l[3], h[3];
        grid_range(b, b->box + 6 * (size_t)k, l, h);
        int w0 = l[2] > j->w0 ? l[2] : j->w0, w1 = h[2] < j->w1 - 1 ? h[2] : j->w1 - 1;
        for (int iw = w0; iw <= w1; iw++)
            for (int iy = l[1]; iy <= h[1]; iy++)
                for (int iu = l[0]; iu <= h[0]; iu++) {
                    size_t c = ((size_t)iw * ny + iy) * nu + iu;
                    if (j->fill) b->cell_prim[b->cell_first[c]++] = k;
                    else b->cell_first[c + 1]++;
                }
    }
    return NULL;
}

typedef struct box_job {
    gr_beams *b;
    uint32_t k0, k1;
} box_job;

static void *box_work(void *arg)
{
    box_job *j = arg;
    for (uint32_t k = j->k0; k < j->k1; k++) prim_box(j->b, k, j->b->box + 6 * (size_t)k, j->b->box + 6 * (size_t)k + 3);
    return NULL;
}

static gr_status build_grid(gr_beams *b, uint32_t np, int threads, gr_error *err)
{
    if (np == 0) return GR_OK;
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX}, ext[3] = {0, 0, 0};
    for (uint32_t k = 0; k < np; k++) {
        const float *bx = b->box + 6 * (size_t)k;
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], bx[a]);
            hi[a] = fmax(hi[a], bx[3 + a]);
            ext[a] += (double)bx[3 + a] - bx[a];
        }
    }
    double cell[3];
    for (int a = 0; a < 3; a++) {
        double span = hi[a] - lo[a];
        cell[a] = GRID_CELL_BOX * ext[a] / np;
        if (!(cell[a] > span * 1e-6)) cell[a] = span > 0.0 ? span * 1e-6 : 1.0;
    }
    /* count the entries per cell (each worker owns a range of w-layers of cells and scans
     * every box), then prefix-sum them; over the budget, coarser cells and count again */
    grid_job jobs[GRID_MAX_THREADS];
    int nt = 1;
    size_t ncells = 0, entries = SIZE_MAX;
    const double budget = GRID_ENTRIES_PER_PRIM * np + 1024.0;
    for (int attempt = 0; attempt < 64 && entries == SIZE_MAX; attempt++) {
        if (attempt > 0)
            for (int a = 0; a < 3; a++) cell[a] *= 1.25;
        double nc = 1.0;
        for (int a = 0; a < 3; a++) {
            double n = floor((hi[a] - lo[a]) / cell[a]) + 1.0;
            if (n > 1e6) { cell[a] = (hi[a] - lo[a]) / 1e6; n = 1e6 + 1.0; }
            b->gn[a] = (int)n;
            b->g0[a] = (float)lo[a];
            b->ginv[a] = (float)(1.0 / cell[a]);
            nc *= n;
        }
        if (nc > budget) continue; /* more cells than entries allowed: coarser */
        ncells = (size_t)b->gn[0] * (size_t)b->gn[1] * (size_t)b->gn[2];
        free(b->cell_first);
        b->cell_first = calloc(ncells + 1, sizeof *b->cell_first);
        if (!b->cell_first)
            return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid (%zu cells)", ncells);
        nt = threads < 1 ? 1 : threads > GRID_MAX_THREADS ? GRID_MAX_THREADS : threads;
        if (nt > b->gn[2]) nt = b->gn[2];
        for (int i = 0; i < nt; i++) {
            jobs[i].b = b;
            jobs[i].np = np;
            jobs[i].w0 = (int)((long)b->gn[2] * i / nt);
            jobs[i].w1 = (int)((long)b->gn[2] * (i + 1) / nt);
            jobs[i].fill = 0;
        }
        run_jobs(grid_work, jobs, sizeof jobs[0], nt);
        size_t total = 0; /* in size_t: an attempt far over the budget must not wrap the lists' uint32 */
        for (size_t c = 0; c < ncells && (double)total <= budget; c++) {
            total += b->cell_first[c + 1];
            b->cell_first[c + 1] = (uint32_t)total;
        }
        if ((double)total <= budget) entries = total;
    }
    if (entries == SIZE_MAX || entries >= UINT32_MAX || ncells >= UINT32_MAX)
        return gr_fail(err, GR_E_NOMEM, "reference: the beam lookup grid needs more than %.0f entries, too many", budget);
    b->cell_prim = malloc((entries ? entries : 1) * sizeof *b->cell_prim);
    if (!b->cell_prim)
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid (%zu entries)", entries);
    /* fill, each cell by one worker in primitive order (deterministic): cell_first[c] runs
     * ahead as the cursor while filling, restored below */
    for (int i = 0; i < nt; i++) jobs[i].fill = 1;
    run_jobs(grid_work, jobs, sizeof jobs[0], nt);
    for (size_t c = ncells; c > 0; c--) b->cell_first[c] = b->cell_first[c - 1];
    b->cell_first[0] = 0;
    /* the 16-bit boxes; the float ones are no longer needed */
    b->qbox = malloc((size_t)np * sizeof *b->qbox);
    if (!b->qbox) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %u beam boxes", np);
    double qunit[3];
    for (int a = 0; a < 3; a++) {
        double span = hi[a] - lo[a];
        qunit[a] = span > 0.0 ? span / 65535.0 : 1.0;
        b->q0[a] = (float)lo[a];
        b->qinv[a] = (float)(1.0 / qunit[a]);
    }
    for (uint32_t k = 0; k < np; k++) {
        const float *bx = b->box + 6 * (size_t)k;
        uint16_t *q = b->qbox[k].q;
        b->qbox[k].tri = b->prim_tri[k];
        for (int a = 0; a < 3; a++) {
            double l = floor(((double)bx[a] - (double)b->q0[a]) / qunit[a]) - 1.0;
            double h = ceil(((double)bx[3 + a] - (double)b->q0[a]) / qunit[a]) + 1.0;
            q[a] = (uint16_t)(l < 0.0 ? 0.0 : l > 65535.0 ? 65535.0 : l);
            q[3 + a] = (uint16_t)(h < 0.0 ? 0.0 : h > 65535.0 ? 65535.0 : h);
        }
    }
    free(b->box);
    b->box = NULL;
    free(b->prim_tri); /* each primitive's triangle now travels with its box */
    b->prim_tri = NULL;
    b->stats.grid_entries = entries;
    b->stats.grid_cells = ncells;
    return GR_OK;
}

/* Number of depth slabs for a beam whose corners drift by up to `drift` metres per metre
 * of height (in sheared coordinates): about `scale` cells of drift per slab keeps its box
 * tight. */
static uint32_t slab_count(double depth, double drift, double cell, double scale)
{
    if (!(depth > 0.0)) return 1;
    double n = ceil(depth * drift / (cell * scale));
    if (!(n >= 1.0)) n = 1.0;
    if (n > 4096.0) n = 4096.0;
    return (uint32_t)n;
}

gr_status gr_beams_build(gr_rtc *rtc, const gr_beam_params *p, gr_beams **out, gr_error *err)
{
    *out = NULL;
    double t_start = now_s();
    const gr_beam_region *r = &p->region;
    double ext_u = (r->u1 - r->u0) + 2.0 * p->pad_m, ext_w = (r->w1 - r->w0) + 2.0 * p->pad_m;
    if (!(ext_u > 0.0 && ext_w > 0.0) || p->res < 1)
        return gr_fail(err, GR_E_INPUT, "reference: empty lit region (%g x %g m) or surface_res %d < 1", ext_u, ext_w, p->res);
    double h = p->cell_m > 0.0 ? p->cell_m : sqrt(ext_u * ext_w) / (double)p->res;
    double nu_d = ceil(ext_u / h) + 1.0, nw_d = ceil(ext_w / h) + 1.0;
    if (nu_d * nw_d * 2.0 > 1.0e9)
        return gr_fail(err, GR_E_INPUT, "reference.surface_res: %d gives %.0f x %.0f cells, too many", p->res, nu_d, nw_d);
    gr_beams *b = calloc(1, sizeof *b);
    if (!b) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for beams");
    b->nu = (int)nu_d;
    b->nw = (int)nw_d;
    b->y_min = r->y_min;
    b->sx = (float)p->shear_x;
    b->sz = (float)p->shear_z;
    double start_u = r->u0 - p->pad_m - p->jitter[0] * h, start_w = r->w0 - p->pad_m - p->jitter[1] * h;
    if (p->cell_m > 0.0) { /* another set's grid lines: the last at or before the patch's start */
        start_u = p->anchor_u + floor((r->u0 - p->pad_m - p->anchor_u) / h) * h;
        start_w = p->anchor_w + floor((r->w0 - p->pad_m - p->anchor_w) / h) * h;
    }
    /* topology: the grid, with the cells near P_s refined (docs/reference.md 2.2) */
    topo tp;
    memset(&tp, 0, sizeof tp);
    tp.nu = b->nu;
    tp.nw = b->nw;
    tp.F = p->refine_factor > 1 ? p->refine_factor : 1;
    if (tp.F > 64) {
        gr_beams_destroy(b);
        return gr_fail(err, GR_E_INPUT, "reference.refine_factor: %d, at most 64", p->refine_factor);
    }
    tp.h = h;
    tp.nv0 = (size_t)(b->nu + 1) * (size_t)(b->nw + 1);
    double rho = tp.F > 1 ? gr_beam_refine_radius(p) : -1.0;
    uint8_t *ref = NULL;
    size_t nref = 0, ntrans = 0;
    if (rho >= 0.0) {
        ref = calloc((size_t)b->nu * (size_t)b->nw, 1);
        if (!ref) {
            gr_beams_destroy(b);
            return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the refinement");
        }
        /* cells whose rest square comes within rho (plus the waves' horizontal displacement)
         * of P_s, the camera's sheared position */
        double A = 0.0;
        for (int k = 0; k < p->water->n_waves; k++) A += fabs(p->water->waves[k].amplitude_m);
        double pu = (double)p->eye.x - p->shear_x * p->eye.y - start_u, pw = (double)p->eye.z - p->shear_z * p->eye.y - start_w;
        double rr = rho + A;
        int ci0 = b->nu, ci1 = -1, cj0 = b->nw, cj1 = -1;
        for (int j = 0; j < b->nw; j++)
            for (int i = 0; i < b->nu; i++) {
                double du = fmax(fmax(i * h - pu, pu - (i + 1) * h), 0.0), dw = fmax(fmax(j * h - pw, pw - (j + 1) * h), 0.0);
                if (du * du + dw * dw > rr * rr) continue;
                ref[(size_t)i + (size_t)j * (size_t)b->nu] = 1;
                nref++;
                if (i < ci0) ci0 = i;
                if (i > ci1) ci1 = i;
                if (j < cj0) cj0 = j;
                if (j > cj1) cj1 = j;
            }
        if (nref) {
            tp.ci0 = ci0;
            tp.cj0 = cj0;
            tp.mu = (ci1 - ci0 + 1) * tp.F + 1;
            tp.mw = (cj1 - cj0 + 1) * tp.F + 1;
            tp.fmap = malloc((size_t)tp.mu * (size_t)tp.mw * sizeof *tp.fmap);
            if (!tp.fmap) {
                free(ref); gr_beams_destroy(b);
                return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the refinement");
            }
            memset(tp.fmap, 0xff, (size_t)tp.mu * (size_t)tp.mw * sizeof *tp.fmap);
        } else {
            free(ref);
            ref = NULL;
        }
    }
    size_t ntri = 0;
    for (int j = 0; j < b->nw; j++)
        for (int i = 0; i < b->nu; i++) {
            int n = cell_tris(&tp, ref, i, j, NULL, NULL);
            ntri += (size_t)n;
            if (ref && !ref[(size_t)i + (size_t)j * (size_t)b->nu] && n != 2) ntrans++;
        }
    b->tri = aligned_alloc(64, ntri * sizeof *b->tri);
    uint8_t *lev = malloc(ntri);
    if (!b->tri || !lev || ntri >= UINT32_MAX) {
        free(ref); free(lev); free(tp.fmap); gr_beams_destroy(b);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %zu surface triangles (reference.surface_res)", ntri);
    }
    /* Ctrl-C at a fine surface (gigabytes of triangles): a cheap read per 65536 triangles and
     * per row of cells below */
    for (size_t t = 0; t < ntri; t++) {
        if ((t & 65535) == 0 && p->interrupt && *p->interrupt) {
            free(ref); free(lev); free(tp.fmap); gr_beams_destroy(b);
            return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
        }
        memset(&b->tri[t], 0, sizeof b->tri[t]);
    }
    {
        /* one cell's triangles: at most 2 F^2 (refined) or 4 F (a fan) */
        size_t F2 = (size_t)tp.F * (size_t)tp.F;
        uint32_t *buf = malloc(3 * (2 * F2 + 4 * (size_t)tp.F + 4) * sizeof *buf);
        if (!buf) tp.oom = 1;
        size_t t = 0;
        for (int j = 0; j < b->nw && buf && !(p->interrupt && *p->interrupt); j++)
            for (int i = 0; i < b->nu; i++) {
                int n = cell_tris(&tp, ref, i, j, buf, lev + t);
                for (int k = 0; k < n; k++, t++)
                    for (int c = 0; c < 3; c++) b->tri[t].vi[c] = buf[3 * k + c];
            }
        free(buf);
    }
    free(ref);
    free(tp.fmap);
    if (p->interrupt && *p->interrupt) {
        free(lev); free(tp.rx); gr_beams_destroy(b);
        return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
    }
    b->stats.refine_factor = nref ? tp.F : 1;
    b->stats.refined_cells = nref;
    b->stats.transition_cells = ntrans;
    b->stats.refine_radius_m = rho;
    size_t nv = tp.nv0 + tp.nx;
    b->nv = nv;
    b->ntri = ntri;
    gr_dvec3 *pos = malloc(nv * sizeof *pos);
    b->v = malloc(nv * sizeof *b->v);
    float *drift = malloc(ntri * sizeof *drift);
    int disc = p->disc_radius > 0.0;
    float *jv = NULL; /* per vertex: the slope Jacobian J (4 floats) */
    if (disc) {
        jv = malloc(nv * 4 * sizeof *jv);
    }
    b->disc = disc;
    if (tp.oom || !pos || !b->v || !drift || (disc && !jv)) {
        free(pos); free(drift); free(jv); free(lev); free(tp.rx); gr_beams_destroy(b);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %zu surface vertices (reference.surface_res)", nv);
    }
    gr_dvec3 I = p->sun_dir;
    double eta = 1.0 / p->ior; /* air (n = 1) to water, seed eq. 5.5.1 with eta = n1 / n2 */
    for (size_t k = 0; k < nv; k++) {
        if ((k & 4095) == 0 && p->interrupt && *p->interrupt) { /* Ctrl-C: a cheap read per 4096 vertices */
            free(pos); free(drift); free(jv); free(lev); free(tp.rx); gr_beams_destroy(b);
            return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
        }
        {
            double x0, z0;
            if (k < tp.nv0) {
                int i = (int)(k % (size_t)(b->nu + 1)), j = (int)(k / (size_t)(b->nu + 1));
                x0 = p->origin.x + start_u + i * h;
                z0 = p->origin.z + start_w + j * h;
            } else {
                x0 = p->origin.x + start_u + tp.rx[2 * (k - tp.nv0)];
                z0 = p->origin.z + start_w + tp.rx[2 * (k - tp.nv0) + 1];
            }
            gr_dvec3 P = gr_gerstner_position(p->water, x0, z0, p->water->time_s);
            gr_dvec3 n;
            gr_gerstner_frame(p->water, x0, z0, p->water->time_s, NULL, NULL, &n);
            pos[k] = gr_d3_sub(P, p->origin);
            beam_vertex *v = &b->v[k];
            double cos_i = -gr_d3_dot(I, n);
            gr_dvec3 T = cos_i > 0.0 ? gr_refract_d(I, n, eta) : gr_d3(0, 0, 0);
            v->py = (float)pos[k].y;
            v->pu = (float)(pos[k].x - p->shear_x * pos[k].y);
            v->pw = (float)(pos[k].z - p->shear_z * pos[k].y);
            v->tx = (float)T.x; v->ty = (float)T.y; v->tz = (float)T.z;
            /* a refracted ray that does not head down (grazing sun on a steep back slope)
             * leaves the water again at once: such vertices carry no beam (docs/reference.md) */
            if (!(T.y < -1e-4)) {
                v->ft = -1.0f;
                v->au = v->aw = 0.0f;
                v->ity = -1.0f;
                continue;
            }
            v->ft = p->fresnel ? (float)(1.0 - gr_fresnel_exact(cos_i, 1.0, p->ior)) : 1.0f;
            if (disc) {
                double J[4];
                slope_jacobian(I, n, eta, p->disc_e1, p->disc_e2, J);
                for (int c = 0; c < 4; c++) jv[4 * k + (size_t)c] = (float)J[c];
            }
            v->au = (float)(T.x / T.y - p->shear_x);
            v->aw = (float)(T.z / T.y - p->shear_z);
            v->ity = (float)(1.0 / T.y);
        }
    }
    free(tp.rx);
    size_t lit = 0;
    for (size_t t = 0; t < ntri; t++) {
        if ((t & 65535) == 0 && p->interrupt && *p->interrupt) { /* Ctrl-C, every 65536 triangles */
            free(pos); free(drift); free(jv); free(lev); gr_beams_destroy(b);
            return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
        }
        beam_tri *bt = &b->tri[t];
        uint32_t idx[3];
        tri_vertices(b, (uint32_t)t, idx);
        const beam_vertex *v0 = &b->v[idx[0]], *v1 = &b->v[idx[1]], *v2 = &b->v[idx[2]];
        bt->ytop = fmaxf(v0->py, fmaxf(v1->py, v2->py));
        bt->ybar = bt->ytop;
        drift[t] = 0.0f;
        if (v0->ft < 0.0f || v1->ft < 0.0f || v2->ft < 0.0f) continue;
        /* the grid's triangles wind so that their area vector points down */
        gr_dvec3 a = gr_d3_scale(gr_d3_cross(gr_d3_sub(pos[idx[1]], pos[idx[0]]), gr_d3_sub(pos[idx[2]], pos[idx[0]])), 0.5);
        double flux = gr_d3_dot(I, a); /* sun flux through the displaced triangle per unit E_sun */
        if (!(flux > 0.0)) continue;   /* faces away from the sun: shadowed by its own wave */
        /* F_t averaged over the vertices: O(h^2) like the rest of the tessellation */
        bt->phi = (float)(flux * (v0->ft + v1->ft + v2->ft) / 3.0);
        const beam_vertex *vs[3] = {v0, v1, v2};
        /* the cross-section's coefficients for the lookups (beam_tri's c), in double */
        double xs[3], zs[3];
        for (int c = 0; c < 3; c++) {
            xs[c] = (double)vs[c]->pu + (double)vs[c]->au * ((double)bt->ytop - vs[c]->py);
            zs[c] = (double)vs[c]->pw + (double)vs[c]->aw * ((double)bt->ytop - vs[c]->py);
            bt->c[4 * c] = (float)(c ? xs[c] - xs[0] : xs[0]);
            bt->c[4 * c + 1] = (float)(c ? zs[c] - zs[0] : zs[0]);
            bt->c[4 * c + 2] = (float)(c ? (double)vs[c]->au - v0->au : v0->au);
            bt->c[4 * c + 3] = (float)(c ? (double)vs[c]->aw - v0->aw : v0->aw);
        }
        if (disc) {
            /* the beam's kernel: the disc radius times its vertices' mean Jacobian (first
             * order: the cross-section moves rigidly with the sun direction) */
            for (int c = 0; c < 4; c++)
                bt->kern[c] = (float)(p->disc_radius * (jv[4 * (size_t)idx[0] + (size_t)c] + jv[4 * (size_t)idx[1] + (size_t)c] +
                                                        jv[4 * (size_t)idx[2] + (size_t)c]) / 3.0);
            bt->ybar = (v0->py + v1->py + v2->py) / 3.0f;
            const float *M = bt->kern;
            bt->kr = 1.0001f * sqrtf(M[0] * M[0] + M[1] * M[1] + M[2] * M[2] + M[3] * M[3]);
        }
        float d = 0.0f;
        for (int c = 0; c < 3; c++) d = fmaxf(d, hypotf(vs[c]->au, vs[c]->aw));
        /* in cells of the grid: a fine triangle's slabs are F times thinner (its box as tight) */
        drift[t] = lev[t] == 1 ? d * (float)tp.F : d;
        lit++;
    }
    /* slabs: about slab_cells cells of drift each, coarsened uniformly if over the primitive budget */
    double scale = p->slab_cells > 0.0 ? p->slab_cells : 1.0;
    size_t total = 0;
    for (int attempt = 0; attempt < 64; attempt++) {
        total = 0;
        for (size_t t = 0; t < ntri; t++)
            if (b->tri[t].phi > 0.0f) total += slab_count(b->tri[t].ytop - r->y_min, drift[t], h, scale);
        if (total <= p->max_prims || total <= lit) break;
        scale *= 1.25 * (double)total / (double)p->max_prims;
    }
    free(lev);
    if (total > p->max_prims || total >= UINT32_MAX) {
        free(pos); free(drift); free(jv); gr_beams_destroy(b);
        if (nref)
            return gr_fail(err, GR_E_NOMEM,
                           "reference.surface_res: %d with refine_factor %d needs %zu beam primitives, over the budget of %zu",
                           p->res, tp.F, total, p->max_prims);
        return gr_fail(err, GR_E_NOMEM, "reference.surface_res: %d needs %zu beam primitives, over the budget of %zu",
                       p->res, total, p->max_prims);
    }
    b->prim_tri = malloc((total ? total : 1) * sizeof *b->prim_tri);
    if (!b->prim_tri) {
        free(pos); free(drift); free(jv); gr_beams_destroy(b);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %zu beam primitives", total);
    }
    uint32_t np = 0;
    for (size_t t = 0; t < ntri; t++) {
        beam_tri *bt = &b->tri[t];
        bt->first = np;
        bt->nslab = 0;
        bt->dy = 1.0f;
        if (!(bt->phi > 0.0f)) continue;
        double depth = bt->ytop - r->y_min;
        uint32_t ns = slab_count(depth, drift[t], h, scale);
        bt->dy = depth > 0.0 ? (float)(depth / ns) : 1.0f;
        bt->nslab = ns;
        for (uint32_t k = 0; k < ns; k++) b->prim_tri[np++] = (uint32_t)t;
    }
    free(drift);
    free(jv);
    b->box = malloc((np ? np : 1) * 6 * sizeof *b->box);
    if (!b->box) {
        free(pos); gr_beams_destroy(b);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %u beam primitives", np);
    }
    {
        /* the boxes, in parallel (disjoint outputs) */
        box_job jobs[GRID_MAX_THREADS];
        int nt = p->threads < 1 ? 1 : p->threads > GRID_MAX_THREADS ? GRID_MAX_THREADS : p->threads;
        for (int i = 0; i < nt; i++) {
            jobs[i].b = b;
            jobs[i].k0 = (uint32_t)((uint64_t)np * (uint64_t)i / (uint64_t)nt);
            jobs[i].k1 = (uint32_t)((uint64_t)np * (uint64_t)(i + 1) / (uint64_t)nt);
        }
        run_jobs(box_work, jobs, sizeof jobs[0], nt);
    }
    gr_status st = build_grid(b, np, p->threads, err);
    if (st == GR_OK && p->surface_mesh) st = build_surface_mesh(rtc, b, pos, err);
    free(pos);
    if (st != GR_OK) {
        gr_beams_destroy(b);
        return st;
    }
    b->stats.nu = b->nu;
    b->stats.nw = b->nw;
    b->stats.cell_m = h;
    b->stats.grid_u0 = start_u;
    b->stats.grid_w0 = start_w;
    b->stats.triangles = ntri;
    b->stats.vertices = nv;
    b->stats.lit_triangles = lit;
    b->stats.prims = np;
    b->stats.bytes = nv * sizeof *b->v + ntri * sizeof *b->tri + np * (sizeof(uint32_t) + sizeof(beam_qbox)) +
                     (b->stats.grid_cells + 1 + b->stats.grid_entries) * sizeof(uint32_t);
    b->stats.build_s = now_s() - t_start;
    *out = b;
    return GR_OK;
}

const gr_beam_stats *gr_beams_stats(const gr_beams *b) { return b ? &b->stats : NULL; }
RTCScene gr_beams_surface(const gr_beams *b) { return b ? b->surface : NULL; }
size_t gr_beams_triangle_count(const gr_beams *b) { return b ? b->ntri : 0; }

gr_vec3 gr_beams_vertex(const gr_beams *b, unsigned k)
{
    const beam_vertex *v = &b->v[k];
    return gr_v3(v->pu + b->sx * v->py, v->py, v->pw + b->sz * v->py);
}

float gr_beams_triangle(const gr_beams *b, size_t t, unsigned idx[3])
{
    uint32_t i3[3];
    tri_vertices(b, (uint32_t)t, i3);
    for (int c = 0; c < 3; c++) idx[c] = i3[c];
    return b->tri[t].phi;
}

void gr_beams_destroy(gr_beams *b)
{
    if (!b) return;
    if (b->surface) rtcReleaseScene(b->surface);
    free(b->v);
    free(b->tri);
    free(b->prim_tri);
    free(b->box);
    free(b->cell_first);
    free(b->cell_prim);
    free(b->qbox);
    free(b);
}
