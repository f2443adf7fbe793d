/* Optics of the air-water interface and of the medium (seed 000 eqs. 5.5.1-5.5.4).
 * Derivations and the Schlick-vs-exact table: docs/optics.md. */
#ifndef GR_OPTICS_H
#define GR_OPTICS_H

#include <math.h>

#include "core/vec.h"

#define GR_PI 3.14159265358979323846

/* Seed eq. 5.5.1 with GLSL `refract` semantics: I and N unit, N on the incident side
 * (dot(N, I) < 0), eta = n1 / n2. Returns the unit transmitted direction, or the zero
 * vector on total internal reflection. */
gr_vec3 gr_refract(gr_vec3 I, gr_vec3 N, float eta);
gr_dvec3 gr_refract_d(gr_dvec3 I, gr_dvec3 N, double eta);

/* Exact unpolarized Fresnel reflectance of a dielectric interface (average of s and p),
 * for the cosine of the incidence angle cos_i in [0, 1] measured on the side of index n1.
 * Returns 1 on total internal reflection. */
double gr_fresnel_exact(double cos_i, double n1, double n2);
/* The two polarizations of gr_fresnel_exact: reflectances R_s (TE) and R_p (TM), so that
 * gr_fresnel_exact = (R_s + R_p) / 2. Both are 1 on total internal reflection. Either output
 * pointer may be NULL. */
void gr_fresnel_sp(double cos_i, double n1, double n2, double *r_s, double *r_p);
/* Seed eq. 5.5.2a: R = R0 + (1 - R0)(1 - cos)^5. */
double gr_fresnel_schlick(double cos_i, double r0);
/* ((n1 - n2) / (n1 + n2))^2; 0.0204 for air (1.0) to water (1.333). */
double gr_fresnel_r0(double n1, double n2);

/* Seed eq. 5.5.3: exp(-c L), with c >= 0, L >= 0; never NaN, 0 for huge c L. */
double gr_beer(double c, double L);

/* Henyey-Greenstein phase, normalized over the sphere (integral = 1):
 * (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)), cos = cosine of the scattering angle
 * (angle between the light's travel direction and the scattered direction).
 * Evaluated in a form that stays accurate for g near 1 and cos near 1. */
double gr_hg_phase(double cos_theta, double g);
/* The seed's un-normalized form (eq. 5.5.4 with beta_M = 1), as its second pass uses it:
 * (1 - g^2) / (1 + g^2 - 2 g cos)^(3/2) = 4 pi gr_hg_phase. */
double gr_hg_phase_seed(double cos_theta, double g);
/* gr_hg_phase with its constants computed once for a g, for loops that evaluate it per
 * sample (the ground truth's march): gr_hg_eval(gr_hg_make(g), c) = gr_hg_phase(c, g). */
typedef struct gr_hg {
    double a, b;   /* the denominator d = a + b (1 - s c) >= 0 (docs/optics.md) */
    double s;      /* 1 for g >= 0, -1 for g < 0: the peak's side */
    double k;      /* (1 - g^2) / (4 pi); 0 for |g| = 1 (a delta function) */
} gr_hg;
gr_hg gr_hg_make(double g);
static inline double gr_hg_eval(gr_hg h, double cos_theta)
{
    double c = cos_theta;
    if (!(c >= -1.0)) c = -1.0; /* also maps NaN */
    if (c > 1.0) c = 1.0;
    double d = h.a + h.b * (1.0 - h.s * c);
    return d > 0.0 ? h.k / (d * sqrt(d)) : 0.0;
}

#endif
