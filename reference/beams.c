#include "reference/beam_grid.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/gerstner.h"
#include "core/optics.h"
#include "reference/phase.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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



/* The top of a beam's slabs: its top, or the region's top (and a centimetre for float
 * rounding) where that is lower: no lookup asks above it; the slab there stays open upward,
 * its box stops at it */
static float slab_top(float ytop, const gr_beam_region *r)
{
    double top = r->y_top + 0.01;
    return r->has_top && (double)ytop > top ? (float)top : ytop;
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

/* One thread's part of a beam build's chunked steps (gr_beams_run_chunks: the chunks' outputs
 * disjoint, the thread's own counters). */
typedef struct build_job {
    const gr_beam_params *p;
    gr_beams *b;
    const topo *tp;
    gr_dvec3 *pos;
    float *jv, *drift;
    const uint8_t *lev;
    double start_u, start_w, h;
    int disc;
    size_t lit;       /* triangles: the lit ones counted (this thread's chunks) */
    int stopped;      /* 1: Ctrl-C seen */
    double y_min, scale; /* slabs: the region's bottom, cells of drift per slab */
    size_t *chunk_slabs; /* slabs: each chunk's count, then its first primitive (the fill) */
    uint32_t *prim_tri;  /* slabs: the primitives' triangles (the fill) */
    float *mv;           /* the surface mesh's vertex buffer (3 floats per vertex) */
    unsigned *mi;        /* its index buffer */
} build_job;

/* Triangles [k0, k1) zeroed (their pages first touched on the build's threads). */
static void zero_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    (void)chunk;
    for (size_t t = k0; t < k1; t += 65536) {
        if (j->p->interrupt && *j->p->interrupt) { j->stopped = 1; return; }
        size_t e = t + 65536 < k1 ? t + 65536 : k1;
        memset(&j->b->tri[t], 0, (e - t) * sizeof j->b->tri[0]);
    }
}

/* The surface vertex over the rest point (x0, z0) (world): displaced (seed eq. 5.5.7), its
 * normal (5.5.8, into *n), the sun refracted (5.5.1), Fresnel; *pos its local position.
 * Returns 0 for a vertex that carries no beam (v->ft < 0): a refracted ray that does not head
 * down (grazing sun on a steep back slope) leaves the water again at once
 * (docs/reference.md). */
static int surface_vertex(const gr_beam_params *p, double x0, double z0, gr_dvec3 *pos, gr_dvec3 *n, beam_vertex *v)
{
    double eta = 1.0 / p->ior; /* air (n = 1) to water, seed eq. 5.5.1 with eta = n1 / n2 */
    gr_dvec3 P = gr_gerstner_position(p->water, x0, z0, p->water->time_s);
    gr_gerstner_frame(p->water, x0, z0, p->water->time_s, NULL, NULL, n);
    *pos = gr_d3_sub(P, p->origin);
    double cos_i = -gr_d3_dot(p->sun_dir, *n);
    gr_dvec3 T = cos_i > 0.0 ? gr_refract_d(p->sun_dir, *n, eta) : gr_d3(0, 0, 0);
    v->py = (float)pos->y;
    v->pu = (float)(pos->x - p->shear_x * pos->y);
    v->pw = (float)(pos->z - p->shear_z * pos->y);
    v->tx = (float)T.x; v->ty = (float)T.y; v->tz = (float)T.z;
    if (!(T.y < -1e-4)) {
        v->ft = -1.0f;
        v->au = v->aw = 0.0f;
        v->ity = -1.0f;
        return 0;
    }
    v->ft = p->fresnel ? (float)(1.0 - gr_fresnel_exact(cos_i, 1.0, p->ior)) : 1.0f;
    v->au = (float)(T.x / T.y - p->shear_x);
    v->aw = (float)(T.z / T.y - p->shear_z);
    v->ity = (float)(1.0 / T.y);
    return 1;
}

/* Vertices [k0, k1): displaced (seed eq. 5.5.7), normal (5.5.8), refraction, Fresnel, the
 * disc's slope Jacobian. */
