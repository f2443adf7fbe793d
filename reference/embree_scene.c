#include "reference/embree_scene.h"

#include <float.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void rtc_error_cb(void *user, enum RTCError code, const char *str)
{
    gr_rtc *r = user;
    if (r->last.status != GR_OK) return; /* keep the first error: later ones are usually consequences */
    gr_status st = code == RTC_ERROR_OUT_OF_MEMORY ? GR_E_NOMEM : GR_E_EMBREE;
    gr_fail(&r->last, st, "Embree error %d: %s", (int)code, str ? str : "(no message)");
}

gr_status gr_rtc_create(int threads, gr_rtc **out, gr_error *err)
{
    *out = NULL;
    gr_rtc *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the Embree device");
    char cfg[64] = "";
    if (threads > 0) snprintf(cfg, sizeof cfg, "threads=%d", threads);
    r->device = rtcNewDevice(cfg[0] ? cfg : NULL);
    if (!r->device) {
        enum RTCError e = rtcGetDeviceError(NULL);
        free(r);
        return gr_fail(err, GR_E_EMBREE, "reference: rtcNewDevice(\"%s\") failed with Embree error %d", cfg, (int)e);
    }
    r->last.status = GR_OK;
    rtcSetDeviceErrorFunction(r->device, rtc_error_cb, r);
    *out = r;
    return GR_OK;
}

void gr_rtc_destroy(gr_rtc *r)
{
    if (!r) return;
    if (r->device) rtcReleaseDevice(r->device);
    free(r);
}

gr_status gr_rtc_check(gr_rtc *r, const char *what, gr_error *err)
{
    if (!r || r->last.status == GR_OK) return GR_OK;
    gr_status st = r->last.status;
    if (err) {
        *err = r->last;
        gr_error_prefix(err, "%s", what);
    }
    r->last.status = GR_OK;
    r->last.msg[0] = '\0';
    return st;
}

/* Appends one triangle-mesh box (12 triangles) rotated by yaw about +y: positive yaw turns
 * the box's +z axis toward +x, the azimuth convention of scene.h. */
