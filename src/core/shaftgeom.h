/* Placement of the real-time shaft grid (seed 000 eqs. 5.5.5-5.5.6). */
#ifndef GR_SHAFTGEOM_H
#define GR_SHAFTGEOM_H

#include "core/vec.h"

/* Seed eq. 5.5.5: P = E + T (h0 - E_y) / T_y with T = refract(I, (0,1,0), 1/ior):
 * where the ray from the viewer E along the refracted sun direction meets the flat water
 * plane y = h0. I is the unit direction in which sunlight travels (I_y < 0).
 * Also returns T through refr_dir if not NULL. */
gr_dvec3 gr_shafts_center(gr_dvec3 eye, gr_dvec3 sun_dir, double h0, double ior, gr_dvec3 *refr_dir);

/* Seed eq. 5.5.6: S = K 2 d tan(fov/2) / N, d the viewer's depth (m), fov in radians. */
double gr_shafts_spacing(double K, double depth_m, double fov_rad, int N);

#endif
