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
/* Unit vector along a; a zero vector stays zero (never NaN). */
static inline gr_vec3 gr_v3_norm(gr_vec3 a)
{
    float l = gr_v3_len(a);
    return l > 0.0f ? gr_v3_scale(a, 1.0f / l) : a;
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
static inline gr_dvec3 gr_d3_norm(gr_dvec3 a)
{
    double l = gr_d3_len(a);
    return l > 0.0 ? gr_d3_scale(a, 1.0 / l) : a;
}
static inline gr_vec3 gr_d3_to_f(gr_dvec3 a) { return gr_v3((float)a.x, (float)a.y, (float)a.z); }
static inline gr_dvec3 gr_v3_to_d(gr_vec3 a) { return gr_d3(a.x, a.y, a.z); }

#endif
