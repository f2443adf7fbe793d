/* Gerstner water surface, seed 000 eqs. 5.5.7-5.5.8, in double precision so phases of
 * order 1e5 rad (points 1e5 m from the origin) keep ~1e-11 rad of accuracy.
 * Derivations (tangents, normal orientation, steepness, inversion): docs/optics.md. */
#include "core/gerstner.h"

#include <float.h>
#include <math.h>

static int wave_count(const gr_water *w)
{
    if (!w || w->n_waves < 0)
        return 0;
    return w->n_waves > GR_MAX_WAVES ? GR_MAX_WAVES : w->n_waves;
}

/* Seed eq. 5.5.7: phi_i = K_i . X0 - w_i t + phi0_i with K_i = k_i dir_i. (The seed's HLSL
 * stores w t + phi0 and subtracts it, i.e. flips the sign of phi0; we follow the equation.) */
static double wave_phase(const gr_wave *wv, double x0, double z0, double t)
{
    return wv->k * (wv->dir[0] * x0 + wv->dir[1] * z0) - wv->omega_rad_s * t + wv->phase_rad;
}

gr_dvec3 gr_gerstner_position(const gr_water *w, double x0, double z0, double t)
{
    double dx = 0.0, dz = 0.0, y = 0.0;
    int n = wave_count(w);
    for (int i = 0; i < n; i++) {
        const gr_wave *wv = &w->waves[i];
        double ph = wave_phase(wv, x0, z0, t);
        double s = sin(ph), c = cos(ph);
        /* Seed eq. 5.5.7: X = X0 - sum a K/|K| sin(phi), y = y0 + sum a cos(phi). */
        dx -= wv->amplitude_m * wv->dir[0] * s;
        dz -= wv->amplitude_m * wv->dir[1] * s;
        y += wv->amplitude_m * c;
    }
    return gr_d3(x0 + dx, (w ? w->rest_height_m : 0.0) + y, z0 + dz);
}

void gr_gerstner_frame(const gr_water *w, double x0, double z0, double t,
                       gr_dvec3 *tangent_x, gr_dvec3 *tangent_z, gr_dvec3 *normal)
{
    /* Seed eq. 5.5.8 (its K_iy is our z component): T = dP/dx0, B = dP/dz0. */
    gr_dvec3 T = gr_d3(1.0, 0.0, 0.0), B = gr_d3(0.0, 0.0, 1.0);
    int n = wave_count(w);
    for (int i = 0; i < n; i++) {
        const gr_wave *wv = &w->waves[i];
        double ph = wave_phase(wv, x0, z0, t);
        double s = sin(ph), c = cos(ph);
        double ak = wv->amplitude_m * wv->k;
        double ux = wv->dir[0], uz = wv->dir[1];
        T.x -= ak * ux * ux * c;
        T.y -= ak * ux * s;
        T.z -= ak * ux * uz * c;
        B.x -= ak * ux * uz * c;
        B.y -= ak * uz * s;
        B.z -= ak * uz * uz * c;
    }
    if (tangent_x)
        *tangent_x = T;
    if (tangent_z)
        *tangent_z = B;
    if (normal) {
        /* cross(B, T): for flat water cross(z, x) = +y. Its y component is the determinant
         * of the horizontal Jacobian, > 0 while steepness < 1 (docs/optics.md), so the
         * normal points up wherever the surface does not fold. */
        gr_dvec3 c = gr_d3_cross(B, T);
        double l = gr_d3_len(c);
        *normal = (l > 0.0 && isfinite(l)) ? gr_d3_scale(c, 1.0 / l) : gr_d3(0.0, 1.0, 0.0);
    }
}

double gr_gerstner_steepness(const gr_water *w)
{
    double s = 0.0;
    int n = wave_count(w);
    for (int i = 0; i < n; i++)
        s += fabs(w->waves[i].amplitude_m * w->waves[i].k);
    return s;
}

/* Residual r = F(X0) - X of the horizontal map F(X0) = X0 - sum a d sin(phi) and its
 * Jacobian J = I - sum a k d d^T cos(phi) (symmetric: j00, j01 = j10, j11). */
