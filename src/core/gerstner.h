/* Gerstner water surface (seed 000 eqs. 5.5.7-5.5.8), evaluated in double precision so
 * it stays exact far from the origin. See docs/optics.md for the derivation. */
#ifndef GR_GERSTNER_H
#define GR_GERSTNER_H

#include "core/vec.h"
#include "scene/scene.h"

/* Seed eq. 5.5.7: world position at time t of the surface point whose rest position is
 * (x0, rest_height, z0). phase_i = k_i dir_i . (x0, z0) - w_i t + phi0_i;
 * X = X0 - sum a_i dir_i sin(phase_i); y = h0 + sum a_i cos(phase_i). */
gr_dvec3 gr_gerstner_position(const gr_water *w, double x0, double z0, double t);

/* Seed eq. 5.5.8: tangents dP/dx0 (T) and dP/dz0 (B), and the unit upward normal
 * normalize(cross(B, T)). Any output pointer may be NULL. */
void gr_gerstner_frame(const gr_water *w, double x0, double z0, double t,
                       gr_dvec3 *tangent_x, gr_dvec3 *tangent_z, gr_dvec3 *normal);

/* Steepness sum_i a_i k_i; the surface loops (the rest-to-world map folds) iff >= 1. */
double gr_gerstner_steepness(const gr_water *w);

/* Height of the surface above the world point (x, z) at time t: finds the rest point
 * (x0, z0) whose displaced horizontal position is (x, z) (a contraction when steepness < 1)
 * and returns its height. Returns 0 on success, -1 if it did not converge.
 * rest_x0 / rest_z0 may be NULL. */
int gr_gerstner_height_at(const gr_water *w, double x, double z, double t,
                          double *height, double *rest_x0, double *rest_z0);

/* gr_gerstner_height_at with an explicit cap on damped-Newton iterations (height_at uses
 * 64) and the number of iterations taken (may be NULL). Returns 0 when the rest point maps
 * back to (x, z) within 1e-10 m + 8 eps (|x| + |z| + sum a_i), -1 otherwise (cap reached,
 * no progress, non-finite input, NULL water); on -1 the outputs are finite but not a
 * solution. */
int gr_gerstner_height_at_iter(const gr_water *w, double x, double z, double t, int max_iter,
                               double *height, double *rest_x0, double *rest_z0,
                               int *iterations);

#endif
