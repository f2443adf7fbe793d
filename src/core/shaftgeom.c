/* Placement of the real-time shaft grid: seed 000 eqs. 5.5.5-5.5.6. */
#include "core/shaftgeom.h"

#include <math.h>

#include "core/optics.h"

gr_dvec3 gr_shafts_center(gr_dvec3 eye, gr_dvec3 sun_dir, double h0, double ior, gr_dvec3 *refr_dir)
{
    /* Seed eq. 5.5.5b: T = refract(I, (0,1,0), 1/ior). I is normalized here so a caller's
     * slightly denormalized direction cannot bias T. */
    gr_dvec3 I = gr_d3_norm(sun_dir);
    gr_dvec3 T = gr_refract_d(I, gr_d3(0.0, 1.0, 0.0), 1.0 / ior);
    /* For valid input (I_y < 0, ior >= 1) T_y <= -sqrt(1 - 1/ior^2) < 0 even for a sun on
     * the horizon, so the division below is safe. Anything else (sun below the horizon,
     * ior < 1 with TIR, NaN) falls back to straight down, so P is directly above E. */
    if (!(I.y <= 0.0) || gr_d3_dot(I, I) == 0.0 || !(T.y < -1e-9) || !isfinite(T.x) ||
        !isfinite(T.z))
        T = gr_d3(0.0, -1.0, 0.0);
    if (refr_dir)
        *refr_dir = T;
    /* Seed eq. 5.5.5a: P = E + T (h0 - E_y) / T_y, the point of y = h0 on the line E + s T. */
    return gr_d3_madd(eye, T, (h0 - eye.y) / T.y);
}

double gr_shafts_spacing(double K, double depth_m, double fov_rad, int N)
{
    /* Seed eq. 5.5.6: S = K 2 d tan(fov/2) / N. A viewer above the water (d < 0), a
     * degenerate grid or a field of view outside (0, pi) gives 0 rather than a negative or
     * infinite spacing; the caller decides what a zero spacing means. */
    if (N <= 0 || !(depth_m > 0.0) || !(fov_rad > 0.0 && fov_rad < GR_PI) || !isfinite(K) ||
        !isfinite(depth_m))
        return 0.0;
    return K * 2.0 * depth_m * tan(0.5 * fov_rad) / (double)N;
}
