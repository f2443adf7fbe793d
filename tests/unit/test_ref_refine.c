/* Local refinement of the beam tessellation (docs/reference.md 2.2, "Local refinement").
 * A camera 8 m deep looks up toward the refracted sun (as data/scenes/default.json), so the
 * cells around P_s (where the line through the camera along T0 meets the surface) are split
 * F x F, with transition fans around them. Real beam sets are built and checked against
 * oracles that do not come from the code:
 *  - topology (flat water, F = 2, 3, 4): every triangle wound with its area vector down;
 *    every edge shared by exactly two triangles in opposite directions, or lying on the
 *    patch's border (no T-junction, no crack, no overlap); the triangles' horizontal areas
 *    sum to the rest patch's area nu nw h^2 (the patch tiled exactly);
 *  - flux on flat water: the sum of the beams' flux equals the closed form
 *    F_t(theta_i) cos(theta_i) x the patch's area (Oracle 1's flux, section 2.1);
 *  - flux on waves: the sum of the beams' flux against the surface integral of
 *    F_t |I . (dP/dx0 x dP/dz0)| over the rest patch, by a 4x finer midpoint rule from the
 *    analytic Gerstner tangents (seed eq. 5.5.8): within the O(h^2) of a piecewise-linear
 *    surface, refined or not, and the refined set's region where its own fine cells give
 *    the flux of a uniform tessellation F times finer;
 *  - off (factor 1, or no camera direction within the angle of +-T0): the regular grid;
 *  - the camera cone's set (a smaller square on the same grid lines) looks up, at every point
 *    of its region, the same beams with the same irradiance as the whole set. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include <stdint.h>
#include "core/gerstner.h"
#include "core/optics.h"
#include "core/rng.h"
#include "reference/beams.h"
#include "reference/embree_scene.h"

typedef struct setup {
    gr_scene *s;
    gr_rtc *rtc;
    gr_beam_params bp;
} setup;

static const char *const waves_json =
    "[{\"amplitude_m\":0.115,\"wavelength_m\":12,\"direction_deg\":40},"
    "{\"amplitude_m\":0.044,\"wavelength_m\":5.5,\"direction_deg\":32,\"phase_rad\":4.4},"
    "{\"amplitude_m\":0.028,\"wavelength_m\":2.4,\"direction_deg\":12,\"phase_rad\":3.6},"
    "{\"amplitude_m\":0.012,\"wavelength_m\":1.0,\"direction_deg\":85,\"phase_rad\":2.2}]";

static void make(setup *u, int waves, int res, int factor)
{
    u->s = ref_scene("{\"water\":{\"waves\":%s},\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30},"
                     "\"camera\":{\"position_m\":[0,-8,0],\"yaw_deg\":30,\"pitch_deg\":60,\"fov_deg\":60,"
                     "\"width\":64,\"height\":36}}",
                     waves ? waves_json : "[]");
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_rtc_create(1, &u->rtc, &err), err);
    if (!u->rtc) exit(1);
    gr_dvec3 I = gr_d3_norm(gr_d3(u->s->sun.dir[0], u->s->sun.dir[1], u->s->sun.dir[2]));
    gr_dvec3 T0 = gr_refract_d(I, gr_d3(0, 1, 0), 1.0 / u->s->medium.ior);
    gr_beam_params *p = &u->bp;
    memset(p, 0, sizeof *p);
    p->water = &u->s->water;
    p->origin = gr_d3(0, 0, 0);
    p->sun_dir = I;
    p->ior = u->s->medium.ior;
    p->fresnel = 1;
    p->shear_x = T0.x / T0.y;
    p->shear_z = T0.z / T0.y;
    /* a 12 m square around P_s (the camera's sheared position) */
    double pu = -p->shear_x * -8.0, pw = -p->shear_z * -8.0;
    p->region.u0 = pu - 6.0; p->region.u1 = pu + 6.0;
    p->region.w0 = pw - 6.0; p->region.w1 = pw + 6.0;
    p->region.y_min = -8.5;
    p->pad_m = 1.0;
    p->res = res;
    p->jitter[0] = 0.3;
    p->jitter[1] = 0.7;
    p->max_prims = (size_t)1 << 24;
    p->refine_factor = factor;
    p->refine_angle = 15.0 * GR_PI / 180.0;
    p->camera = &u->s->camera;
    p->eye = gr_v3(0.0f, -8.0f, 0.0f);
}

