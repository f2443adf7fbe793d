#include "reference/beam_grid.h"

#include <float.h>
#if defined(__SSE2__) && !defined(GR_NO_SIMD)
#include <emmintrin.h>
#endif
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "reference/phase.h"
#include "reference/pool.h"

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

/* The box of primitive `prim` (a triangle's beam over one slab) in sheared coordinates:
 * lo/hi = {u, y, w}. */
static void prim_box(const gr_beams *b, uint32_t prim, float lo3[3], float hi3[3])
{
    uint32_t t = b->prim_tri[prim];
    uint32_t nslab = b->tri[t].nslab, k = prim - b->tri[t].first;
    float lo, hi;
    slab_range(b, t, k, nslab, &lo, &hi);
    float ylo = isinf(lo) ? (float)b->y_min : lo, yhi = isinf(hi) ? b->tri[t].ys : hi;
    uint32_t idx[3];
    tri_vertices(b, t, idx);
    const beam_vertex *v[3] = {&b->v[idx[0]], &b->v[idx[1]], &b->v[idx[2]]};
    beam_slab_box(v, b->tri[t].kern, b->tri[t].ybar, b->disc, ylo, yhi, lo3, hi3);
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
    if (k > 0 && !(y < bt->ys - (float)k * bt->dy)) return;
    if (k + 1 < bt->nslab && !(y >= bt->ys - (float)(k + 1) * bt->dy)) return;
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
     * must not cost n^2, nor n log n when they come sorted (the grid's lookups always do) */
    int sorted = 1;
    for (int i = 1; i < n && sorted; i++) sorted = hits[i - 1].prim < hits[i].prim;
    if (sorted) return;
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

/* A sheared coordinate in cells from the grid's corner along axis a: the one expression that
 * the cell ranges, the entries' bytes and the lookups use (so they agree to the bit). */
static inline float grid_f(const gr_beams *b, int a, float x) { return (x - b->g0[a]) * b->ginv[a]; }

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
    /* the grid cell holding the point (none outside the grid, NaN included) and the point in
     * that cell's bytes */
    float f[3] = {grid_f(b, 0, s.u), grid_f(b, 1, s.y), grid_f(b, 2, s.w)};
    if (!(f[0] >= 0.0f && f[1] >= 0.0f && f[2] >= 0.0f)) return 0;
    int ic[3];
    uint8_t qp[3];
    for (int a = 0; a < 3; a++) {
        ic[a] = (int)f[a];
        if (ic[a] >= b->gn[a]) return 0;
        qp[a] = grid_qbyte(grid_qcoord(f[a]), ic[a]);
    }
    long c = ((long)ic[2] * b->gn[1] + ic[1]) * b->gn[0] + ic[0];
    /* the cell's primitives in increasing id: the hits come out sorted, whatever the grid */
    const uint32_t *cp = b->cell_prim, *pt = b->prim_tri; /* locals: the hit list's writes cannot alias them */
    const uint8_t *q = b->cell_q;
    const size_t qs = b->cell_q_stride;
    uint32_t pass[LOOKUP_CHUNK];
#if defined(__SSE2__) && !defined(GR_NO_SIMD)
    const __m128i pv[3] = {_mm_set1_epi8((char)qp[0]), _mm_set1_epi8((char)qp[1]), _mm_set1_epi8((char)qp[2])};
#endif
    for (uint32_t i0 = b->cell_first[c], e = b->cell_first[c + 1]; i0 < e; i0 += LOOKUP_CHUNK) {
        uint32_t e1 = e - i0 < LOOKUP_CHUNK ? e : i0 + LOOKUP_CHUNK;
        int np = 0;
#if defined(__SSE2__) && !defined(GR_NO_SIMD)
        /* 16 entries at a time: lo <= p as max(lo, p) == p, p <= hi as min(hi, p) == p */
        for (uint32_t i = i0; i < e1; i += 16) {
            __m128i m = _mm_set1_epi8((char)0xff);
            for (int a = 0; a < 3; a++) {
                __m128i lo = _mm_loadu_si128((const __m128i *)(q + (size_t)(2 * a) * qs + i));
                __m128i hi = _mm_loadu_si128((const __m128i *)(q + (size_t)(2 * a + 1) * qs + i));
                m = _mm_and_si128(m, _mm_cmpeq_epi8(_mm_max_epu8(lo, pv[a]), pv[a]));
                m = _mm_and_si128(m, _mm_cmpeq_epi8(_mm_min_epu8(hi, pv[a]), pv[a]));
            }
            unsigned bits = (unsigned)_mm_movemask_epi8(m);
            if (e1 - i < 16) bits &= (1u << (e1 - i)) - 1u;
            while (bits) {
                pass[np++] = cp[i + (uint32_t)__builtin_ctz(bits)];
                bits &= bits - 1u;
            }
        }
#else
        for (uint32_t i = i0; i < e1; i++) {
            /* without branches (most candidates fail, unpredictably) */
            int in = 1;
            for (int a = 0; a < 3; a++) in &= (q[(size_t)(2 * a) * qs + i] <= qp[a]) & (qp[a] <= q[(size_t)(2 * a + 1) * qs + i]);
            pass[np] = cp[i];
            np += in;
        }
#endif
        for (int k = 0; k < np; k++) beam_test(b, pass[k], pt[pass[k]], &s);
    }
    if (s.oom) return -1;
    sort_hits(out->h, out->n);
    return out->n;
}

int gr_beams_lookup_brute(const gr_beams *b, gr_vec3 p, gr_beam_hits *out)
{
    out->n = 0;
    if (!b || !b->prim_tri) return 0;
    lookup_state s = {p.x - b->sx * p.y, p.y, p.z - b->sz * p.y, out, 0};
    for (uint32_t k = 0; k < (uint32_t)b->stats.prims; k++) beam_test(b, k, b->prim_tri[k], &s);
    if (s.oom) return -1;
    sort_hits(out->h, out->n);
    return out->n;
}

/* The lookup grid over the primitives' boxes (docs/reference.md 2.2, "Lookups"). Cells of
 * GRID_CELL_BOX times the mean box extent per axis, coarsened uniformly while the entries
 * exceed GRID_ENTRIES_PER_PRIM per primitive. With the boxes in the lists (16 candidates a
 * test) a candidate costs little and an entry a byte write per end: 1.0 (0.35 when each
 * candidate read its box from a primitive array; issue 30 measured 0.7, 1.0 and 1.4: the
 * march the same within the machine's drift, the grid 4.0, 2.7 and 1.9 CPU-s a render, peak
 * memory 440, 386 and 353 MB). Filled in primitive order, so every cell's list is sorted by
 * primitive id. The cap: 16 entries of 10 bytes per primitive (typically 8), the bytes the
 * 32 entries of 4 bytes and a 16-bit box per primitive took before, so the memory model
 * (reference/memory.h) holds as it did. */
#define GRID_CELL_BOX 1.0
#define GRID_ENTRIES_PER_PRIM 16.0

/* Box bx's cell range (lower u, y, w then upper, clamped to the grid) into r and its ends in
 * cell units (grid_qcoord, the entries' bytes) into g, from one grid coordinate per end. */
static void grid_range(const gr_beams *b, const float *bx, int32_t r[6], int32_t g[6])
{
    for (int a = 0; a < 3; a++) {
        float f0 = grid_f(b, a, bx[a]), f1 = grid_f(b, a, bx[3 + a]);
        int i0 = f0 > 0.0f ? (int)f0 : 0, i1 = f1 > 0.0f ? (int)f1 : 0;
        r[a] = i0 < b->gn[a] ? i0 : b->gn[a] - 1;
        r[3 + a] = i1 < b->gn[a] ? i1 : b->gn[a] - 1;
        g[a] = grid_qcoord(f0);
        g[3 + a] = grid_qcoord(f1);
    }
}

typedef struct job_call {
    void *(*fn)(void *);
    void *arg;
    double t0, t1;
} job_call;

static void *job_main(void *arg)
{
    job_call *c = arg;
    c->t0 = gr_ref_mono_s();
    c->fn(c->arg);
    c->t1 = gr_ref_mono_s();
    return NULL;
}

double gr_beams_run_jobs(void *(*fn)(void *), void *jobs, size_t size, int n)
{
    pthread_t th[GRID_MAX_THREADS];
    job_call call[GRID_MAX_THREADS];
    int started[GRID_MAX_THREADS] = {0};
    if (n > GRID_MAX_THREADS) n = GRID_MAX_THREADS;
    for (int i = 0; i < n; i++) call[i] = (job_call){fn, (char *)jobs + (size_t)i * size, 0.0, 0.0};
    for (int i = 1; i < n; i++) started[i] = pthread_create(&th[i], NULL, job_main, &call[i]) == 0;
    job_main(&call[0]);
    for (int i = 1; i < n; i++) {
        if (started[i]) pthread_join(th[i], NULL);
        else job_main(&call[i]);
    }
    double a[GRID_MAX_THREADS], b[GRID_MAX_THREADS];
    for (int i = 0; i < n; i++) { a[i] = call[i].t0; b[i] = call[i].t1; }
    return gr_ref_overlap_s(a, b, n);
}

typedef struct chunk_run {
    gr_chunk_fn fn;
    size_t total;
    int nchunks;
    atomic_int next;
} chunk_run;

typedef struct chunk_call {
    chunk_run *run;
    void *job;
} chunk_call;

static void *chunk_main(void *arg)
{
    chunk_call *c = arg;
    chunk_run *r = c->run;
    for (int k; (k = atomic_fetch_add(&r->next, 1)) < r->nchunks;)
        r->fn(c->job, k, r->total * (size_t)k / (size_t)r->nchunks, r->total * (size_t)(k + 1) / (size_t)r->nchunks);
    return NULL;
}

double gr_beams_run_chunks(gr_chunk_fn fn, void *jobs, size_t size, int n, size_t total, int nchunks)
{
    n = gr_beams_threads(n);
    chunk_run run = {fn, total, nchunks < 1 ? 1 : nchunks, 0};
    atomic_init(&run.next, 0);
    chunk_call call[GRID_MAX_THREADS];
    for (int i = 0; i < n; i++) call[i] = (chunk_call){&run, (char *)jobs + (size_t)i * size};
    return gr_beams_run_jobs(chunk_main, call, sizeof call[0], n);
}

int gr_beams_threads(int threads)
{
    return threads < 1 ? 1 : threads > GRID_MAX_THREADS ? GRID_MAX_THREADS : threads;
}

int gr_beams_chunks(size_t total, int n)
{
    size_t c = (size_t)(n < 1 ? 1 : n) * 16u;
    if (c > total) c = total ? total : 1;
    return c > GRID_CHUNKS_MAX ? GRID_CHUNKS_MAX : (int)c;
}

/* The primitives' cell ranges (grid_range of their boxes: lower u, y, w then upper), computed
 * once per grid by ranges of primitives and then read by the count and the fill, which no
 * longer recompute them in every worker (each scans every primitive); with each range's
 * entries, summed exactly (integers: the same total for any thread count), and a coarse
 * histogram of the entries over the w-layers that balances the workers' layers. */
enum { RANGE_BINS = 1024 };
typedef struct range_job {
    gr_beams *b;
    int32_t *rng;                 /* 6 per primitive */
    int32_t *gq;                  /* 6 per primitive: the box's ends in cell units (grid_qcoord) */
    int nbins;                    /* histogram bins over the w-layers */
    uint64_t total;               /* entries of the job's primitives */
    uint64_t hist[RANGE_BINS];    /* entries per bin (each primitive's in the bin of its middle layer) */
} range_job;

static void range_work(void *arg, int chunk, size_t k0, size_t k1)
{
    range_job *j = arg;
    const gr_beams *b = j->b;
    const int gw = b->gn[2];
    uint64_t total = 0;
    (void)chunk;
    for (uint32_t k = (uint32_t)k0; k < (uint32_t)k1; k++) {
        int32_t *r = j->rng + 6 * (size_t)k;
        grid_range(b, b->box + 6 * (size_t)k, r, j->gq + 6 * (size_t)k);
        uint64_t n = (uint64_t)(r[3] - r[0] + 1) * (uint64_t)(r[4] - r[1] + 1) * (uint64_t)(r[5] - r[2] + 1);
        total += n;
        j->hist[(int)((int64_t)((r[2] + r[5]) / 2) * j->nbins / gw)] += n;
    }
    j->total += total;
}

/* The grid's count and fill by layer chunks: the w-layers cut into L chunks balanced by their
 * entries, each chunk with the list of the primitives that reach its layers (ascending), built
 * by ranges of primitives (their per-chunk counts, then their writes at the prefix sums). A
 * chunk's cells are counted and filled by whichever thread takes it, in primitive order: the
 * lists do not depend on the split, and every thread reads only its chunks' primitives (the
 * per-thread layers before scanned every primitive on every thread). */
typedef struct layer_plan {
    gr_beams *b;
    const int32_t *rng;      /* 6 per primitive: cell ranges */
    const int32_t *gq;       /* 6 per primitive: box ends in cell units */
    int L;                   /* layer chunks */
    const int *lw;           /* chunk c: layers [lw[c], lw[c + 1]) */
    const int *chunk_of;     /* layer -> its chunk */
    uint64_t *cnt;           /* P x L: primitives of chunk p reaching layer chunk c, then the write offsets */
    uint32_t *list;          /* the layer chunks' primitive lists, chunk after chunk */
    uint64_t *first;         /* L + 1: each layer chunk's list start */
    uint64_t *total;         /* L: each layer chunk's entries (the count), then its first entry (the fill) */
    int fill;
} layer_plan;

static void list_count_work(void *arg, int pc, size_t k0, size_t k1)
{
    const layer_plan *lp = arg;
    uint64_t *cnt = lp->cnt + (size_t)pc * (size_t)lp->L;
    for (size_t k = k0; k < k1; k++) {
        const int32_t *r = lp->rng + 6 * k;
        for (int c = lp->chunk_of[r[2]], c1 = lp->chunk_of[r[5]]; c <= c1; c++) cnt[c]++;
    }
}

static void list_fill_work(void *arg, int pc, size_t k0, size_t k1)
{
    const layer_plan *lp = arg;
    uint64_t *off = lp->cnt + (size_t)pc * (size_t)lp->L;
    for (size_t k = k0; k < k1; k++) {
        const int32_t *r = lp->rng + 6 * k;
        for (int c = lp->chunk_of[r[2]], c1 = lp->chunk_of[r[5]]; c <= c1; c++) lp->list[off[c]++] = (uint32_t)k;
    }
}

static void grid_work(void *arg, int lc, size_t unused0, size_t unused1)
{
    const layer_plan *lp = arg;
    (void)unused0;
    (void)unused1;
    const size_t nu = (size_t)lp->b->gn[0], ny = (size_t)lp->b->gn[1];
    uint32_t *cf = lp->b->cell_first, *cp = lp->b->cell_prim; /* locals: the stores cannot alias them */
    const int32_t *rng = lp->rng;
    const uint32_t *list = lp->list + lp->first[lc];
    const uint64_t nl = lp->first[lc + 1] - lp->first[lc];
    const int fw0 = lp->lw[lc], fw1 = lp->lw[lc + 1] - 1;
    const size_t c_lo = (size_t)lp->lw[lc] * ny * nu, c_hi = (size_t)lp->lw[lc + 1] * ny * nu; /* the chunk's cells */
    if (!lp->fill) {
        /* each cell's entries, then their running sum over the chunk (its end, local) */
        for (uint64_t i = 0; i < nl; i++) {
            const int32_t *r = rng + 6 * (size_t)list[i];
            int w0 = r[2] > fw0 ? r[2] : fw0, w1 = r[5] < fw1 ? r[5] : fw1;
            for (int iw = w0; iw <= w1; iw++)
                for (int iy = r[1]; iy <= r[4]; iy++) {
                    size_t c0 = ((size_t)iw * ny + (size_t)iy) * nu;
                    for (int iu = r[0]; iu <= r[3]; iu++) cf[c0 + (size_t)iu]++;
                }
        }
        uint64_t sum = 0;
        for (size_t c = c_lo; c < c_hi; c++) {
            sum += cf[c];
            cf[c] = (uint32_t)sum;
        }
        lp->total[lc] = sum;
        return;
    }
    /* the ends made global, then each cell filled from its end down in reverse primitive
     * order: the lists ascend and cf[c] ends at the cell's start */
    const uint32_t off = (uint32_t)lp->total[lc];
    for (size_t c = c_lo; c < c_hi; c++) cf[c] += off;
    const uint32_t end = c_hi > c_lo ? cf[c_hi - 1] : off; /* the chunk's last entry + 1 */
    for (uint64_t i = nl; i-- > 0;) {
        const uint32_t k = list[i];
        const int32_t *r = rng + 6 * (size_t)k;
        int w0 = r[2] > fw0 ? r[2] : fw0, w1 = r[5] < fw1 ? r[5] : fw1;
        for (int iw = w0; iw <= w1; iw++)
            for (int iy = r[1]; iy <= r[4]; iy++) {
                size_t c0 = ((size_t)iw * ny + (size_t)iy) * nu;
                for (int iu = r[0]; iu <= r[3]; iu++) cp[--cf[c0 + (size_t)iu]] = k;
            }
    }
    /* each entry's box in its cell's bytes, cell after cell (sequential writes; the boxes of
     * a cell's primitives are mostly those of the cell before) */
    uint8_t *q = lp->b->cell_q;
    const size_t qs = lp->b->cell_q_stride;
    uint8_t *qu0 = q, *qu1 = q + qs, *qy0 = q + 2 * qs, *qy1 = q + 3 * qs, *qw0 = q + 4 * qs, *qw1 = q + 5 * qs;
    const int32_t *gq = lp->gq;
    size_t c = c_lo;
    for (int iw = lp->lw[lc]; iw < lp->lw[lc + 1]; iw++)
        for (int iy = 0; iy < (int)ny; iy++)
            for (int iu = 0; iu < (int)nu; iu++, c++) {
                const uint32_t e1 = c + 1 < c_hi ? cf[c + 1] : end;
                for (uint32_t e = cf[c]; e < e1; e++) {
                    const int32_t *g = gq + 6 * (size_t)cp[e];
                    qu0[e] = grid_qbyte(g[0], iu);
                    qu1[e] = grid_qbyte(g[3], iu);
                    qy0[e] = grid_qbyte(g[1], iy);
                    qy1[e] = grid_qbyte(g[4], iy);
                    qw0[e] = grid_qbyte(g[2], iw);
                    qw1[e] = grid_qbyte(g[5], iw);
                }
            }
}

static void box_work(void *arg, int chunk, size_t k0, size_t k1)
{
    gr_beams *b = arg;
    (void)chunk;
    for (uint32_t k = (uint32_t)k0; k < (uint32_t)k1; k++) prim_box(b, k, b->box + 6 * (size_t)k, b->box + 6 * (size_t)k + 3);
}

/* The boxes' bounds and summed extents over BOUND_CHUNKS fixed chunks of the primitives (the
 * same chunks and the same order of summation for any number of threads: the same grid) */
enum { BOUND_CHUNKS = 64 };
typedef struct bound_job {
    const gr_beams *b;
    double lo[BOUND_CHUNKS][3], hi[BOUND_CHUNKS][3], ext[BOUND_CHUNKS][3];
} bound_job;

static void bound_work(void *arg, int ck, size_t k0, size_t k1)
{
    bound_job *j = arg;
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX}, ext[3] = {0, 0, 0};
    for (size_t k = k0; k < k1; k++) {
        const float *bx = j->b->box + 6 * k;
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], bx[a]);
            hi[a] = fmax(hi[a], bx[3 + a]);
            ext[a] += (double)bx[3 + a] - bx[a];
        }
    }
    for (int a = 0; a < 3; a++) { j->lo[ck][a] = lo[a]; j->hi[ck][a] = hi[a]; j->ext[ck][a] = ext[a]; }
}

