/* glTF 2.0 export (see gltf.h; decisions and conventions in docs/engines.md). */
#include "export/gltf.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "common/memlimit.h"
#include "common/outfile.h"
#include "core/gerstner.h"
#include "core/optics.h"
#include "core/shaftgeom.h"

#define GL_FLOAT_ 5126
#define GL_UNSIGNED_INT_ 5125
#define GL_ARRAY_BUFFER_ 34962
#define GL_ELEMENT_ARRAY_BUFFER_ 34963
#define CAM_ZNEAR_M 0.05   /* the real-time renderer's planes (src/realtime/shafts.c) */
#define CAM_ZFAR_M 2000.0
#define SPHERE_STACKS 32
#define SPHERE_SLICES 64
#define DEG2RAD (GR_PI / 180.0)

/* ---- the binary buffer and the JSON arrays that index it ------------------------------ */

typedef struct ctx {
    cJSON *root, *views, *accessors, *meshes, *nodes, *materials;
    unsigned char *bin;
    size_t n, cap;
    int nomem;
} ctx;

static size_t bin_append(ctx *c, const void *data, size_t bytes)
{
    size_t off = (c->n + 3u) & ~(size_t)3u; /* every component is 4 bytes: 4-byte alignment */
    if (off + bytes > c->cap) {
        size_t cap = c->cap ? c->cap : 1u << 16;
        while (cap < off + bytes) cap *= 2;
        unsigned char *p = realloc(c->bin, cap);
        if (!p) {
            c->nomem = 1;
            return 0;
        }
        c->bin = p;
        c->cap = cap;
    }
    memset(c->bin + c->n, 0, off - c->n);
    memcpy(c->bin + off, data, bytes);
    c->n = off + bytes;
    return off;
}

static cJSON *num_array(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]));
    return a;
}

/* One bufferView + accessor over `count` elements of `ncomp` 4-byte components. Float
 * accessors of vertex data carry min/max (required for POSITION, computed from the stored
 * floats so that they match them exactly). Returns the accessor index, -1 out of memory. */
static int add_accessor(ctx *c, const void *data, int count, int ncomp, int comp_type, int target, int minmax)
{
    static const char *types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    size_t bytes = (size_t)count * (size_t)ncomp * 4u;
    size_t off = bin_append(c, data, bytes);
    if (c->nomem) return -1;
    cJSON *v = cJSON_CreateObject();
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)off);
    cJSON_AddNumberToObject(v, "byteLength", (double)bytes);
    if (target) cJSON_AddNumberToObject(v, "target", target);
    cJSON_AddItemToArray(c->views, v);
    cJSON *a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", cJSON_GetArraySize(c->views) - 1);
    cJSON_AddNumberToObject(a, "componentType", comp_type);
    cJSON_AddNumberToObject(a, "count", count);
    cJSON_AddStringToObject(a, "type", types[ncomp]);
    if (minmax && comp_type == GL_FLOAT_) {
        const float *f = data;
        double mn[4], mx[4];
        for (int k = 0; k < ncomp; k++) mn[k] = mx[k] = f[k];
        for (int i = 1; i < count; i++)
            for (int k = 0; k < ncomp; k++) {
                double x = f[(size_t)i * ncomp + k];
                if (x < mn[k]) mn[k] = x;
                if (x > mx[k]) mx[k] = x;
            }
        cJSON_AddItemToObject(a, "min", num_array(mn, ncomp));
        cJSON_AddItemToObject(a, "max", num_array(mx, ncomp));
    }
    cJSON_AddItemToArray(c->accessors, a);
    return cJSON_GetArraySize(c->accessors) - 1;
}

/* A mesh of one indexed triangle primitive. Returns the mesh's JSON (already in the array)
 * and its index through *index; NULL out of memory. */
static cJSON *add_mesh(ctx *c, const char *name, const float *pos, const float *nrm, int nv, const uint32_t *idx,
                       int ni, int material, int *index)
{
    int ap = add_accessor(c, pos, nv, 3, GL_FLOAT_, GL_ARRAY_BUFFER_, 1);
    int an = add_accessor(c, nrm, nv, 3, GL_FLOAT_, GL_ARRAY_BUFFER_, 0);
    int ai = add_accessor(c, idx, ni, 1, GL_UNSIGNED_INT_, GL_ELEMENT_ARRAY_BUFFER_, 0);
    if (ap < 0 || an < 0 || ai < 0) return NULL;
    cJSON *m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "name", name);
    cJSON *prims = cJSON_AddArrayToObject(m, "primitives");
    cJSON *p = cJSON_CreateObject();
    cJSON *at = cJSON_AddObjectToObject(p, "attributes");
    cJSON_AddNumberToObject(at, "POSITION", ap);
    cJSON_AddNumberToObject(at, "NORMAL", an);
    cJSON_AddNumberToObject(p, "indices", ai);
    cJSON_AddNumberToObject(p, "mode", 4);
    cJSON_AddNumberToObject(p, "material", material);
    cJSON_AddItemToArray(prims, p);
    cJSON_AddItemToArray(c->meshes, m);
    *index = cJSON_GetArraySize(c->meshes) - 1;
    return m;
}

static cJSON *add_node(ctx *c, const char *name, const double *t, const double *q, int *index)
{
    cJSON *n = cJSON_CreateObject();
    cJSON_AddStringToObject(n, "name", name);
    if (t) cJSON_AddItemToObject(n, "translation", num_array(t, 3));
    if (q) cJSON_AddItemToObject(n, "rotation", num_array(q, 4));
    cJSON_AddItemToArray(c->nodes, n);
    *index = cJSON_GetArraySize(c->nodes) - 1;
    return n;
}