static void done(setup *u)
{
    gr_rtc_destroy(u->rtc);
    free(u->s);
}

static gr_beams *build(setup *u)
{
    gr_error err = {GR_OK, ""};
    gr_beams *b = NULL;
    CHECK_OK(gr_beams_build(u->rtc, &u->bp, &b, &err), err);
    if (!b) exit(1);
    return b;
}

typedef struct edge { uint64_t key; int dir; } edge;

static int cmp_edge(const void *a, const void *b)
{
    uint64_t x = ((const edge *)a)->key, y = ((const edge *)b)->key;
    return (x > y) - (x < y);
}

/* Topology: edges shared by two opposite triangles or on the border; on flat water
 * (displaced = rest) also the winding, the border's place and the tiling. Returns the sum of
 * the triangles' horizontal areas. */
static double check_topology(const gr_beams *b, const char *what, int flat)
{
    size_t nt = gr_beams_triangle_count(b);
    edge *e = malloc(3 * nt * sizeof *e);
    if (!e) exit(1);
    double area = 0.0, umin = INFINITY, umax = -INFINITY, wmin = INFINITY, wmax = -INFINITY;
    size_t bad_wind = 0;
    for (size_t t = 0; t < nt; t++) {
        unsigned idx[3];
        gr_beams_triangle(b, t, idx);
        gr_vec3 P[3];
        for (int c = 0; c < 3; c++) {
            P[c] = gr_beams_vertex(b, idx[c]);
            umin = fmin(umin, P[c].x); umax = fmax(umax, P[c].x);
            wmin = fmin(wmin, P[c].z); wmax = fmax(wmax, P[c].z);
        }
        /* y component of (P1 - P0) x (P2 - P0) / 2: negative = area vector down */
        double ay = 0.5 * ((double)(P[1].z - P[0].z) * (P[2].x - P[0].x) - (double)(P[1].x - P[0].x) * (P[2].z - P[0].z));
        if (!(ay < 0.0)) bad_wind++;
        area += -ay;
        for (int c = 0; c < 3; c++) {
            uint64_t a = idx[c], z = idx[(c + 1) % 3];
            e[3 * t + (size_t)c].key = a < z ? (a << 32) | z : (z << 32) | a;
            e[3 * t + (size_t)c].dir = a < z ? 1 : -1;
        }
    }
    CHECK_MSG(!flat || bad_wind == 0, "%s: %zu triangles not wound with the area vector down", what, bad_wind);
    qsort(e, 3 * nt, sizeof *e, cmp_edge);
    size_t inner = 0, border = 0, bad = 0;
    double tol = 1e-4;
    for (size_t i = 0; i < 3 * nt;) {
        size_t j = i;
        while (j < 3 * nt && e[j].key == e[i].key) j++;
        if (j - i == 2 && e[i].dir == -e[i + 1].dir) {
            inner++;
        } else if (j - i == 1) {
            /* used once: must lie on the patch's border (both ends on the same side) */
            gr_vec3 a = gr_beams_vertex(b, (unsigned)(e[i].key >> 32)), z = gr_beams_vertex(b, (unsigned)(e[i].key & 0xffffffffu));
            int on = (fabs(a.x - umin) < tol && fabs(z.x - umin) < tol) || (fabs(a.x - umax) < tol && fabs(z.x - umax) < tol) ||
                     (fabs(a.z - wmin) < tol && fabs(z.z - wmin) < tol) || (fabs(a.z - wmax) < tol && fabs(z.z - wmax) < tol);
            if (on || !flat) border++;
            else bad++;
        } else {
            bad++;
        }
        i = j;
    }
    CHECK_MSG(bad == 0, "%s: %zu edges neither shared by two opposite triangles nor on the border (%zu inner, %zu border)",
              what, bad, inner, border);
    const gr_beam_stats *st = gr_beams_stats(b);
    /* the border of a nu x nw grid has 2 (nu + nw) edges: refinement stays inside */
    CHECK_MSG(border == 2 * (size_t)(st->nu + st->nw), "%s: %zu border edges, grid %d x %d", what, border, st->nu, st->nw);
    double patch = (double)st->nu * st->nw * st->cell_m * st->cell_m;
    CHECK_MSG(!flat || fabs(area - patch) <= 1e-5 * patch, "%s: triangles' area %.9g, patch %.9g", what, area, patch);
    free(e);
    return area;
}