static void vertex_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    (void)chunk;
    const gr_beam_params *p = j->p;
    gr_beams *b = j->b;
    const topo *tp = j->tp;
    gr_dvec3 I = p->sun_dir;
    double eta = 1.0 / p->ior; /* air (n = 1) to water, seed eq. 5.5.1 with eta = n1 / n2 */
    for (size_t k = k0; k < k1; k++) {
        if ((k & 4095) == 0 && p->interrupt && *p->interrupt) { /* Ctrl-C: a cheap read per 4096 vertices */
            j->stopped = 1;
            return;
        }
        double x0, z0;
        if (k < tp->nv0) {
            int i = (int)(k % (size_t)(b->nu + 1)), jj = (int)(k / (size_t)(b->nu + 1));
            x0 = p->origin.x + j->start_u + i * j->h;
            z0 = p->origin.z + j->start_w + jj * j->h;
        } else {
            x0 = p->origin.x + j->start_u + tp->rx[2 * (k - tp->nv0)];
            z0 = p->origin.z + j->start_w + tp->rx[2 * (k - tp->nv0) + 1];
        }
        gr_dvec3 n;
        beam_vertex *v = &b->v[k];
        if (!surface_vertex(p, x0, z0, &j->pos[k], &n, v)) continue;
        if (j->disc) {
            double J[4];
            slope_jacobian(I, n, eta, p->disc_e1, p->disc_e2, J);
            for (int c = 0; c < 4; c++) j->jv[4 * k + (size_t)c] = (float)J[c];
        }
    }
}

/* A beam's disc kernel: the disc radius times its vertices' mean slope Jacobian (ja, jb, jc;
 * first order: the cross-section moves rigidly with the sun direction), and the mean height
 * of its vertices, from which the kernel's depth is measured. */
static void tri_kernel(double radius, const float *ja, const float *jb, const float *jc, const beam_vertex *const vs[3],
                       float kern[4], float *ybar)
{
    for (int c = 0; c < 4; c++) kern[c] = (float)(radius * (ja[c] + jb[c] + jc[c]) / 3.0);
    *ybar = (vs[0]->py + vs[1]->py + vs[2]->py) / 3.0f;
}

/* A beam's drift per metre of height (sheared): its vertices' largest. */
static float tri_drift(const beam_vertex *const vs[3])
{
    float d = 0.0f;
    for (int c = 0; c < 3; c++) d = fmaxf(d, hypotf(vs[c]->au, vs[c]->aw));
    return d;
}

/* Triangles [k0, k1): flux, the cross-section's coefficients, the disc kernel, the drift. */
static void triangle_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    (void)chunk;
    const gr_beam_params *p = j->p;
    gr_beams *b = j->b;
    const gr_dvec3 *pos = j->pos;
    const float *jv = j->jv;
    float *drift = j->drift;
    const uint8_t *lev = j->lev;
    gr_dvec3 I = p->sun_dir;
    int disc = j->disc;
    for (size_t t = k0; t < k1; t++) {
        if ((t & 65535) == 0 && p->interrupt && *p->interrupt) { /* Ctrl-C, every 65536 triangles */
            j->stopped = 1;
            return;
        }
        beam_tri *bt = &b->tri[t];
        uint32_t idx[3];
        tri_vertices(b, (uint32_t)t, idx);
        const beam_vertex *v0 = &b->v[idx[0]], *v1 = &b->v[idx[1]], *v2 = &b->v[idx[2]];
        bt->ytop = fmaxf(v0->py, fmaxf(v1->py, v2->py));
        bt->ys = slab_top(bt->ytop, &p->region);
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
            tri_kernel(p->disc_radius, &jv[4 * (size_t)idx[0]], &jv[4 * (size_t)idx[1]], &jv[4 * (size_t)idx[2]], vs, bt->kern,
                       &bt->ybar);
            const float *M = bt->kern;
            bt->kr = 1.0001f * sqrtf(M[0] * M[0] + M[1] * M[1] + M[2] * M[2] + M[3] * M[3]);
        }
        float d = tri_drift(vs);
        /* in cells of the grid: a fine triangle's slabs are F times thinner (its box as tight) */
        drift[t] = lev[t] == 1 ? d * (float)j->tp->F : d;
        j->lit++;
    }
}