static void add_box(RTCDevice dev, RTCScene scene, const gr_occluder *o, gr_dvec3 origin)
{
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 8);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 12);
    if (!v || !idx) { rtcReleaseGeometry(g); return; } /* the error callback has the reason */
    double a = o->yaw_deg * 3.14159265358979323846 / 180.0;
    gr_dvec3 ex = gr_d3(cos(a), 0.0, -sin(a)), ey = gr_d3(0, 1, 0), ez = gr_d3(sin(a), 0.0, cos(a));
    gr_dvec3 c = gr_d3_sub(gr_d3(o->center_m[0], o->center_m[1], o->center_m[2]), origin);
    for (int i = 0; i < 8; i++) {
        double sx = (i & 1) ? 0.5 : -0.5, sy = (i & 2) ? 0.5 : -0.5, sz = (i & 4) ? 0.5 : -0.5;
        gr_dvec3 p = gr_d3_madd(gr_d3_madd(gr_d3_madd(c, ex, sx * o->size_m[0]), ey, sy * o->size_m[1]),
                                ez, sz * o->size_m[2]);
        v[3 * i + 0] = (float)p.x;
        v[3 * i + 1] = (float)p.y;
        v[3 * i + 2] = (float)p.z;
    }
    /* two triangles per face; winding does not matter (no culling, rays are two-sided) */
    static const unsigned faces[6][4] = {
        {0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int f = 0; f < 6; f++) {
        idx[6 * f + 0] = faces[f][0]; idx[6 * f + 1] = faces[f][1]; idx[6 * f + 2] = faces[f][2];
        idx[6 * f + 3] = faces[f][0]; idx[6 * f + 4] = faces[f][2]; idx[6 * f + 5] = faces[f][3];
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

static void add_spheres(RTCDevice dev, RTCScene scene, const gr_scene *s, gr_dvec3 origin)
{
    int n = 0;
    for (int i = 0; i < s->n_occluders; i++) n += s->occluders[i].type == GR_OCC_SPHERE;
    if (!n) return;
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), (size_t)n);
    if (!v) { rtcReleaseGeometry(g); return; }
    int k = 0;
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *o = &s->occluders[i];
        if (o->type != GR_OCC_SPHERE) continue;
        v[4 * k + 0] = (float)(o->center_m[0] - origin.x);
        v[4 * k + 1] = (float)(o->center_m[1] - origin.y);
        v[4 * k + 2] = (float)(o->center_m[2] - origin.z);
        v[4 * k + 3] = (float)o->radius_m;
        k++;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

static void add_occluders(RTCDevice dev, RTCScene scene, const gr_scene *s, gr_dvec3 origin)
{
    for (int i = 0; i < s->n_occluders; i++)
        if (s->occluders[i].type == GR_OCC_BOX) add_box(dev, scene, &s->occluders[i], origin);
    add_spheres(dev, scene, s, origin);
}

gr_status gr_ref_geometry_create(gr_rtc *rtc, const gr_scene *s, gr_dvec3 origin,
                                 double seabed_half_size_m, gr_ref_geometry **out, gr_error *err)
{
    *out = NULL;
    gr_ref_geometry *g = calloc(1, sizeof *g);
    if (!g) return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the scene geometry");
    g->origin = origin;
    g->n_occluders = s->n_occluders;
    g->has_seabed = s->has_seabed;
    if (s->n_occluders > 0) {
        g->bound = calloc((size_t)s->n_occluders, sizeof *g->bound);
        if (!g->bound) { free(g); return gr_fail(err, GR_E_NOMEM, "reference: out of memory for the occluders"); }
        for (int i = 0; i < s->n_occluders; i++) {
            const gr_occluder *o = &s->occluders[i];
            gr_ref_bound *b = &g->bound[i];
            gr_dvec3 c = gr_d3_sub(gr_d3(o->center_m[0], o->center_m[1], o->center_m[2]), origin);
            b->c[0] = (float)c.x; b->c[1] = (float)c.y; b->c[2] = (float)c.z;
            b->sphere = o->type == GR_OCC_SPHERE;
            /* padded well beyond float rounding, so the prefilter never misses a hit */
            b->r = (float)(o->radius_m * 1.0001 + 1e-3);
            for (int k = 0; k < 3; k++) b->h[k] = (float)(0.5 * o->size_m[k] * 1.0001 + 1e-3);
            double a = o->yaw_deg * 3.14159265358979323846 / 180.0;
            b->ca = (float)cos(a);
            b->sa = (float)sin(a);
        }
    }
    RTCDevice dev = rtc->device;
    if (s->n_occluders > 0 || s->has_seabed) {
        g->ends = rtcNewScene(dev);
        if (g->ends) {
            rtcSetSceneBuildQuality(g->ends, RTC_BUILD_QUALITY_HIGH);
            add_occluders(dev, g->ends, s, origin);
            if (s->has_seabed) {
                /* the seabed plane as one large quad centred on the local origin */
                RTCGeometry q = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
                float *v = rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4);
                unsigned *idx = rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2);
                if (v && idx) {
                    float y = (float)(s->water.rest_height_m - s->seabed_depth_m - origin.y);
                    float h = (float)seabed_half_size_m;
                    const float c[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
                    for (int i = 0; i < 4; i++) { v[3 * i] = c[i][0]; v[3 * i + 1] = y; v[3 * i + 2] = c[i][1]; }
                    idx[0] = 0; idx[1] = 1; idx[2] = 2; idx[3] = 0; idx[4] = 2; idx[5] = 3;
                    rtcCommitGeometry(q);
                    rtcAttachGeometry(g->ends, q);
                }
                rtcReleaseGeometry(q);
            }
            rtcCommitScene(g->ends);
        }
    }
    if (s->n_occluders > 0) {
        g->shadow = rtcNewScene(dev);
        if (g->shadow) {
            add_occluders(dev, g->shadow, s, origin);
            rtcCommitScene(g->shadow);
        }
    }
    gr_status st = gr_rtc_check(rtc, "reference: building occluders and seabed", err);
    if (st != GR_OK) {
        gr_ref_geometry_destroy(g);
        return st;
    }
    *out = g;
    return GR_OK;
}