static void add_material(ctx *c, const char *name, double r, double g, double b, double roughness)
{
    cJSON *m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "name", name);
    cJSON *pbr = cJSON_AddObjectToObject(m, "pbrMetallicRoughness");
    double col[4] = {r, g, b, 1.0};
    cJSON_AddItemToObject(pbr, "baseColorFactor", num_array(col, 4));
    cJSON_AddNumberToObject(pbr, "metallicFactor", 0.0);
    cJSON_AddNumberToObject(pbr, "roughnessFactor", roughness);
    /* seen from below (the usual view here) as well as from above */
    cJSON_AddBoolToObject(m, "doubleSided", 1);
    cJSON_AddItemToArray(c->materials, m);
}

/* Unit quaternion [x, y, z, w] of the rotation whose matrix has columns c0, c1, c2 (a proper
 * orthonormal frame). Shepperd's method: the branch on the largest diagonal term keeps the
 * square root away from zero. */
static void quat_from_frame(gr_dvec3 c0, gr_dvec3 c1, gr_dvec3 c2, double q[4])
{
    double m00 = c0.x, m10 = c0.y, m20 = c0.z, m01 = c1.x, m11 = c1.y, m21 = c1.z, m02 = c2.x, m12 = c2.y,
           m22 = c2.z;
    double tr = m00 + m11 + m22, x, y, z, w;
    if (tr > 0.0) {
        double s = 2.0 * sqrt(tr + 1.0);
        w = 0.25 * s, x = (m21 - m12) / s, y = (m02 - m20) / s, z = (m10 - m01) / s;
    } else if (m00 > m11 && m00 > m22) {
        double s = 2.0 * sqrt(1.0 + m00 - m11 - m22);
        w = (m21 - m12) / s, x = 0.25 * s, y = (m01 + m10) / s, z = (m02 + m20) / s;
    } else if (m11 > m22) {
        double s = 2.0 * sqrt(1.0 + m11 - m00 - m22);
        w = (m02 - m20) / s, x = (m01 + m10) / s, y = 0.25 * s, z = (m12 + m21) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + m22 - m00 - m11);
        w = (m10 - m01) / s, x = (m02 + m20) / s, y = (m12 + m21) / s, z = 0.25 * s;
    }
    double l = sqrt(x * x + y * y + z * z + w * w);
    q[0] = x / l, q[1] = y / l, q[2] = z / l, q[3] = w / l;
}

static gr_dvec3 d3v(const double *v) { return gr_d3(v[0], v[1], v[2]); }

/* ---- geometry ------------------------------------------------------------------------- */

typedef struct water_grid {
    int N;              /* cells per side */
    double cx, cz, H;   /* rest-patch centre and half side */
    double h0;          /* rest height: the node's y translation */
} water_grid;

/* Seed eqs. 5.5.7-5.5.8 at the grid's rest points: positions relative to (cx, h0, cz) and unit
 * normals, in double, stored as float (relative coordinates keep float's error below 4e-6 m
 * for a patch of up to 64 m, however far the scene is from the origin). */
static void water_surface(const gr_water *w, const water_grid *g, double t, float *pos, float *nrm)
{
    int n1 = g->N + 1;
    double h = 2.0 * g->H / g->N;
    for (int j = 0; j < n1; j++)
        for (int i = 0; i < n1; i++) {
            double x0 = g->cx - g->H + i * h, z0 = g->cz - g->H + j * h;
            gr_dvec3 p = gr_gerstner_position(w, x0, z0, t), nn;
            gr_gerstner_frame(w, x0, z0, t, NULL, NULL, &nn);
            size_t k = 3u * ((size_t)j * n1 + i);
            pos[k + 0] = (float)(p.x - g->cx);
            pos[k + 1] = (float)(p.y - g->h0);
            pos[k + 2] = (float)(p.z - g->cz);
            nrm[k + 0] = (float)nn.x;
            nrm[k + 1] = (float)nn.y;
            nrm[k + 2] = (float)nn.z;
        }
}

/* Two triangles per cell, counter-clockwise seen from above (+y, the normals' side). */
static void grid_indices(int N, uint32_t *idx)
{
    size_t k = 0;
    uint32_t n1 = (uint32_t)N + 1;
    for (uint32_t j = 0; j < (uint32_t)N; j++)
        for (uint32_t i = 0; i < (uint32_t)N; i++) {
            uint32_t v00 = j * n1 + i, v10 = v00 + 1, v01 = v00 + n1, v11 = v01 + 1;
            idx[k++] = v00, idx[k++] = v01, idx[k++] = v10;
            idx[k++] = v10, idx[k++] = v01, idx[k++] = v11;
        }
}

/* Box of full extents sx, sy, sz centred at the origin: 4 vertices per face (flat normals),
 * counter-clockwise seen from outside. */
static void box_mesh(const double size[3], float pos[72], float nrm[72], uint32_t idx[36])
{
    int v = 0, k = 0;
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2) {
            int ua = (a + 1) % 3, va = (a + 2) % 3; /* e_ua x e_va = e_a */
            if (s < 0) {
                int t = ua;
                ua = va, va = t;
            }
            static const int corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
            for (int c = 0; c < 4; c++) {
                double p[3] = {0, 0, 0};
                p[a] = 0.5 * s * size[a];
                p[ua] = 0.5 * corner[c][0] * size[ua];
                p[va] = 0.5 * corner[c][1] * size[va];
                for (int q = 0; q < 3; q++) {
                    pos[3 * (v + c) + q] = (float)p[q];
                    nrm[3 * (v + c) + q] = q == a ? (float)s : 0.0f;
                }
            }
            idx[k++] = (uint32_t)v, idx[k++] = (uint32_t)v + 1, idx[k++] = (uint32_t)v + 2;
            idx[k++] = (uint32_t)v, idx[k++] = (uint32_t)v + 2, idx[k++] = (uint32_t)v + 3;
            v += 4;
        }
}