static double flux_sum(const gr_beams *b)
{
    double s = 0.0;
    unsigned idx[3];
    for (size_t t = 0; t < gr_beams_triangle_count(b); t++) s += gr_beams_triangle(b, t, idx);
    return s;
}

/* The surface integral of F_t |I . dA| over the rest patch [u0, u0 + nu h] x [w0, w0 + nw h]
 * by the midpoint rule on cells of h / q (the analytic tangents, seed eq. 5.5.8). */
static double flux_exact(const setup *u, const gr_beam_stats *st, double u0, double w0, int q)
{
    const gr_beam_params *p = &u->bp;
    double hq = st->cell_m / q, sum = 0.0;
    for (int j = 0; j < st->nw * q; j++)
        for (int i = 0; i < st->nu * q; i++) {
            double x0 = u0 + (i + 0.5) * hq, z0 = w0 + (j + 0.5) * hq;
            gr_dvec3 tx, tz, n;
            gr_gerstner_frame(p->water, x0, z0, p->water->time_s, &tx, &tz, &n);
            gr_dvec3 dA = gr_d3_cross(tz, tx); /* upward, |dA| per unit rest area */
            double cos_i = -gr_d3_dot(p->sun_dir, n);
            double ft = 1.0 - gr_fresnel_exact(cos_i, 1.0, p->ior);
            sum += ft * fabs(gr_d3_dot(p->sun_dir, dA)) * hq * hq;
        }
    return sum;
}

