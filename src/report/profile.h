/* Radial profile of a god-ray image: mean radiance against the angle between each pixel's
 * camera ray and the direction in which the refracted sun is seen from below (-T0, with T0
 * the sun's rays refracted by the flat rest surface, seed eq. 5.5.1). Under the forward-
 * peaked phase function (HG, g ~ 0.9) most of the layer's shape is this angular falloff, so
 * one chart of both renderers shows whether the real-time technique gets it right even where
 * individual rays of light do not line up. docs/report.md. */
#ifndef GR_PROFILE_H
#define GR_PROFILE_H

#include "common/status.h"
#include "compare/structure.h"
#include "image/image.h"
#include "scene/scene.h"

/* -T0: unit direction (world) from the camera toward the refracted sun, for water index
 * s->medium.ior and flat water (Snell: sin theta_t = sin theta_i / n). */
void gr_profile_sun_view_dir(const gr_scene *s, double out[3]);

/* Angle (degrees) between the central ray of every pixel (camera convention of scene.h:
 * pixel centre (px + 0.5, py + 0.5)) and the unit direction dir, row-major into
 * angles_deg[width * height]. */
void gr_profile_angles(const gr_camera *cam, const double dir[3], float *angles_deg);

/* The beam-structure options of scene s's god rays on its camera (compare/structure.h), as
 * every comparison that computes the verdict uses them: the vanishing point of the refracted
 * sun and the de-glow by the angle to it, in rings of one pixel (fov / height degrees);
 * angles_deg (width * height floats) is filled and referenced by *so. Returns 0, *so zeroed,
 * when the beams have no finite vanishing point (parallel to the image plane): then no
 * structure is computed and the verdict is the error term alone. */
int gr_profile_structure_options(const gr_scene *s, float *angles_deg, gr_structure_options *so);

enum { GR_PROFILE_R = 0, GR_PROFILE_G, GR_PROFILE_B, GR_PROFILE_Y, GR_PROFILE_NCH };

typedef struct gr_radial_profile {
    int nbins;
    double bin_deg;                /* bin width; bin i covers [i, i + 1) bin_deg */
    double *center_deg;            /* bin centres */
    long long *count;              /* pixels in each bin */
    double *mean[GR_PROFILE_NCH];  /* mean of R, G, B and Rec. 709 Y over the bin; NaN if empty */
    /* Bound on the standard error of each bin mean when the image has stderr.R/G/B: the mean
     * of the pixels' standard errors (valid for any correlation between pixels, which share
     * sun directions and grid offsets). NULL when the image has no stderr channels. */
    double *stderr_bound[GR_PROFILE_NCH];
} gr_radial_profile;

/* Bins img (channels R, G, B as gr_metrics_pick_rgb picks them) times `scale` by angles_deg
 * (from gr_profile_angles) into nbins bins of width bin_deg. scored (may be NULL: all) skips
 * pixels with scored[p] = 0. GR_E_INPUT for nbins < 1, bin_deg <= 0 or non-finite; GR_E_NOMEM.
 * Pixels beyond the last bin are not counted. out must be freed with gr_radial_profile_free. */
gr_status gr_radial_profile_compute(const gr_image *img, const float *angles_deg, const unsigned char *scored,
                                    int nbins, double bin_deg, double scale, gr_radial_profile *out, gr_error *err);
void gr_radial_profile_free(gr_radial_profile *p); /* accepts NULL; leaves p empty */

/* A bin width for a profile reaching max_deg with about target_bins bins: a round value
 * (1, 2 or 5 times a power of ten) so that the chart's bins are easy to read. */
double gr_profile_bin_width(double max_deg, int target_bins);

#endif