#define SPHERE_NV ((SPHERE_STACKS + 1) * (SPHERE_SLICES + 1))
#define SPHERE_NI (6 * SPHERE_SLICES * (SPHERE_STACKS - 1))

/* Latitude-longitude sphere about the origin; the pole rows' degenerate triangles are left
 * out; every triangle wound counter-clockwise seen from outside. */
static void sphere_mesh(double r, float *pos, float *nrm, uint32_t *idx)
{
    int n1 = SPHERE_SLICES + 1;
    for (int st = 0; st <= SPHERE_STACKS; st++)
        for (int sl = 0; sl <= SPHERE_SLICES; sl++) {
            double th = GR_PI * st / SPHERE_STACKS, ph = 2.0 * GR_PI * sl / SPHERE_SLICES;
            double n[3] = {sin(th) * sin(ph), cos(th), sin(th) * cos(ph)};
            size_t k = 3u * ((size_t)st * n1 + sl);
            for (int q = 0; q < 3; q++) {
                nrm[k + q] = (float)n[q];
                pos[k + q] = (float)(r * n[q]);
            }
        }
    int k = 0;
    for (int st = 0; st < SPHERE_STACKS; st++)
        for (int sl = 0; sl < SPHERE_SLICES; sl++) {
            uint32_t a = (uint32_t)(st * n1 + sl), b = a + 1, c = a + (uint32_t)n1, d = c + 1;
            /* th grows downward, ph toward +x from +z: (a, c, b) faces outward */
            if (st != 0) idx[k++] = a, idx[k++] = c, idx[k++] = b;
            if (st != SPHERE_STACKS - 1) idx[k++] = b, idx[k++] = c, idx[k++] = d;
        }
}

/* ---- extras --------------------------------------------------------------------------- */

static cJSON *vec3_json(const double *v) { return num_array(v, 3); }