int main(void)
{
    int reduced = ref_reduced();
    /* 1. topology and flux on flat water */
    const int factors[] = {1, 2, 3, 4};
    for (int k = 0; k < 4; k++) {
        setup u;
        make(&u, 0, 40, factors[k]);
        gr_beams *b = build(&u);
        const gr_beam_stats *st = gr_beams_stats(b);
        char what[64];
        snprintf(what, sizeof what, "flat, factor %d", factors[k]);
        double area = check_topology(b, what, 1);
        size_t grid = 2 * (size_t)st->nu * (size_t)st->nw;
        if (factors[k] == 1) {
            CHECK(gr_beams_triangle_count(b) == grid && st->refined_cells == 0);
        } else {
            CHECK_MSG(st->refined_cells > 0 && st->transition_cells > 0 && gr_beams_triangle_count(b) > grid,
                      "%s: %zu refined, %zu transition cells, %zu triangles (grid %zu)", what, st->refined_cells,
                      st->transition_cells, gr_beams_triangle_count(b), grid);
            /* every refined cell adds 2 F^2 - 2 triangles; a fan has 4 + (F - 1) per refined side */
            CHECK(gr_beams_triangle_count(b) >= grid + st->refined_cells * (2 * (size_t)(factors[k] * factors[k]) - 2) +
                                                    st->transition_cells * (size_t)(factors[k] + 1));
            CHECK(st->refine_radius_m > 1.0 && st->refine_radius_m < 6.0); /* ~ 8 m tan(15 deg) / |T0_y|^2 */
        }
        /* Oracle 1's flux: E_sun F_t cos(theta_i) per unit horizontal area */
        double cos_i = -u.bp.sun_dir.y, sin_i = sqrt(1.0 - cos_i * cos_i);
        double sin_t = sin_i / u.bp.ior, cos_t = sqrt(1.0 - sin_t * sin_t), n = u.bp.ior;
        double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
        double ft = 1.0 - 0.5 * (rs * rs + rp * rp); /* Fresnel, written here from the amplitude formulas */
        double phi = flux_sum(b);
        CHECK_MSG(fabs(phi - ft * cos_i * area) <= 2e-5 * phi, "%s: flux %.9g, closed form %.9g", what, phi, ft * cos_i * area);
        printf("%s: %zu triangles (grid %zu), %zu refined + %zu transition cells within %.2f m, flux %.6f vs %.6f\n", what,
               gr_beams_triangle_count(b), grid, st->refined_cells, st->transition_cells, st->refine_radius_m, phi,
               ft * cos_i * area);
        gr_beams_destroy(b);
        done(&u);
    }
    /* 1b. no camera direction within the angle of +-T0 (looking away from the sun, 10 deg
     * down: +T0 is 68 deg down, out of the 60 deg frustum): no refinement, the plain grid */
    {
        setup u;
        make(&u, 0, 40, 4);
        u.s->camera.pitch_deg = -10.0;
        double f[3] = {cos(-10.0 * GR_PI / 180.0) * sin(210.0 * GR_PI / 180.0), sin(-10.0 * GR_PI / 180.0),
                       cos(-10.0 * GR_PI / 180.0) * cos(210.0 * GR_PI / 180.0)};
        double rl = hypot(f[0], f[2]);
        for (int c = 0; c < 3; c++) u.s->camera.forward[c] = f[c];
        u.s->camera.right[0] = -f[2] / rl; u.s->camera.right[1] = 0.0; u.s->camera.right[2] = f[0] / rl;
        const double *r = u.s->camera.right;
        u.s->camera.up[0] = r[1] * f[2] - r[2] * f[1];
        u.s->camera.up[1] = r[2] * f[0] - r[0] * f[2];
        u.s->camera.up[2] = r[0] * f[1] - r[1] * f[0];
        gr_beams *b = build(&u);
        const gr_beam_stats *st = gr_beams_stats(b);
        CHECK_MSG(st->refined_cells == 0 && st->refine_radius_m < 0.0 &&
                      gr_beams_triangle_count(b) == 2 * (size_t)st->nu * (size_t)st->nw,
                  "looking away: %zu cells refined, radius %g", st->refined_cells, st->refine_radius_m);
        gr_beams_destroy(b);
        done(&u);
    }
    /* 2. flux on waves against the surface integral: uniform at res, refined at res, uniform at res F */
    int res = reduced ? 32 : 48, F = 4;
    double rel[3];
    for (int k = 0; k < 3; k++) {
        setup u;
        make(&u, 1, k == 2 ? res * F : res, k == 1 ? F : 1);
        gr_beams *b = build(&u);
        const gr_beam_stats *st = gr_beams_stats(b);
        if (k == 1) check_topology(b, "waves, factor 4", 0);
        double u0 = u.bp.region.u0 - u.bp.pad_m - u.bp.jitter[0] * st->cell_m;
        double w0 = u.bp.region.w0 - u.bp.pad_m - u.bp.jitter[1] * st->cell_m;
        double ex = flux_exact(&u, st, u0, w0, k == 2 ? 4 : 4 * F);
        double phi = flux_sum(b);
        rel[k] = (phi - ex) / ex;
        printf("waves, %s: flux %.8f, surface integral %.8f, relative %+.3e\n",
               k == 0 ? "uniform res" : k == 1 ? "refined x4" : "uniform res x4", phi, ex, rel[k]);
        gr_beams_destroy(b);
        done(&u);
    }
    /* piecewise-linear: O(h^2) (measured 1.6e-6 and 2.3e-6 at res 48, -6e-8 at 192) */
    CHECK_MSG(fabs(rel[0]) < 2e-5 && fabs(rel[1]) < 2e-5 && fabs(rel[2]) < 2e-6, "flux errors %.3e %.3e %.3e", rel[0], rel[1],
              rel[2]);
    /* 3. the camera cone's set (docs/reference.md 2.2): a set over a smaller square around
     * P_s on another set's grid lines (cell_m, anchor) must give, at every point of its own
     * region, the lookups of that set itself (the same triangles up to float rounding of the
     * vertices: the same beams, the same disc-averaged irradiance), refined (F = 3, the cone)
     * or not; a point near the square's edge is where a missing beam (a short pad) would show */
    for (int fac = 1; fac <= 3; fac += 2) {
        setup u;
        make(&u, 1, reduced ? 40 : 64, fac);
        gr_dvec3 I = u.bp.sun_dir, hlp = fabs(I.y) < 0.9 ? gr_d3(0, 1, 0) : gr_d3(1, 0, 0);
        u.bp.disc_radius = 0.5 * 0.53 * GR_PI / 180.0; /* the sun's disc convolved, as renders do */
        u.bp.disc_e1 = gr_d3_norm(gr_d3_cross(I, hlp));
        u.bp.disc_e2 = gr_d3_cross(I, u.bp.disc_e1);
        gr_beams *full = build(&u);
        const gr_beam_stats *fs = gr_beams_stats(full);
        double pu = -u.bp.shear_x * -8.0, pw = -u.bp.shear_z * -8.0, R = 2.5;
        u.bp.region.u0 = pu - R; u.bp.region.u1 = pu + R;
        u.bp.region.w0 = pw - R; u.bp.region.w1 = pw + R;
        u.bp.cell_m = fs->cell_m;
        u.bp.anchor_u = fs->grid_u0;
        u.bp.anchor_w = fs->grid_w0;
        gr_beams *cone = build(&u);
        const gr_beam_stats *cs = gr_beams_stats(cone);
        CHECK_MSG(fabs(cs->cell_m - fs->cell_m) < 1e-12 && cs->triangles < fs->triangles && cs->refined_cells == fs->refined_cells,
                  "factor %d: the cone set: cell %g vs %g, %zu vs %zu triangles, %zu vs %zu refined", fac, cs->cell_m, fs->cell_m,
                  cs->triangles, fs->triangles, cs->refined_cells, fs->refined_cells);
        gr_beam_hits ha = {0}, hb = {0};
        gr_rng g = gr_rng_make(7, 0, (uint64_t)fac);
        int n = reduced ? 4000 : 20000, diff = 0, hits = 0;
        double worst = 0.0;
        for (int i = 0; i < n; i++) {
            /* uniform in the square (sheared) and in depth; every 4th point within 5 cm of its edge */
            double su = pu + R * (2.0 * gr_rng_double(&g) - 1.0), sw = pw + R * (2.0 * gr_rng_double(&g) - 1.0);
            double y = -8.0 + 7.5 * gr_rng_double(&g);
            if (i % 4 == 0) su = pu + (i % 8 ? 1.0 : -1.0) * (R - 0.05 * gr_rng_double(&g));
            gr_vec3 x = gr_v3((float)(su + u.bp.shear_x * y), (float)y, (float)(sw + u.bp.shear_z * y));
            int na = gr_beams_lookup(full, x, &ha), nb = gr_beams_lookup(cone, x, &hb);
            double ea = 0.0, eb = 0.0;
            for (int k = 0; k < na; k++) ea += ha.h[k].e_h;
            for (int k = 0; k < nb; k++) eb += hb.h[k].e_h;
            hits += na;
            if (na != nb) diff++;
            double r = fabs(ea - eb) / fmax(ea, 1e-12);
            if (ea > 0.0 && r > worst) worst = r;
        }
        printf("cone set, factor %d: %zu of %zu triangles, %d points, %d beam hits, %d with another hit count, worst "
               "relative irradiance difference %.2e\n",
               fac, cs->triangles, fs->triangles, n, hits, diff, worst);
        /* float rounding of the vertices (start + i h) can move a blurred footprint's edge by
         * ulps: a hit more or less with a vanishing share, never a lost beam */
        CHECK_MSG(hits > n && diff <= n / 1000 && worst < 1e-4, "factor %d: %d of %d points differ in hits, worst %.3e", fac, diff,
                  n, worst);
        gr_beam_hits_free(&ha);
        gr_beam_hits_free(&hb);
        gr_beams_destroy(cone);
        gr_beams_destroy(full);
        done(&u);
    }
    CHECK_DONE();
}
