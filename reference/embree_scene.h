/* Embree device and the static geometry of the ground truth: occluders (boxes as triangle
 * meshes, spheres as Embree sphere points) and the seabed plane. Everything is placed in a
 * local frame whose origin is given in double precision (the camera's horizontal position
 * at the water's rest height), so that a scene 1e5 m from the world origin keeps
 * millimetre precision in Embree's float geometry. Embree's own errors are routed into
 * gr_error through rtcSetDeviceErrorFunction. */
#ifndef GR_REF_EMBREE_SCENE_H
#define GR_REF_EMBREE_SCENE_H

#include <embree3/rtcore.h>
#include "common/status.h"
#include "core/vec.h"
#include "scene/scene.h"

/* An Embree device plus the last error it reported (first error wins until cleared). */
typedef struct gr_rtc {
    RTCDevice device;
    gr_error last;      /* status GR_OK while nothing went wrong */
} gr_rtc;

/* threads: 0 = Embree's default (all cores), else the number of build threads. */
gr_status gr_rtc_create(int threads, gr_rtc **out, gr_error *err);
void gr_rtc_destroy(gr_rtc *r); /* accepts NULL */
/* If Embree reported an error since the last call, copies it into err (prefixed with
 * `what`), clears it and returns its status; else GR_OK. */
gr_status gr_rtc_check(gr_rtc *r, const char *what, gr_error *err);

/* An occluder's padded shape in the local frame, for the shadow rays' prefilter. */
typedef struct gr_ref_bound {
    int sphere;          /* 1: sphere (c, r); 0: box (c, half extents h, yaw as cos/sin) */
    float c[3], h[3], r, ca, sa;
} gr_ref_bound;

/* Static scene in the local frame (local = world - origin). */
typedef struct gr_ref_geometry {
    RTCScene ends;       /* occluders + seabed: where camera rays stop (NULL if empty) */
    RTCScene shadow;     /* occluders only: shadow rays (NULL when there are no occluders) */
    gr_dvec3 origin;     /* world position of the local origin */
    int n_occluders;
    int has_seabed;
    gr_ref_bound *bound; /* one per occluder, padded by 1e-4 relative + 1 mm */
} gr_ref_geometry;

/* Builds the static scenes. seabed_half_size_m: half extent of the seabed quad around
 * the origin (it only needs to cover what camera rays can reach). */
gr_status gr_ref_geometry_create(gr_rtc *rtc, const gr_scene *s, gr_dvec3 origin,
                                 double seabed_half_size_m, gr_ref_geometry **out, gr_error *err);
void gr_ref_geometry_destroy(gr_ref_geometry *g); /* accepts NULL */

/* Distance along the unit local ray (o, d) to the first hit of scene within (tnear, tfar);
 * returns tfar when nothing is hit (or scene is NULL). *hit_geom (may be NULL) gets the
 * geometry id or RTC_INVALID_GEOMETRY_ID. */
float gr_rtc_intersect(RTCScene scene, gr_vec3 o, gr_vec3 d, float tnear, float tfar,
                       unsigned *hit_geom, float *ng_y);
/* 1 if anything in scene blocks the segment o + t d, t in (tnear, tfar); 0 if scene NULL. */
int gr_rtc_occluded(RTCScene scene, gr_vec3 o, gr_vec3 d, float tnear, float tfar);
/* The same against g->shadow (unit d), with a prefilter: a segment that misses every
 * occluder's padded shape (tested here in closed form) is not traced; the others go to
 * Embree, whose answer counts. */
int gr_ref_shadowed(const gr_ref_geometry *g, gr_vec3 o, gr_vec3 d, float tfar);
/* The prefilter for a bundle of shadow rays from o at once: 0 when no segment o + t d',
 * t in [0, tmax], with unit d' and |d' - d| tmax <= spread, can touch an occluder's padded
 * shape (each gr_ref_shadowed of the bundle would then return 0 untraced); else 1. */
int gr_ref_shadow_near(const gr_ref_geometry *g, gr_vec3 o, gr_vec3 d, float tmax, float spread);

#endif