static cJSON *extras_json(const gr_scene *s, const water_grid *g, const gr_gltf_options *o, gr_dvec3 refr,
                          int water_node)
{
    cJSON *x = cJSON_CreateObject();
    cJSON_AddStringToObject(x, "format", "godrays-export-1");
    cJSON_AddStringToObject(x, "scene_name", s->name);
    cJSON_AddStringToObject(x, "scene_hash", s->hash);
    cJSON *u = cJSON_AddObjectToObject(x, "units");
    cJSON_AddStringToObject(u, "length", "m");
    cJSON_AddStringToObject(u, "time", "s");
    cJSON_AddStringToObject(u, "angle", "rad, except keys ending in _deg");
    cJSON_AddStringToObject(u, "irradiance", "W/m^2 per RGB channel on a plane facing the sun (the scene's "
                            "units); the KHR light's intensity is 683 lm/W x max(E) in lux, its colour E / max(E)");
    cJSON_AddStringToObject(u, "coefficients", "1/m");
    cJSON_AddStringToObject(u, "radiance_of_the_god_ray_layer", "W/(m^2 sr) per RGB channel, linear");
    cJSON *ax = cJSON_AddObjectToObject(x, "axes");
    cJSON_AddStringToObject(ax, "up", "+y");
    cJSON_AddStringToObject(ax, "handedness", "right");
    cJSON_AddStringToObject(ax, "azimuth", "from +z toward +x: direction (sin a, 0, cos a)");
    cJSON_AddStringToObject(ax, "gltf", "the glTF coordinates are the scene's world coordinates (glTF is also "
                            "+y up, right-handed, metres); cameras look along local -z, lights shine along local -z");
    cJSON_AddNumberToObject(x, "time_s", s->water.time_s);

    cJSON *w = cJSON_AddObjectToObject(x, "water");
    cJSON_AddNumberToObject(w, "rest_height_m", s->water.rest_height_m);
    cJSON_AddStringToObject(w, "model", "Gerstner, seed 000 eq. 5.5.7: phase_i = k_i dir_i . (x0, z0) - omega_i t + "
                            "phase_rad_i; (x, z) = (x0, z0) - sum a_i dir_i sin(phase_i); y = rest_height + "
                            "sum a_i cos(phase_i)");
    cJSON_AddNumberToObject(w, "steepness", gr_gerstner_steepness(&s->water));
    cJSON *wa = cJSON_AddArrayToObject(w, "waves");
    for (int i = 0; i < s->water.n_waves; i++) {
        const gr_wave *wv = &s->water.waves[i];
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "amplitude_m", wv->amplitude_m);
        cJSON_AddNumberToObject(e, "wavelength_m", wv->wavelength_m);
        cJSON_AddNumberToObject(e, "k_per_m", wv->k);
        cJSON_AddNumberToObject(e, "direction_deg", wv->direction_deg);
        cJSON_AddItemToObject(e, "dir_xz", num_array(wv->dir, 2));
        cJSON_AddNumberToObject(e, "omega_rad_s", wv->omega_rad_s);
        cJSON_AddNumberToObject(e, "phase_rad", wv->phase_rad);
        cJSON_AddItemToArray(wa, e);
    }
    cJSON *m = cJSON_AddObjectToObject(x, "water_mesh");
    cJSON_AddNumberToObject(m, "node", water_node);
    double c[2] = {g->cx, g->cz};
    cJSON_AddItemToObject(m, "rest_centre_xz_m", num_array(c, 2));
    cJSON_AddNumberToObject(m, "half_size_m", g->H);
    cJSON_AddNumberToObject(m, "cells", g->N);
    cJSON_AddNumberToObject(m, "spacing_m", 2.0 * g->H / g->N);
    cJSON_AddStringToObject(m, "vertex_order", "vertex i + j (cells + 1) is the displaced rest point (x0, z0) = "
                            "(cx - H + i spacing, cz - H + j spacing); positions are relative to the node's "
                            "translation (cx, rest_height, cz)");
    if (o->n_frames > 0) {
        cJSON *f = cJSON_AddObjectToObject(x, "frames");
        cJSON *ts = cJSON_AddArrayToObject(f, "water_times_s");
        for (int i = 0; i < o->n_frames; i++)
            cJSON_AddItemToArray(ts, cJSON_CreateNumber(o->frame_t0 + i * o->frame_dt));
        cJSON_AddStringToObject(f, "encoding", "morph target i of the water mesh is the surface at water_times_s[i] "
                                "(POSITION and NORMAL deltas from the base mesh at time_s); the animation "
                                "'water' sets weight i to 1 and the others to 0 (STEP) at animation time "
                                "water_times_s[i] - water_times_s[0]");
    }

    const gr_sun *sn = &s->sun;
    cJSON *su = cJSON_AddObjectToObject(x, "sun");
    cJSON_AddNumberToObject(su, "elevation_deg", sn->elevation_deg);
    cJSON_AddNumberToObject(su, "azimuth_deg", sn->azimuth_deg);
    cJSON_AddItemToObject(su, "irradiance_W_m2", vec3_json(sn->irradiance));
    cJSON_AddNumberToObject(su, "angular_diameter_deg", sn->angular_diameter_deg);
    cJSON_AddItemToObject(su, "to_sun", vec3_json(sn->to_sun));
    cJSON_AddItemToObject(su, "dir", vec3_json(sn->dir));
    double r[3] = {refr.x, refr.y, refr.z};
    cJSON_AddItemToObject(su, "refracted_dir", vec3_json(r));

    const gr_medium *md = &s->medium;
    cJSON *me = cJSON_AddObjectToObject(x, "medium");
    cJSON_AddItemToObject(me, "absorption_per_m", vec3_json(md->absorption));
    cJSON_AddItemToObject(me, "scattering_per_m", vec3_json(md->scattering));
    cJSON_AddItemToObject(me, "extinction_per_m", vec3_json(md->extinction));
    cJSON_AddNumberToObject(me, "g", md->g);
    cJSON_AddNumberToObject(me, "ior", md->ior);
    cJSON_AddStringToObject(me, "phase", "Henyey-Greenstein (seed eq. 5.5.4), normalized over the sphere");
    if (md->preset[0]) cJSON_AddStringToObject(me, "preset", md->preset);

    const gr_camera *cm = &s->camera;
    cJSON *ca = cJSON_AddObjectToObject(x, "camera");
    cJSON_AddItemToObject(ca, "position_m", vec3_json(cm->position_m));
    cJSON_AddItemToObject(ca, "forward", vec3_json(cm->forward));
    cJSON_AddItemToObject(ca, "right", vec3_json(cm->right));
    cJSON_AddItemToObject(ca, "up", vec3_json(cm->up));
    cJSON_AddNumberToObject(ca, "yaw_deg", cm->yaw_deg);
    cJSON_AddNumberToObject(ca, "pitch_deg", cm->pitch_deg);
    cJSON_AddNumberToObject(ca, "fov_y_deg", cm->fov_deg);
    cJSON_AddNumberToObject(ca, "width", cm->width);
    cJSON_AddNumberToObject(ca, "height", cm->height);
    cJSON_AddNumberToObject(ca, "znear_m", CAM_ZNEAR_M);
    cJSON_AddNumberToObject(ca, "zfar_m", CAM_ZFAR_M);

    if (s->has_seabed) {
        cJSON *sb = cJSON_AddObjectToObject(x, "seabed");
        cJSON_AddNumberToObject(sb, "depth_m", s->seabed_depth_m);
        cJSON_AddNumberToObject(sb, "y_m", s->water.rest_height_m - s->seabed_depth_m);
        cJSON_AddStringToObject(sb, "shape", "infinite plane; the mesh is a square patch of it");
    }
    cJSON *oc = cJSON_AddArrayToObject(x, "occluders");
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *q = &s->occluders[i];
        cJSON *e = cJSON_CreateObject();
        cJSON_AddStringToObject(e, "type", q->type == GR_OCC_BOX ? "box" : "sphere");
        cJSON_AddStringToObject(e, "name", q->name);
        cJSON_AddItemToObject(e, "center_m", vec3_json(q->center_m));
        if (q->type == GR_OCC_BOX) {
            cJSON_AddItemToObject(e, "size_m", vec3_json(q->size_m));
            cJSON_AddNumberToObject(e, "yaw_deg", q->yaw_deg);
        } else {
            cJSON_AddNumberToObject(e, "radius_m", q->radius_m);
            cJSON_AddStringToObject(e, "mesh", "tessellated; the exact sphere is center_m, radius_m");
        }
        cJSON_AddItemToArray(oc, e);
    }
    return x;
}

/* ---- options, paths, files ------------------------------------------------------------ */

gr_status gr_gltf_parse_frames(const char *text, const char *flag, gr_gltf_options *o, gr_error *err)
{
    double v[3];
    const char *p = text;
    for (int i = 0; i < 3; i++) {
        char *end;
        errno = 0;
        v[i] = strtod(p, &end);
        if (end == p || errno || !isfinite(v[i]) || (i < 2 ? *end != ':' : *end != '\0'))
            return gr_fail(err, GR_E_USAGE, "%s %s: expected A:B:S (first and last water time, step, in s)", flag,
                           text);
        p = end + 1;
    }
    if (!(v[2] > 0.0)) return gr_fail(err, GR_E_USAGE, "%s %s: step S must be > 0", flag, text);
    if (v[1] < v[0]) return gr_fail(err, GR_E_USAGE, "%s %s: last time B is before first time A", flag, text);
    double n = floor((v[1] - v[0]) / v[2] * (1.0 + 1e-12) + 1e-9) + 1.0;
    if (!(n <= GR_GLTF_MAX_FRAMES))
        return gr_fail(err, GR_E_USAGE, "%s %s: %.3g frames, at most %d", flag, text, n, GR_GLTF_MAX_FRAMES);
    o->frame_t0 = v[0];
    o->frame_dt = v[2];
    o->n_frames = (int)n;
    return GR_OK;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n > m && !strcasecmp(s + n - m, suffix);
}