static void horizontal_residual(const gr_water *w, int n, double x0, double z0, double t,
                                double x, double z, double r[2], double *j00, double *j01,
                                double *j11)
{
    /* X0 - X first: near the solution the two are close and the difference is exact, which
     * keeps the residual accurate far from the origin. */
    double rx = x0 - x, rz = z0 - z;
    double a00 = 1.0, a01 = 0.0, a11 = 1.0;
    for (int i = 0; i < n; i++) {
        const gr_wave *wv = &w->waves[i];
        double ph = wave_phase(wv, x0, z0, t);
        double s = sin(ph), c = cos(ph);
        double a = wv->amplitude_m, akc = a * wv->k * c;
        double ux = wv->dir[0], uz = wv->dir[1];
        rx -= a * ux * s;
        rz -= a * uz * s;
        a00 -= akc * ux * ux;
        a01 -= akc * ux * uz;
        a11 -= akc * uz * uz;
    }
    r[0] = rx;
    r[1] = rz;
    if (j00) {
        *j00 = a00;
        *j01 = a01;
        *j11 = a11;
    }
}

int gr_gerstner_height_at_iter(const gr_water *w, double x, double z, double t, int max_iter,
                               double *height, double *rest_x0, double *rest_z0,
                               int *iterations)
{
    double x0 = isfinite(x) ? x : 0.0, z0 = isfinite(z) ? z : 0.0;
    int it = 0, ok = 0;
    if (w && isfinite(x) && isfinite(z) && isfinite(t)) {
        int n = wave_count(w);
        double suma = 0.0;
        for (int i = 0; i < n; i++)
            suma += fabs(w->waves[i].amplitude_m);
        /* What a double can resolve at these coordinates, plus an absolute floor. */
        double tol = 1e-10 + 8.0 * DBL_EPSILON * (fabs(x) + fabs(z) + suma);
        double r[2], j00, j01, j11;
        horizontal_residual(w, n, x0, z0, t, x, z, r, &j00, &j01, &j11);
        double rn2 = r[0] * r[0] + r[1] * r[1];
        for (;;) {
            if (!isfinite(rn2))
                break;
            if (rn2 <= tol * tol) {
                ok = 1;
                break;
            }
            if (it >= max_iter)
                break;
            it++;
            /* Newton step J d = r (2x2, Cramer). J is positive definite with eigenvalues
             * >= 1 - steepness when steepness < 1; if it is (nearly) singular (a folded
             * surface) fall back to the fixed-point step d = r. */
            double det = j00 * j11 - j01 * j01;
            double dx, dz;
            if (fabs(det) > 1e-12) {
                dx = (j11 * r[0] - j01 * r[1]) / det;
                dz = (j00 * r[1] - j01 * r[0]) / det;
            } else {
                dx = r[0];
                dz = r[1];
            }
            /* Backtracking (Armijo) on |r|^2: the Newton direction always decreases it,
             * d/dlambda |r|^2 / 2 = -|r|^2, which makes the iteration globally convergent. */
            double lambda = 1.0, nx = x0, nz = z0, nr[2] = {r[0], r[1]};
            double nj00 = j00, nj01 = j01, nj11 = j11, nrn2 = rn2;
            int accepted = 0;
            for (int ls = 0; ls < 40; ls++) {
                nx = x0 - lambda * dx;
                nz = z0 - lambda * dz;
                horizontal_residual(w, n, nx, nz, t, x, z, nr, &nj00, &nj01, &nj11);
                nrn2 = nr[0] * nr[0] + nr[1] * nr[1];
                if (nrn2 <= (1.0 - 1e-4 * lambda) * rn2) {
                    accepted = 1;
                    break;
                }
                lambda *= 0.5;
            }
            if (!accepted || !isfinite(nx) || !isfinite(nz))
                break; /* no progress possible (rounding floor or a fold): give up */
            x0 = nx;
            z0 = nz;
            r[0] = nr[0];
            r[1] = nr[1];
            j00 = nj00;
            j01 = nj01;
            j11 = nj11;
            rn2 = nrn2;
        }
    }
    if (rest_x0)
        *rest_x0 = x0;
    if (rest_z0)
        *rest_z0 = z0;
    if (height)
        *height = w ? gr_gerstner_position(w, x0, z0, isfinite(t) ? t : 0.0).y : 0.0;
    if (iterations)
        *iterations = it;
    return ok ? 0 : -1;
}

int gr_gerstner_height_at(const gr_water *w, double x, double z, double t,
                          double *height, double *rest_x0, double *rest_z0)
{
    return gr_gerstner_height_at_iter(w, x, z, t, 64, height, rest_x0, rest_z0, NULL);
}