void gr_ref_geometry_destroy(gr_ref_geometry *g)
{
    if (!g) return;
    if (g->ends) rtcReleaseScene(g->ends);
    if (g->shadow) rtcReleaseScene(g->shadow);
    free(g->bound);
    free(g);
}

float gr_rtc_intersect(RTCScene scene, gr_vec3 o, gr_vec3 d, float tnear, float tfar,
                       unsigned *hit_geom, float *ng_y)
{
    if (hit_geom) *hit_geom = RTC_INVALID_GEOMETRY_ID;
    if (!scene || !(tfar > tnear)) return tfar;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.mask = ~0u; /* mask support is compiled in: a zero mask misses everything */
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return tfar;
    if (hit_geom) *hit_geom = rh.hit.geomID;
    if (ng_y) *ng_y = rh.hit.Ng_y;
    return rh.ray.tfar;
}

int gr_rtc_occluded(RTCScene scene, gr_vec3 o, gr_vec3 d, float tnear, float tfar)
{
    if (!scene || !(tfar > tnear)) return 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    memset(&r, 0, sizeof r);
    r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
    r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
    r.tnear = tnear;
    r.tfar = tfar;
    r.mask = ~0u;
    rtcOccluded1(scene, &ctx, &r);
    return r.tfar < 0.0f; /* Embree sets tfar = -inf on a hit */
}

/* Does the segment o + t d, t in [0, tmax] (unit d), touch the padded shape grown by pad
 * (a sphere's radius, a box's half extents: the box contains the shape's pad-neighbourhood)? */
static int segment_touches(const gr_ref_bound *b, gr_vec3 o, gr_vec3 d, float tmax, float pad)
{
    float v[3] = {b->c[0] - o.x, b->c[1] - o.y, b->c[2] - o.z};
    if (b->sphere) {
        float t = v[0] * d.x + v[1] * d.y + v[2] * d.z;
        t = t < 0.0f ? 0.0f : t > tmax ? tmax : t;
        float q[3] = {v[0] - t * d.x, v[1] - t * d.y, v[2] - t * d.z};
        return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= (b->r + pad) * (b->r + pad);
    }
    /* into the box's frame: ex = (cos, 0, -sin), ey = y, ez = (sin, 0, cos) (add_box) */
    float lo[3] = {-v[0] * b->ca + v[2] * b->sa, -v[1], -v[0] * b->sa - v[2] * b->ca};
    float dl[3] = {d.x * b->ca - d.z * b->sa, d.y, d.x * b->sa + d.z * b->ca};
    float t0 = 0.0f, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        float h = b->h[k] + pad;
        if (dl[k] == 0.0f) {
            if (lo[k] < -h || lo[k] > h) return 0;
            continue;
        }
        float inv = 1.0f / dl[k], ta = (-h - lo[k]) * inv, tb = (h - lo[k]) * inv;
        if (ta > tb) { float x = ta; ta = tb; tb = x; }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
        if (t0 > t1) return 0;
    }
    return 1;
}

int gr_ref_shadowed(const gr_ref_geometry *g, gr_vec3 o, gr_vec3 d, float tfar)
{
    if (!g->shadow || !(tfar > 0.0f)) return 0;
    int near = 0;
    for (int i = 0; i < g->n_occluders && !near; i++) near = segment_touches(&g->bound[i], o, d, tfar, 0.0f);
    return near ? gr_rtc_occluded(g->shadow, o, d, 0.0f, tfar) : 0;
}

int gr_ref_shadow_near(const gr_ref_geometry *g, gr_vec3 o, gr_vec3 d, float tmax, float spread)
{
    if (!g->shadow || !(tmax > 0.0f)) return 0;
    /* a point o - t d' of such a segment lies within t |d' - d| <= spread of o + t d on this
     * one: if this one misses every shape grown by spread, they all miss the shapes. 1 mm
     * more against the rounding of the two computations (the shapes' own pad is for
     * gr_ref_shadowed's); not finite: near */
    float pad = spread + 1e-3f;
    if (!(pad < FLT_MAX)) return 1;
    for (int i = 0; i < g->n_occluders; i++)
        if (segment_touches(&g->bound[i], o, d, tmax, pad)) return 1;
    return 0;
}