int gr_gltf_kind(const char *path)
{
    if (!path) return 0;
    if (ends_with(path, ".gltf")) return 1;
    if (ends_with(path, ".glb")) return 2;
    return 0;
}

int gr_gltf_bin_path(const char *path, char *buf, size_t n)
{
    if (gr_gltf_kind(path) != 1) return 0;
    const size_t stem = strlen(path) - 5;
    return snprintf(buf, n, "%.*s.bin", (int)stem, path) < (int)n;
}

/* a, then b, then nzero (< 4) zero bytes into o's temporary file for path, written and checked
 * (gr_outfile_finish) but not yet renamed into place; o is released on failure */
static gr_status write_tmp(gr_outfile *o, const char *path, const void *a, size_t na, const void *b, size_t nb,
                           size_t nzero, gr_error *err)
{
    static const unsigned char zero[4] = {0, 0, 0, 0};
    gr_status st = gr_outfile_open(o, path, err);
    if (st != GR_OK) return st;
    if ((na && fwrite(a, 1, na, o->f) != na) || (nb && fwrite(b, 1, nb, o->f) != nb) ||
        (nzero && fwrite(zero, 1, nzero, o->f) != nzero)) {
        int e = errno;
        gr_outfile_abort(o);
        return gr_fail(err, GR_E_IO, "%s: write failed: %s", path, strerror(e));
    }
    return gr_outfile_finish(o, (long long)(na + nb + nzero), err);
}

/* The .bin and the .gltf that names it, as a pair: both are written and checked under their
 * temporary names first, then the .bin is renamed into place and the .gltf last. A signal
 * waits until both are in place (common/outfile), so an interrupted export leaves the old pair
 * or the new one, never a new .bin beside an old .gltf. */
static gr_status write_pair(const char *binpath, const void *bin, size_t nbin, const char *path, const char *json,
                            size_t njson, gr_error *err)
{
    gr_outfile ob, og;
    gr_status st = write_tmp(&ob, binpath, bin, nbin, NULL, 0, 0, err);
    if (st != GR_OK) return st;
    if ((st = write_tmp(&og, path, json, njson, NULL, 0, 0, err)) != GR_OK) {
        gr_outfile_abort(&ob);
        return st;
    }
    if ((st = gr_outfile_commit(&ob, (long long)nbin, err)) != GR_OK) {
        gr_outfile_abort(&og); /* the old pair stays */
        return st;
    }
    return gr_outfile_commit(&og, (long long)njson, err);
}

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v & 0xff), p[1] = (unsigned char)((v >> 8) & 0xff);
    p[2] = (unsigned char)((v >> 16) & 0xff), p[3] = (unsigned char)(v >> 24);
}

/* RFC 3986 percent-encoding of a file name for a relative URI (glTF 2.0, "URIs"). */
static char *uri_encode(const char *name)
{
    static const char hex[] = "0123456789ABCDEF";
    char *u = malloc(3 * strlen(name) + 1), *p = u;
    if (!u) return NULL;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++) {
        if ((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || strchr("-._~", *c)) {
            *p++ = (char)*c;
        } else {
            *p++ = '%', *p++ = hex[*c >> 4], *p++ = hex[*c & 15];
        }
    }
    *p = '\0';
    return u;
}

/* ---- the export ----------------------------------------------------------------------- */

/* What the export needs, known from the grid and the frames before anything is built (issue
 * 31: 1000 frames ran 160 s to 6.3 GB before the .glb's 4 GiB limit was found; 200 frames took
 * 1.4 GB under a 1 GiB limit). The binary buffer: the water's positions and normals (24 B per
 * vertex) and indices (4 B), one morph target per frame (24 B per vertex), the animation's
 * times and n_frames^2 weights; the occluders and seabed are far smaller. In memory: the buffer
 * (it grows by realloc, whose untouched capacity takes no memory) and the four vertex arrays
 * (the audit measured 1.4 GB for 200 frames, a 1.28 GB buffer). */
static gr_status check_size(const char *path, int kind, const gr_gltf_options *o, gr_error *err)
{
    const double n1 = o->grid_cells + 1.0, nv = n1 * n1, ni = 6.0 * o->grid_cells * o->grid_cells, nf = o->n_frames;
    const double bin = nv * 24.0 + ni * 4.0 + nf * nv * 24.0 + nf * 4.0 + nf * nf * 4.0;
    if (kind == 2 && bin > (double)UINT32_MAX)
        return gr_fail(err, GR_E_USAGE, "%s: about %.0f bytes, over the 4 GiB a .glb can hold; use .gltf, fewer frames or "
                       "a smaller grid", path, bin);
    char detail[160];
    snprintf(detail, sizeof detail, "a %d-cell water grid with %d frames: %.0f bytes of buffer", o->grid_cells,
             o->n_frames, bin);
    return gr_memlimit_check("the glTF export", bin + 48.0 * nv, detail, err);
}