/* Triangles [k0, k1): their slabs at `scale` counted (the primitive budget's check). */
static void slab_count_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    const gr_beams *b = j->b;
    size_t n = 0;
    for (size_t t = k0; t < k1; t++)
        if (b->tri[t].phi > 0.0f) n += slab_count(b->tri[t].ys - j->y_min, j->drift[t], j->h, j->scale);
    j->chunk_slabs[chunk] = n;
}

/* Triangles [k0, k1): their slabs (first, count, height) and primitives from the chunk's
 * first on. */
static void slab_fill_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    gr_beams *b = j->b;
    size_t np = j->chunk_slabs[chunk];
    for (size_t t = k0; t < k1; t++) {
        beam_tri *bt = &b->tri[t];
        bt->first = (uint32_t)np;
        bt->nslab = 0;
        bt->dy = 1.0f;
        if (!(bt->phi > 0.0f)) continue;
        double depth = bt->ys - j->y_min;
        uint32_t ns = slab_count(depth, j->drift[t], j->h, j->scale);
        bt->dy = depth > 0.0 ? (float)(depth / ns) : 1.0f;
        bt->nslab = ns;
        for (uint32_t k = 0; k < ns; k++) j->prim_tri[np++] = (uint32_t)t;
    }
}

/* The surface mesh's buffers: vertices [k0, k1) in float, then (mesh_tri_work) triangles. */
static void mesh_vert_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    (void)chunk;
    for (size_t i = k0; i < k1; i++) {
        j->mv[3 * i] = (float)j->pos[i].x; j->mv[3 * i + 1] = (float)j->pos[i].y; j->mv[3 * i + 2] = (float)j->pos[i].z;
    }
}

static void mesh_tri_work(void *arg, int chunk, size_t k0, size_t k1)
{
    build_job *j = arg;
    (void)chunk;
    for (size_t t = k0; t < k1; t++) tri_vertices(j->b, (uint32_t)t, j->mi + 3 * t);
}

static gr_status build_surface_mesh(gr_rtc *rtc, gr_beams *b, const gr_dvec3 *pos, int threads, gr_error *err)
{
    RTCDevice dev = rtc->device;
    size_t nv = b->nv, nt = b->ntri;
    b->surface = rtcNewScene(dev);
    if (!b->surface) return gr_rtc_check(rtc, "reference: surface mesh", err);
    /* the camera rays meet it once a pass (one query per pixel against millions of beam
     * lookups): the quick build serves */
    rtcSetSceneBuildQuality(b->surface, RTC_BUILD_QUALITY_LOW);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
    int n = gr_beams_threads(threads);
    if (v && idx) {
        build_job mj[GRID_MAX_THREADS];
        for (int i = 0; i < n; i++) {
            memset(&mj[i], 0, sizeof mj[i]);
            mj[i].b = b;
            mj[i].pos = (gr_dvec3 *)pos;
            mj[i].mv = v;
            mj[i].mi = idx;
        }
        b->stats.par_s += gr_beams_run_chunks(mesh_vert_work, mj, sizeof mj[0], n, nv, gr_beams_chunks(nv, n));
        b->stats.par_s += gr_beams_run_chunks(mesh_tri_work, mj, sizeof mj[0], n, nt, gr_beams_chunks(nt, n));
        rtcCommitGeometry(g);
        rtcAttachGeometry(b->surface, g);
    }
    rtcReleaseGeometry(g);
    /* Embree builds on its own threads (the device's `threads`), which the jobs' records do
     * not see: the time with at most one thread busy is bounded from the process's CPU time
     * over the commit, s <= (n w - cpu) / (n - 1) (during s at most one thread runs, during
     * w - s at most n), and the rest counted as parallel (docs/reference.md 2.8) */
    double w0 = now_s(), c0 = gr_ref_cpu_s();
    rtcCommitScene(b->surface);
    double w = now_s() - w0, cpu = gr_ref_cpu_s() - c0;
    if (n > 1 && w > 0.0) {
        double ser = ((double)n * w - cpu) / (double)(n - 1);
        b->stats.par_s += w - (ser < 0.0 ? 0.0 : ser > w ? w : ser);
    }
    return gr_rtc_check(rtc, "reference: building the surface mesh", err);
}

