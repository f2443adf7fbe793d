/* Optics of the air-water interface and the medium: seed 000 eqs. 5.5.1-5.5.4.
 * Derivations, stability notes and the Schlick-vs-exact table: docs/optics.md. */
#include "core/optics.h"

#include <math.h>

/* exp(-708) = 3.3e-308 is still a normal double; beyond it exp() would return denormals
 * (slow on some CPUs, and a hint of garbage), so gr_beer returns exactly 0 there. */
#define GR_BEER_TAU_MAX 708.0

gr_vec3 gr_refract(gr_vec3 I, gr_vec3 N, float eta)
{
    /* Seed eq. 5.5.1, term for term as the GLSL spec writes refract(). */
    float d = gr_v3_dot(N, I);
    float k = 1.0f - eta * eta * (1.0f - d * d);
    if (k < 0.0f)
        return gr_v3(0.0f, 0.0f, 0.0f); /* total internal reflection */
    return gr_v3_sub(gr_v3_scale(I, eta), gr_v3_scale(N, eta * d + sqrtf(k)));
}

gr_dvec3 gr_refract_d(gr_dvec3 I, gr_dvec3 N, double eta)
{
    double d = gr_d3_dot(N, I);
    double k = 1.0 - eta * eta * (1.0 - d * d);
    if (k < 0.0)
        return gr_d3(0.0, 0.0, 0.0);
    return gr_d3_sub(gr_d3_scale(I, eta), gr_d3_scale(N, eta * d + sqrt(k)));
}

/* |cos_i| clamped to [0, 1]; NaN maps to 0 (grazing, R = 1) so nothing non-finite leaks. */
static double clamp_cos(double c)
{
    c = fabs(c);
    if (!(c <= 1.0))
        c = (c > 1.0) ? 1.0 : 0.0;
    return c;
}

void gr_fresnel_sp(double cos_i, double n1, double n2, double *r_s, double *r_p)
{
    double rs2 = 0.0, rp2 = 0.0;
    if (n1 > 0.0 && n2 > 0.0 && isfinite(n1) && isfinite(n2)) {
        double ci = clamp_cos(cos_i);
        double eta = n1 / n2;
        /* Snell: cos_t^2 = 1 - eta^2 sin_i^2 = (1 - eta^2) + eta^2 cos_i^2; for eta < 1 (air
         * into water) both terms are positive, so there is no cancellation. */
        double ct2 = (1.0 - eta * eta) + eta * eta * ci * ci;
        if (ct2 <= 0.0) {
            rs2 = rp2 = 1.0; /* total internal reflection (or exactly critical) */
        } else {
            double ct = sqrt(ct2);
            /* Fresnel amplitude ratios (Born & Wolf 1.5.2), s = TE, p = TM. */
            double ds = n1 * ci + n2 * ct, dp = n2 * ci + n1 * ct;
            double rs = ds > 0.0 ? (n1 * ci - n2 * ct) / ds : -1.0;
            double rp = dp > 0.0 ? (n2 * ci - n1 * ct) / dp : -1.0;
            rs2 = rs * rs;
            rp2 = rp * rp;
        }
    }
    if (r_s)
        *r_s = rs2;
    if (r_p)
        *r_p = rp2;
}

double gr_fresnel_exact(double cos_i, double n1, double n2)
{
    double rs, rp;
    gr_fresnel_sp(cos_i, n1, n2, &rs, &rp);
    return 0.5 * (rs + rp); /* unpolarized light: equal power in s and p */
}

double gr_fresnel_schlick(double cos_i, double r0)
{
    /* Seed eq. 5.5.2a (Schlick 1994). */
    double m = 1.0 - clamp_cos(cos_i);
    double m2 = m * m;
    return r0 + (1.0 - r0) * m2 * m2 * m;
}

double gr_fresnel_r0(double n1, double n2)
{
    double s = n1 + n2;
    if (!(s != 0.0) || !isfinite(s))
        return 0.0;
    double r = (n1 - n2) / s;
    return r * r;
}

double gr_beer(double c, double L)
{
    /* Seed eq. 5.5.3. tau = c L; a non-positive or undefined optical depth (0 * inf, negative
     * input) means no attenuation; an optical depth past GR_BEER_TAU_MAX gives exactly 0. */
    double tau = c * L;
    if (!(tau > 0.0))
        return 1.0;
    if (tau > GR_BEER_TAU_MAX)
        return 0.0;
    return exp(-tau);
}

gr_hg gr_hg_make(double g)
{
    /* Seed eq. 5.5.4 with beta_M = 1. The denominator 1 + g^2 - 2 g cos is rewritten as a
     * sum of non-negative terms so that it keeps full relative precision at the peak:
     *   g >= 0: (1 - g)^2 + 2 g (1 - cos)   (peak at cos = 1)
     *   g <  0: (1 + g)^2 + 2 |g| (1 + cos) (peak at cos = -1). */
    if (!(g >= -1.0))
        g = -1.0; /* also maps NaN */
    if (g > 1.0)
        g = 1.0;
    gr_hg h;
    h.s = g >= 0.0 ? 1.0 : -1.0;
    h.a = (1.0 - h.s * g) * (1.0 - h.s * g);
    h.b = 2.0 * h.s * g;
    double num = (1.0 - g) * (1.0 + g);
    /* |g| = 1: a delta function; 0 rather than 0/0. Normalized over the sphere: the integral
     * of (1 - g^2) / u^(3/2) over solid angle is 4 pi. */
    h.k = num > 0.0 ? num / (4.0 * GR_PI) : 0.0;
    return h;
}

double gr_hg_phase_seed(double cos_theta, double g)
{
    return gr_hg_phase(cos_theta, g) * (4.0 * GR_PI);
}

double gr_hg_phase(double cos_theta, double g)
{
    return gr_hg_eval(gr_hg_make(g), cos_theta);
}