static gr_status build_grid(gr_beams *b, uint32_t np, int threads, gr_error *err)
{
    if (np == 0) return GR_OK;
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX}, ext[3] = {0, 0, 0};
    {
        int nb = gr_beams_threads(threads);
        bound_job *bj = malloc(sizeof *bj); /* one table: each chunk writes its own row */
        if (!bj) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid");
        bj->b = b;
        b->stats.par_s += gr_beams_run_chunks(bound_work, bj, 0, nb, np, BOUND_CHUNKS);
        for (int ck = 0; ck < BOUND_CHUNKS; ck++)
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], bj->lo[ck][a]);
                hi[a] = fmax(hi[a], bj->hi[ck][a]);
                ext[a] += bj->ext[ck][a];
            }
        free(bj);
    }
    double cell[3];
    for (int a = 0; a < 3; a++) {
        double span = hi[a] - lo[a];
        cell[a] = GRID_CELL_BOX * ext[a] / np;
        if (!(cell[a] > span * 1e-6)) cell[a] = span > 0.0 ? span * 1e-6 : 1.0;
    }
    int nt = gr_beams_threads(threads);
    /* the cells' ranges and the entries they make; over the budget, coarser cells and again */
    int32_t *rng = malloc((size_t)np * 6 * sizeof *rng), *gq = malloc((size_t)np * 6 * sizeof *gq);
    range_job *rj = malloc((size_t)nt * sizeof *rj);
    if (!rng || !gq || !rj) {
        free(rng);
        free(gq);
        free(rj);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid");
    }
    uint64_t entries = UINT64_MAX;
    const double budget = GRID_ENTRIES_PER_PRIM * np + 1024.0;
    for (int attempt = 0; attempt < 64 && entries == UINT64_MAX; attempt++) {
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
        uint64_t total = 0;
        for (int i = 0; i < nt; i++) { /* integer sums: the same for any split */
            rj[i].b = b;
            rj[i].rng = rng;
            rj[i].gq = gq;
            rj[i].nbins = b->gn[2] < RANGE_BINS ? b->gn[2] : RANGE_BINS;
            rj[i].total = 0;
            memset(rj[i].hist, 0, sizeof rj[i].hist);
        }
        b->stats.par_s += gr_beams_run_chunks(range_work, rj, sizeof rj[0], nt, np, gr_beams_chunks(np, nt));
        for (int i = 0; i < nt; i++) total += rj[i].total;
        if ((double)total <= budget) entries = total;
    }
    free(b->box); /* the ranges replace the float boxes */
    b->box = NULL;
    if (entries == UINT64_MAX || entries >= UINT32_MAX ||
        (size_t)b->gn[0] * (size_t)b->gn[1] * (size_t)b->gn[2] >= UINT32_MAX) {
        free(rng);
        free(gq);
        free(rj);
        return gr_fail(err, GR_E_NOMEM, "reference: the beam lookup grid needs more than %.0f entries, too many", budget);
    }
    /* the layer chunks, balanced by the histogram: 8 per thread, at most one per layer */
    size_t ncells = (size_t)b->gn[0] * (size_t)b->gn[1] * (size_t)b->gn[2];
    const int gw = b->gn[2];
    int L = 8 * nt < gw ? 8 * nt : gw;
    const int P = gr_beams_chunks(np, nt);
    int *lw = malloc(((size_t)L + 1) * sizeof *lw), *chunk_of = malloc((size_t)gw * sizeof *chunk_of);
    uint64_t *cnt = calloc((size_t)P * (size_t)L, sizeof *cnt), *lfirst = malloc(((size_t)L + 1) * sizeof *lfirst);
    uint64_t *ltotal = malloc((size_t)L * sizeof *ltotal);
    if (!lw || !chunk_of || !cnt || !lfirst || !ltotal) {
        free(lw); free(chunk_of); free(cnt); free(lfirst); free(ltotal); free(rng); free(gq); free(rj);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid");
    }
    {
        const int nbins = rj[0].nbins;
        uint64_t hist[RANGE_BINS] = {0}, cum = 0;
        for (int i = 0; i < nt; i++)
            for (int k = 0; k < nbins; k++) hist[k] += rj[i].hist[k];
        int bin = 0;
        lw[0] = 0;
        for (int i = 0; i < L; i++) {
            /* this chunk's bins: up to the (i + 1)-th share of the entries; its layers end at
             * the first layer of the next bin (layer l is in bin l nbins / gn[2], rounded down) */
            while (bin < nbins && (cum + hist[bin]) * (uint64_t)L <= entries * (uint64_t)(i + 1)) cum += hist[bin++];
            lw[i + 1] = i + 1 == L ? gw : (int)(((int64_t)bin * gw + nbins - 1) / nbins);
            if (lw[i + 1] < lw[i]) lw[i + 1] = lw[i];
        }
        for (int i = 0; i < L; i++)
            for (int l = lw[i]; l < lw[i + 1]; l++) chunk_of[l] = i;
    }
    free(rj);
    layer_plan lp = {b, rng, gq, L, lw, chunk_of, cnt, NULL, lfirst, ltotal, 0};
    /* the chunks' primitive lists: counts by ranges of primitives, their offsets, the writes */
    b->stats.par_s += gr_beams_run_chunks(list_count_work, &lp, 0, nt, np, P);
    lfirst[0] = 0;
    for (int c = 0; c < L; c++) {
        uint64_t f = lfirst[c];
        for (int pc = 0; pc < P; pc++) {
            uint64_t n = cnt[(size_t)pc * (size_t)L + (size_t)c];
            cnt[(size_t)pc * (size_t)L + (size_t)c] = f;
            f += n;
        }
        lfirst[c + 1] = f;
    }
    lp.list = malloc((lfirst[L] ? lfirst[L] : 1) * sizeof *lp.list);
    free(b->cell_first);
    b->cell_first = calloc(ncells + 1, sizeof *b->cell_first);
    b->cell_prim = malloc((entries ? entries : 1) * sizeof *b->cell_prim);
    free(b->cell_q);
    b->cell_q_stride = (size_t)entries + 16; /* the lookups' last 16-byte read */
    b->cell_q = calloc(6 * b->cell_q_stride, 1);
    if (!lp.list || !b->cell_first || !b->cell_prim || !b->cell_q) {
        free(lw); free(chunk_of); free(cnt); free(lfirst); free(ltotal); free(lp.list); free(rng); free(gq);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the beam lookup grid (%zu cells, %llu entries)", ncells,
                       (unsigned long long)entries);
    }
    b->stats.par_s += gr_beams_run_chunks(list_fill_work, &lp, 0, nt, np, P);
    /* count (each chunk's cells, with their running sum), the chunks' offsets, fill: the
     * prefix sum on the workers' threads, each cell's first entry at cell_first[c] */
    b->stats.par_s += gr_beams_run_chunks(grid_work, &lp, 0, nt, (size_t)L, L);
    for (uint64_t c = 0, off = 0; c < (uint64_t)L; c++) {
        uint64_t n = ltotal[c];
        ltotal[c] = off;
        off += n;
    }
    lp.fill = 1;
    b->stats.par_s += gr_beams_run_chunks(grid_work, &lp, 0, nt, (size_t)L, L);
    free(lw); free(chunk_of); free(cnt); free(lfirst); free(ltotal); free(lp.list);
    free(rng);
    free(gq);
    b->cell_first[ncells] = (uint32_t)entries;
    b->stats.grid_entries = (size_t)entries;
    b->stats.grid_cells = ncells;
    return GR_OK;
}