/* The rest patch's grid of a set: cell size *h, nu x nw cells, its corner (sheared local,
 * the jitter included; on another set's lines when p->cell_m > 0). */
static gr_status patch_grid(const gr_beam_params *p, double *h, double *nu, double *nw, double *start_u, double *start_w,
                            gr_error *err)
{
    const gr_beam_region *r = &p->region;
    double ext_u = (r->u1 - r->u0) + 2.0 * p->pad_m, ext_w = (r->w1 - r->w0) + 2.0 * p->pad_m;
    if (!(ext_u > 0.0 && ext_w > 0.0) || p->res < 1)
        return gr_fail(err, GR_E_INPUT, "reference: empty lit region (%g x %g m) or surface_res %d < 1", ext_u, ext_w, p->res);
    *h = p->cell_m > 0.0 ? p->cell_m : sqrt(ext_u * ext_w) / (double)p->res;
    *nu = ceil(ext_u / *h) + 1.0;
    *nw = ceil(ext_w / *h) + 1.0;
    if (*nu * *nw * 2.0 > 1.0e9)
        return gr_fail(err, GR_E_INPUT, "reference.surface_res: %d gives %.0f x %.0f cells, too many", p->res, *nu, *nw);
    *start_u = r->u0 - p->pad_m - p->jitter[0] * *h;
    *start_w = r->w0 - p->pad_m - p->jitter[1] * *h;
    if (p->cell_m > 0.0) { /* another set's grid lines: the last at or before the patch's start */
        *start_u = p->anchor_u + floor((r->u0 - p->pad_m - p->anchor_u) / *h) * *h;
        *start_w = p->anchor_w + floor((r->w0 - p->pad_m - p->anchor_w) / *h) * *h;
    }
    return GR_OK;
}