gr_status gr_gltf_write(const gr_scene *s, const gr_gltf_options *opt, const char *path, gr_error *err)
{
    int kind = gr_gltf_kind(path);
    if (!kind) return gr_fail(err, GR_E_USAGE, "%s: unknown extension, expected .gltf or .glb", path ? path : "(null)");
    gr_gltf_options o = {0};
    if (opt) o = *opt;
    if (o.grid_cells == 0) o.grid_cells = 512;
    if (o.half_size_m == 0.0) o.half_size_m = 32.0;
    if (o.grid_cells < 1 || o.grid_cells > 4096)
        return gr_fail(err, GR_E_USAGE, "grid cells %d: must be in [1, 4096]", o.grid_cells);
    if (!(o.half_size_m > 0.0 && o.half_size_m <= 1e5))
        return gr_fail(err, GR_E_USAGE, "half size %g m: must be in (0, 1e5]", o.half_size_m);
    if (o.n_frames < 0 || o.n_frames > GR_GLTF_MAX_FRAMES || (o.n_frames > 0 && !(o.frame_dt > 0.0)))
        return gr_fail(err, GR_E_USAGE, "frames: bad count %d or step %g", o.n_frames, o.frame_dt);
    gr_status st = check_size(path, kind, &o, err);
    if (st != GR_OK) return st;

    ctx c = {0};
    float *pos = NULL, *nrm = NULL, *tp = NULL, *tn = NULL, *wts = NULL, *times = NULL;
    uint32_t *idx = NULL;
    char *json = NULL, *binpath = NULL;

    /* Patch centre: the point P of seed eq. 5.5.5 (where the refracted sun ray through the eye
     * meets the rest plane), the centre of the surface that lights the viewer's surroundings;
     * the eye's (x, z) when P is not finite (an eye above the water). */
    const gr_camera *cm = &s->camera;
    gr_dvec3 eye = d3v(cm->position_m), refr;
    gr_dvec3 P = gr_shafts_center(eye, d3v(s->sun.dir), s->water.rest_height_m, s->medium.ior, &refr);
    water_grid g = {o.grid_cells, P.x, P.z, o.half_size_m, s->water.rest_height_m};
    if (!(isfinite(P.x) && isfinite(P.z)) || eye.y > s->water.rest_height_m) g.cx = eye.x, g.cz = eye.z;

    c.root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(c.root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "godrays export 0.1.0");
    cJSON *used = cJSON_AddArrayToObject(c.root, "extensionsUsed");
    cJSON_AddItemToArray(used, cJSON_CreateString("KHR_lights_punctual"));
    c.views = cJSON_AddArrayToObject(c.root, "bufferViews");
    c.accessors = cJSON_AddArrayToObject(c.root, "accessors");
    c.materials = cJSON_AddArrayToObject(c.root, "materials");
    c.meshes = cJSON_AddArrayToObject(c.root, "meshes");
    c.nodes = cJSON_AddArrayToObject(c.root, "nodes");
    add_material(&c, "water", 0.6, 0.8, 0.9, 0.05);
    add_material(&c, "occluder", 0.3, 0.3, 0.3, 0.8);
    add_material(&c, "seabed", 0.5, 0.45, 0.35, 0.9);
    cJSON *scene_nodes = cJSON_CreateArray();

    /* water */
    int n1 = o.grid_cells + 1;
    int nv = n1 * n1, ni = 6 * o.grid_cells * o.grid_cells;
    pos = malloc(sizeof *pos * 3u * (size_t)nv);
    nrm = malloc(sizeof *nrm * 3u * (size_t)nv);
    idx = malloc(sizeof *idx * (size_t)ni);
    if (!pos || !nrm || !idx || !c.root) {
        st = gr_fail(err, GR_E_NOMEM, "%s: out of memory for a %d-cell water mesh", path, o.grid_cells);
        goto done;
    }
    water_surface(&s->water, &g, s->water.time_s, pos, nrm);
    grid_indices(o.grid_cells, idx);
    int mesh_i, node_i;
    cJSON *wm = add_mesh(&c, "water", pos, nrm, nv, idx, ni, 0, &mesh_i);
    if (!wm) goto nomem;
    double wt[3] = {g.cx, g.h0, g.cz};
    cJSON *wn = add_node(&c, "water", wt, NULL, &node_i);
    cJSON_AddNumberToObject(wn, "mesh", mesh_i);
    cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(node_i));
    int water_node = node_i;
    if (o.n_frames > 0) {
        /* Morph targets: deltas from the base mesh (docs/engines.md, "Animation"). */
        tp = malloc(sizeof *tp * 3u * (size_t)nv);
        tn = malloc(sizeof *tn * 3u * (size_t)nv);
        wts = calloc((size_t)o.n_frames * (size_t)o.n_frames, sizeof *wts);
        times = malloc(sizeof *times * (size_t)o.n_frames);
        if (!tp || !tn || !wts || !times) goto nomem;
        cJSON *prim = cJSON_GetArrayItem(cJSON_GetObjectItem(wm, "primitives"), 0);
        cJSON *targets = cJSON_AddArrayToObject(prim, "targets");
        cJSON *mw = cJSON_AddArrayToObject(wm, "weights");
        cJSON *names = cJSON_AddArrayToObject(cJSON_AddObjectToObject(wm, "extras"), "targetNames");
        for (int f = 0; f < o.n_frames; f++) {
            double t = o.frame_t0 + f * o.frame_dt;
            water_surface(&s->water, &g, t, tp, tn);
            for (size_t k = 0; k < 3u * (size_t)nv; k++) {
                tp[k] = (float)((double)tp[k] - (double)pos[k]);
                tn[k] = (float)((double)tn[k] - (double)nrm[k]);
            }
            int ap = add_accessor(&c, tp, nv, 3, GL_FLOAT_, GL_ARRAY_BUFFER_, 1);
            int an = add_accessor(&c, tn, nv, 3, GL_FLOAT_, GL_ARRAY_BUFFER_, 0);
            if (ap < 0 || an < 0) goto nomem;
            cJSON *tg = cJSON_CreateObject();
            cJSON_AddNumberToObject(tg, "POSITION", ap);
            cJSON_AddNumberToObject(tg, "NORMAL", an);
            cJSON_AddItemToArray(targets, tg);
            cJSON_AddItemToArray(mw, cJSON_CreateNumber(0));
            char name[64];
            snprintf(name, sizeof name, "t=%.9g", t);
            cJSON_AddItemToArray(names, cJSON_CreateString(name));
            times[f] = (float)(f * o.frame_dt);
            wts[(size_t)f * o.n_frames + f] = 1.0f;
        }
        int ain = add_accessor(&c, times, o.n_frames, 1, GL_FLOAT_, 0, 1);
        int aout = add_accessor(&c, wts, o.n_frames * o.n_frames, 1, GL_FLOAT_, 0, 0);
        if (ain < 0 || aout < 0) goto nomem;
        cJSON *anim = cJSON_CreateObject();
        cJSON_AddStringToObject(anim, "name", "water");
        cJSON *smp = cJSON_CreateObject();
        cJSON_AddNumberToObject(smp, "input", ain);
        cJSON_AddNumberToObject(smp, "output", aout);
        cJSON_AddStringToObject(smp, "interpolation", "STEP");
        cJSON_AddItemToArray(cJSON_AddArrayToObject(anim, "samplers"), smp);
        cJSON *ch = cJSON_CreateObject();
        cJSON_AddNumberToObject(ch, "sampler", 0);
        cJSON *tgt = cJSON_AddObjectToObject(ch, "target");
        cJSON_AddNumberToObject(tgt, "node", water_node);
        cJSON_AddStringToObject(tgt, "path", "weights");
        cJSON_AddItemToArray(cJSON_AddArrayToObject(anim, "channels"), ch);
        cJSON_AddItemToArray(cJSON_AddArrayToObject(c.root, "animations"), anim);
    }

    /* seabed: a square of the plane under the water patch, wider by the depth (light reaches
     * it sheared along the refracted sun) */
    if (s->has_seabed) {
        double hs = g.H + s->seabed_depth_m;
        float sp[12] = {(float)-hs, 0, (float)-hs, (float)hs, 0, (float)-hs, (float)hs, 0, (float)hs,
                        (float)-hs, 0, (float)hs};
        float sn[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
        uint32_t si[6] = {0, 3, 1, 1, 3, 2}; /* counter-clockwise seen from +y */
        if (!add_mesh(&c, "seabed", sp, sn, 4, si, 6, 2, &mesh_i)) goto nomem;
        double t[3] = {g.cx, s->water.rest_height_m - s->seabed_depth_m, g.cz};
        cJSON *n = add_node(&c, "seabed", t, NULL, &node_i);
        cJSON_AddNumberToObject(n, "mesh", mesh_i);
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(node_i));
    }

    /* occluders: meshes about their centre, placed by the node (boxes turned by yaw about +y:
     * +z toward +x, as reference/embree_scene.c builds them) */
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *q = &s->occluders[i];
        char name[96];
        snprintf(name, sizeof name, "%s", q->name[0] ? q->name : (q->type == GR_OCC_BOX ? "box" : "sphere"));
        if (q->type == GR_OCC_BOX) {
            float bp[72], bn[72];
            uint32_t bi[36];
            box_mesh(q->size_m, bp, bn, bi);
            if (!add_mesh(&c, name, bp, bn, 24, bi, 36, 1, &mesh_i)) goto nomem;
            double a = q->yaw_deg * DEG2RAD, rot[4] = {0.0, sin(0.5 * a), 0.0, cos(0.5 * a)};
            cJSON *n = add_node(&c, name, q->center_m, rot, &node_i);
            cJSON_AddNumberToObject(n, "mesh", mesh_i);
        } else {
            float *sp = malloc(sizeof *sp * 3u * SPHERE_NV), *snn = malloc(sizeof *snn * 3u * SPHERE_NV);
            uint32_t *si = malloc(sizeof *si * SPHERE_NI);
            cJSON *m = NULL;
            if (sp && snn && si) {
                sphere_mesh(q->radius_m, sp, snn, si);
                m = add_mesh(&c, name, sp, snn, SPHERE_NV, si, SPHERE_NI, 1, &mesh_i);
            }
            free(sp), free(snn), free(si);
            if (!m) goto nomem;
            cJSON *n = add_node(&c, name, q->center_m, NULL, &node_i);
            cJSON_AddNumberToObject(n, "mesh", mesh_i);
        }
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(node_i));
    }

    /* camera: glTF cameras look along local -z with +y up, so the node's rotation has columns
     * (right, up, -forward) of the scene's camera frame (scene.h) */
    {
        cJSON *cams = cJSON_AddArrayToObject(c.root, "cameras");
        cJSON *cam = cJSON_CreateObject();
        cJSON_AddStringToObject(cam, "name", "camera");
        cJSON_AddStringToObject(cam, "type", "perspective");
        cJSON *pr = cJSON_AddObjectToObject(cam, "perspective");
        cJSON_AddNumberToObject(pr, "yfov", cm->fov_deg * DEG2RAD);
        cJSON_AddNumberToObject(pr, "aspectRatio", (double)cm->width / (double)cm->height);
        cJSON_AddNumberToObject(pr, "znear", CAM_ZNEAR_M);
        cJSON_AddNumberToObject(pr, "zfar", CAM_ZFAR_M);
        cJSON_AddItemToArray(cams, cam);
        double q[4];
        quat_from_frame(d3v(cm->right), d3v(cm->up), gr_d3_scale(d3v(cm->forward), -1.0), q);
        cJSON *n = add_node(&c, "camera", cm->position_m, q, &node_i);
        cJSON_AddNumberToObject(n, "camera", 0);
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(node_i));
    }

    /* sun: a directional light shines along its node's local -z, so local +z = to_sun */
    {
        const gr_sun *sn = &s->sun;
        double emax = fmax(sn->irradiance[0], fmax(sn->irradiance[1], sn->irradiance[2]));
        double col[3] = {1.0, 1.0, 1.0};
        if (emax > 0.0)
            for (int k = 0; k < 3; k++) col[k] = sn->irradiance[k] / emax;
        cJSON *ext = cJSON_AddObjectToObject(c.root, "extensions");
        cJSON *lights = cJSON_AddArrayToObject(cJSON_AddObjectToObject(ext, "KHR_lights_punctual"), "lights");
        cJSON *l = cJSON_CreateObject();
        cJSON_AddStringToObject(l, "name", "sun");
        cJSON_AddStringToObject(l, "type", "directional");
        cJSON_AddItemToObject(l, "color", num_array(col, 3));
        /* KHR_lights_punctual: a directional intensity is in lux. E is radiometric (W/m^2); the
         * standard luminous efficacy 683 lm/W turns it into lux, the factor importers such as
         * Blender's divide by to get W/m^2 back (docs/engines.md, 1.2) */
        cJSON_AddNumberToObject(l, "intensity", GR_GLTF_LM_PER_W * emax);
        cJSON_AddItemToArray(lights, l);
        gr_dvec3 z = d3v(sn->to_sun);
        gr_dvec3 xa = gr_d3_cross(gr_d3(0, 1, 0), z);
        if (gr_d3_len(xa) < 1e-9) xa = gr_d3(1, 0, 0); /* sun at the zenith */
        xa = gr_d3_norm(xa);
        gr_dvec3 ya = gr_d3_cross(z, xa);
        double q[4];
        quat_from_frame(xa, ya, z, q);
        /* a directional light has no position; the node sits above P for viewers */
        double t[3] = {P.x, s->water.rest_height_m + 10.0, P.z};
        if (!(isfinite(t[0]) && isfinite(t[2]))) t[0] = eye.x, t[2] = eye.z;
        cJSON *n = add_node(&c, "sun", t, q, &node_i);
        cJSON *ne = cJSON_AddObjectToObject(n, "extensions");
        cJSON_AddNumberToObject(cJSON_AddObjectToObject(ne, "KHR_lights_punctual"), "light", 0);
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(node_i));
    }

    cJSON_AddNumberToObject(c.root, "scene", 0);
    cJSON *scene = cJSON_CreateObject();
    cJSON_AddStringToObject(scene, "name", s->name[0] ? s->name : "godrays");
    cJSON_AddItemToObject(scene, "nodes", scene_nodes);
    scene_nodes = NULL;
    cJSON *extras = cJSON_AddObjectToObject(scene, "extras");
    cJSON_AddItemToObject(extras, "godrays", extras_json(s, &g, &o, refr, water_node));
    cJSON_AddItemToArray(cJSON_AddArrayToObject(c.root, "scenes"), scene);
    if (c.nomem) goto nomem;

    /* buffer */
    size_t plen = strlen(path);
    binpath = malloc(plen + 8);
    if (!binpath) goto nomem;
    binpath[0] = '\0';
    size_t binlen = c.n;
    cJSON *buf = cJSON_CreateObject();
    cJSON_AddNumberToObject(buf, "byteLength", (double)binlen);
    const char *uri_name = NULL;
    if (kind == 1) {
        gr_gltf_bin_path(path, binpath, plen + 8);
        const char *slash = strrchr(binpath, '/');
        uri_name = slash ? slash + 1 : binpath;
        char *uri = uri_encode(uri_name);
        if (!uri) goto nomem;
        cJSON_AddStringToObject(buf, "uri", uri);
        free(uri);
    }
    cJSON_AddItemToArray(cJSON_AddArrayToObject(c.root, "buffers"), buf);
    json = cJSON_PrintUnformatted(c.root);
    if (!json) goto nomem;
    size_t jlen = strlen(json);
    if (kind == 1) {
        st = write_pair(binpath, c.bin, binlen, path, json, jlen, err);
    } else {
        /* GLB (glTF 2.0 spec, "Binary glTF Layout"): 12-byte header, JSON chunk padded with
         * spaces, BIN chunk padded with zeros, both to 4 bytes */
        size_t jpad = (jlen + 3u) & ~(size_t)3u, bpad = (binlen + 3u) & ~(size_t)3u;
        size_t total = 12u + 8u + jpad + 8u + bpad;
        if (total > UINT32_MAX) {
            st = gr_fail(err, GR_E_USAGE, "%s: %zu bytes, over the 4 GiB a .glb can hold; use .gltf or a smaller grid",
                         path, total);
            goto done;
        }
        unsigned char *head = malloc(12u + 8u + jpad + 8u);
        if (!head) goto nomem;
        put_u32(head, 0x46546C67u); /* "glTF" */
        put_u32(head + 4, 2u);
        put_u32(head + 8, (uint32_t)total);
        put_u32(head + 12, (uint32_t)jpad);
        put_u32(head + 16, 0x4E4F534Au); /* "JSON" */
        memcpy(head + 20, json, jlen);
        memset(head + 20 + jlen, ' ', jpad - jlen);
        put_u32(head + 20 + jpad, (uint32_t)bpad);
        put_u32(head + 24 + jpad, 0x004E4942u); /* "BIN\0" */
        gr_outfile out;
        st = write_tmp(&out, path, head, 28u + jpad, c.bin, binlen, bpad - binlen, err);
        if (st == GR_OK) st = gr_outfile_commit(&out, (long long)total, err);
        free(head);
    }
    goto done;

nomem:
    st = gr_fail(err, GR_E_NOMEM, "%s: out of memory building the glTF", path);
done:
    cJSON_Delete(scene_nodes);
    cJSON_Delete(c.root);
    free(c.bin);
    free(json), free(binpath);
    free(pos), free(nrm), free(idx), free(tp), free(tn), free(wts), free(times);
    return st;
}