double gr_beams_entries_per_prim(const gr_beam_prim_sample *s, const double *weight, int n)
{
    double np = 0.0, e1[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        np += weight[i] * s[i].prims;
        for (int a = 0; a < 3; a++) e1[a] += weight[i] * s[i].e1[a];
    }
    double c[3];
    for (int a = 0; a < 3; a++) c[a] = GRID_CELL_BOX * e1[a] / np; /* build_grid's cells */
    if (!(np > 0.0) || !(c[0] > 0.0 && c[1] > 0.0 && c[2] > 0.0)) return 0.0;
    /* sum over the primitives of (1 + e_u / c_u)(1 + e_y / c_y)(1 + e_w / c_w), expanded */
    double sum = 0.0;
    for (int i = 0; i < n; i++)
        sum += weight[i] * (s[i].prims + s[i].e1[0] / c[0] + s[i].e1[1] / c[1] + s[i].e1[2] / c[2] +
                            s[i].e2[0] / (c[0] * c[1]) + s[i].e2[1] / (c[0] * c[2]) + s[i].e2[2] / (c[1] * c[2]) +
                            s[i].e3 / (c[0] * c[1] * c[2]));
    return fmin(sum / np, GRID_ENTRIES_PER_PRIM);
}

gr_status gr_beams_index(gr_beams *b, uint32_t np, int threads, gr_error *err)
{
    /* the boxes, in parallel (disjoint outputs; every thread's job is the set) */
    int nt = gr_beams_threads(threads);
    b->stats.par_s += gr_beams_run_chunks(box_work, b, 0, nt, np, gr_beams_chunks(np, nt));
    return build_grid(b, np, threads, err);
}