void gr_beams_sample_prims(const gr_beam_params *p, int fine, int samples, gr_beam_prim_sample *out)
{
    memset(out, 0, sizeof *out);
    double h = 0.0, nu = 0.0, nw = 0.0, su = 0.0, sw = 0.0;
    gr_error e;
    if (samples < 1 || patch_grid(p, &h, &nu, &nw, &su, &sw, &e) != GR_OK) return;
    const double scale = p->slab_cells > 0.0 ? p->slab_cells : 1.0, eta = 1.0 / p->ior;
    const int F = fine > 1 ? fine : 1, disc = p->disc_radius > 0.0;
    const double c = h / F; /* the sampled cells' side: a plain cell, or a refined sub-cell */
    enum { MAX_SLABS = 32 }; /* slabs whose boxes are measured per triangle, evenly spread */
    for (int sj = 0; sj < samples; sj++)
        for (int si = 0; si < samples; si++) {
            /* the cell at the centre of stratum (si, sj) of the patch: its 4 corners */
            double x = p->origin.x + su + floor((si + 0.5) * nu / samples) * h;
            double z = p->origin.z + sw + floor((sj + 0.5) * nw / samples) * h;
            gr_dvec3 pos[4], n;
            beam_vertex v[4];
            float J[4][4];
            int ok[4];
            for (int k = 0; k < 4; k++) {
                ok[k] = surface_vertex(p, x + (k & 1) * c, z + (k >> 1) * c, &pos[k], &n, &v[k]);
                if (ok[k] && disc) {
                    double Jd[4];
                    slope_jacobian(p->sun_dir, n, eta, p->disc_e1, p->disc_e2, Jd);
                    for (int q = 0; q < 4; q++) J[k][q] = (float)Jd[q];
                }
            }
            /* its two triangles, wound so that their rest area vectors point down (as the grid's) */
            static const int tri[2][3] = {{0, 1, 2}, {1, 3, 2}};
            for (int t = 0; t < 2; t++) {
                const int *q = tri[t];
                out->tris += 1.0;
                if (!ok[q[0]] || !ok[q[1]] || !ok[q[2]]) continue;
                gr_dvec3 a = gr_d3_cross(gr_d3_sub(pos[q[1]], pos[q[0]]), gr_d3_sub(pos[q[2]], pos[q[0]]));
                if (!(gr_d3_dot(p->sun_dir, a) > 0.0)) continue; /* no beam: no primitive (slab_count_work) */
                /* as triangle_work: the drift, the top, the disc kernel */
                const beam_vertex *vs[3] = {&v[q[0]], &v[q[1]], &v[q[2]]};
                float ytop = fmaxf(vs[0]->py, fmaxf(vs[1]->py, vs[2]->py)), ybar = ytop, kern[4] = {0, 0, 0, 0};
                if (disc) tri_kernel(p->disc_radius, J[q[0]], J[q[1]], J[q[2]], vs, kern, &ybar);
                float ys = slab_top(ytop, &p->region);
                double depth = (double)ys - p->region.y_min;
                uint32_t ns = slab_count(depth, (double)tri_drift(vs) * F, h, scale);
                out->prims += ns;
                /* the boxes of (up to MAX_SLABS of) its slabs, as slab_range and prim_box make them */
                float dy = depth > 0.0 ? (float)(depth / ns) : 1.0f;
                uint32_t m = ns < MAX_SLABS ? ns : MAX_SLABS;
                double w = (double)ns / m;
                for (uint32_t r = 0; r < m; r++) {
                    uint32_t k = (uint32_t)(((uint64_t)r * ns) / m);
                    float lo, hi;
                    slab_bounds(ys, dy, k, ns, &lo, &hi);
                    float ylo = isinf(lo) ? (float)p->region.y_min : lo, yhi = isinf(hi) ? ys : hi;
                    float lo3[3], hi3[3];
                    beam_slab_box(vs, kern, ybar, disc, ylo, yhi, lo3, hi3);
                    double ex[3];
                    for (int ax = 0; ax < 3; ax++) {
                        ex[ax] = (double)hi3[ax] - lo3[ax];
                        out->e1[ax] += w * ex[ax];
                    }
                    out->e2[0] += w * ex[0] * ex[1];
                    out->e2[1] += w * ex[0] * ex[2];
                    out->e2[2] += w * ex[1] * ex[2];
                    out->e3 += w * ex[0] * ex[1] * ex[2];
                }
            }
        }
}

