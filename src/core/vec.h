/* Small 3-vector math, header-only. float for per-sample work (style habit 4);
 * double variants (gr_dvec3) for geometry that must stay exact far from the origin. */
#ifndef GR_VEC_H
#define GR_VEC_H
#include <math.h>

typedef struct gr_vec3 { float x, y, z; } gr_vec3;
typedef struct gr_dvec3 { double x, y, z; } gr_dvec3;

static inline gr_vec3 gr_v3(float x, float y, float z) { gr_vec3 r = {x, y, z}; return r; }
static inline gr_vec3 gr_v3_add(gr_vec3 a, gr_vec3 b) { return gr_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline gr_vec3 gr_v3_sub(gr_vec3 a, gr_vec3 b) { return gr_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline gr_vec3 gr_v3_scale(gr_vec3 a, float s) { return gr_v3(a.x * s, a.y * s, a.z * s); }
static inline gr_vec3 gr_v3_mul(gr_vec3 a, gr_vec3 b) { return gr_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline gr_vec3 gr_v3_madd(gr_vec3 a, gr_vec3 b, float s) { return gr_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float gr_v3_dot(gr_vec3 a, gr_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline gr_vec3 gr_v3_cross(gr_vec3 a, gr_vec3 b)
{
    return gr_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float gr_v3_len(gr_vec3 a) { return sqrtf(gr_v3_dot(a, a)); }
/* Unit vector along a; a zero vector stays zero (never NaN). Vectors whose squared length
 * would underflow or overflow (components below ~1e-19 or above ~1e19) are rescaled by
 * their largest component first, so they still come out unit length. */
static inline gr_vec3 gr_v3_norm(gr_vec3 a)
{
    float l2 = gr_v3_dot(a, a);
    if (!(l2 >= 1e-30f && l2 <= 1e30f)) {
        float m = fmaxf(fabsf(a.x), fmaxf(fabsf(a.y), fabsf(a.z)));
        if (!(m > 0.0f) || isinf(m))
            return a; /* zero (or non-finite) stays as it is */
        a = gr_v3(a.x / m, a.y / m, a.z / m); /* divide: 1/m may overflow for denormal m */
        l2 = gr_v3_dot(a, a);
    }
    return gr_v3_scale(a, 1.0f / sqrtf(l2));
}

static inline gr_dvec3 gr_d3(double x, double y, double z) { gr_dvec3 r = {x, y, z}; return r; }
static inline gr_dvec3 gr_d3_add(gr_dvec3 a, gr_dvec3 b) { return gr_d3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline gr_dvec3 gr_d3_sub(gr_dvec3 a, gr_dvec3 b) { return gr_d3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline gr_dvec3 gr_d3_scale(gr_dvec3 a, double s) { return gr_d3(a.x * s, a.y * s, a.z * s); }
static inline gr_dvec3 gr_d3_madd(gr_dvec3 a, gr_dvec3 b, double s) { return gr_d3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline double gr_d3_dot(gr_dvec3 a, gr_dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline gr_dvec3 gr_d3_cross(gr_dvec3 a, gr_dvec3 b)
{
    return gr_d3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double gr_d3_len(gr_dvec3 a) { return sqrt(gr_d3_dot(a, a)); }
/* Same contract as gr_v3_norm, with the rescue for components below ~1e-150 / above ~1e150. */
static inline gr_dvec3 gr_d3_norm(gr_dvec3 a)
{
    double l2 = gr_d3_dot(a, a);
    if (!(l2 >= 1e-300 && l2 <= 1e300)) {
        double m = fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
        if (!(m > 0.0) || isinf(m))
            return a;
        a = gr_d3(a.x / m, a.y / m, a.z / m);
        l2 = gr_d3_dot(a, a);
    }
    return gr_d3_scale(a, 1.0 / sqrt(l2));
}
static inline gr_vec3 gr_d3_to_f(gr_dvec3 a) { return gr_v3((float)a.x, (float)a.y, (float)a.z); }
static inline gr_dvec3 gr_v3_to_d(gr_vec3 a) { return gr_d3(a.x, a.y, a.z); }

#endif