gr_status gr_beams_build(gr_rtc *rtc, const gr_beam_params *p, gr_beams **out, gr_error *err)
{
    *out = NULL;
    double t_start = now_s();
    const gr_beam_region *r = &p->region;
    double h = 0.0, nu_d = 0.0, nw_d = 0.0, start_u = 0.0, start_w = 0.0;
    gr_status pst = patch_grid(p, &h, &nu_d, &nw_d, &start_u, &start_w, err);
    if (pst != GR_OK) return pst;
    gr_beams *b = calloc(1, sizeof *b);
    if (!b) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for beams");
    b->nu = (int)nu_d;
    b->nw = (int)nw_d;
    b->y_min = r->y_min;
    b->sx = (float)p->shear_x;
    b->sz = (float)p->shear_z;
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
    double rho = tp.F > 1 ? (p->refine_radius_m > 0.0 ? p->refine_radius_m : gr_beam_refine_radius(p)) : -1.0;
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
    /* zeroed on the build's threads; Ctrl-C at a fine surface (gigabytes of triangles): a
     * cheap read per 65536 triangles and per row of cells below */
    build_job bj[GRID_MAX_THREADS];
    int nbj = gr_beams_threads(p->threads);
    {
        int stop = 0;
        for (int i = 0; i < nbj; i++) {
            memset(&bj[i], 0, sizeof bj[i]);
            bj[i].p = p;
            bj[i].b = b;
        }
        b->stats.par_s += gr_beams_run_chunks(zero_work, bj, sizeof bj[0], nbj, ntri, gr_beams_chunks(ntri, nbj));
        for (int i = 0; i < nbj; i++) stop |= bj[i].stopped;
        if (stop) {
            free(ref); free(lev); free(tp.fmap); gr_beams_destroy(b);
            return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
        }
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
    /* vertices, then triangles, on the build's threads (disjoint outputs: the same bytes for
     * any number of threads) */
    for (int i = 0; i < nbj; i++) {
        bj[i] = (build_job){.p = p, .b = b, .tp = &tp, .pos = pos, .jv = jv, .drift = drift, .lev = lev, .start_u = start_u, .start_w = start_w, .h = h, .disc = disc};
        bj[i].y_min = r->y_min;
    }
    b->stats.par_s += gr_beams_run_chunks(vertex_work, bj, sizeof bj[0], nbj, nv, gr_beams_chunks(nv, nbj));
    int stopped = 0;
    for (int i = 0; i < nbj; i++) stopped |= bj[i].stopped;
    if (stopped) { /* Ctrl-C */
        free(pos); free(drift); free(jv); free(lev); free(tp.rx); gr_beams_destroy(b);
        return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
    }
    free(tp.rx);
    size_t lit = 0;
    b->stats.par_s += gr_beams_run_chunks(triangle_work, bj, sizeof bj[0], nbj, ntri, gr_beams_chunks(ntri, nbj));
    for (int i = 0; i < nbj; i++) {
        stopped |= bj[i].stopped;
        lit += bj[i].lit;
    }
    if (stopped) { /* Ctrl-C */
        free(pos); free(drift); free(jv); free(lev); gr_beams_destroy(b);
        return gr_fail(err, GR_E_INTERRUPTED, "reference: interrupted while building the beams");
    }
    /* slabs: about slab_cells cells of drift each, coarsened uniformly if over the primitive budget */
    double scale = p->slab_cells > 0.0 ? p->slab_cells : 1.0;
    size_t total = 0;
    size_t chunk_slabs[GRID_CHUNKS_MAX];
    const int nch = gr_beams_chunks(ntri, nbj);
    for (int attempt = 0; attempt < 64; attempt++) {
        total = 0;
        for (int i = 0; i < nbj; i++) {
            bj[i].scale = scale;
            bj[i].chunk_slabs = chunk_slabs;
        }
        b->stats.par_s += gr_beams_run_chunks(slab_count_work, bj, sizeof bj[0], nbj, ntri, nch);
        for (int c = 0; c < nch; c++) total += chunk_slabs[c];
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
    /* each chunk's count -> its first primitive (the sum of the chunks before it: the serial order) */
    for (size_t c = 0, f = 0; c < (size_t)nch; c++) {
        size_t n = chunk_slabs[c];
        chunk_slabs[c] = f;
        f += n;
    }
    for (int i = 0; i < nbj; i++) bj[i].prim_tri = b->prim_tri;
    b->stats.par_s += gr_beams_run_chunks(slab_fill_work, bj, sizeof bj[0], nbj, ntri, nch);
    uint32_t np = (uint32_t)total;
    free(drift);
    free(jv);
    b->box = malloc((np ? np : 1) * 6 * sizeof *b->box);
    if (!b->box) {
        free(pos); gr_beams_destroy(b);
        return gr_fail(err, GR_E_NOMEM, "reference: out of memory for %u beam primitives", np);
    }
    double ti = now_s(), ci = gr_ref_cpu_s(), pi = b->stats.par_s;
    gr_status st = gr_beams_index(b, np, p->threads, err); /* the lookups' boxes and grid */
    b->stats.index_s = now_s() - ti;
    b->stats.index_cpu_s = gr_ref_cpu_s() - ci;
    b->stats.index_par_s = b->stats.par_s - pi;
    if (st == GR_OK && p->surface_mesh) st = build_surface_mesh(rtc, b, pos, p->threads, err);
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
    b->stats.bytes = nv * sizeof *b->v + ntri * sizeof *b->tri + np * sizeof(uint32_t) +
                     (b->stats.grid_cells + 1 + b->stats.grid_entries) * sizeof(uint32_t) + 6 * b->cell_q_stride;
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
    free(b->cell_q);
    free(b);
}
