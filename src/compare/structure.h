/* Metrics of the structure of the god-ray layer: where the beams are, how many, how sharp.
 * In perspective the beams (lines parallel to the refracted sun direction) converge toward a
 * vanishing point, the screen position of that direction; around it a beam is a ray of the
 * image and a beam pattern is a function of the angle. Three measures, each per image and
 * compared with the truth's (derivations: docs/metrics.md "Beam structure"):
 *
 *  - all on the de-glowed luminance D = Y / R(q): Rec. 709 luminance over its own mean on the
 *    ring of radial coordinate q (the distance to the vanishing point, or the angle to the
 *    sun), interpolated, so that any function of q alone (a glow around the sun) becomes flat
 *    and only the structure beside it remains;
 *  - local band-pass contrast C = (G_f * D - G_c * D) / (G_c * D + eps), a difference of
 *    Gaussians over the local mean (Peli's band-limited contrast);
 *    its RMS over the image is the *streak contrast*, and the Pearson correlation of the
 *    test's C with the truth's is the *band-pass correlation* (1: beams in the same places);
 *  - the *angular power spectrum* of the relative luminance fluctuation around the vanishing
 *    point, per annulus, at integer angular frequencies m (cycles per full turn: beams per
 *    360 degrees), compared as a log-spectral distance.
 *
 * Every measure is invariant to a scale factor on the image (the shafts' unit is arbitrary). */
#ifndef GR_STRUCTURE_H
#define GR_STRUCTURE_H

#include "common/status.h"
#include "image/image.h"
#include "scene/scene.h"

#define GR_STRUCT_MAX_ANNULI 16
#define GR_STRUCT_MAX_M 256

/* Zero-initialized fields ask for the defaults. Image coordinates: x right, y down, pixel
 * (px, py) covers [px, px + 1) x [py, py + 1) (its centre is (px + 0.5, py + 0.5)). */
typedef struct gr_structure_options {
    double vp_x, vp_y;           /* vanishing point (may lie outside the image) */
    double sigma_fine_px;        /* 0: height / 180 (1 px at 180 rows) */
    double sigma_coarse_px;      /* 0: 4 sigma_fine */
    double eps_rel;              /* contrast denominator floor, times mean(G_c * Y); 0: 0.01 */
    int n_annuli;                /* 0: 4 (at most GR_STRUCT_MAX_ANNULI) */
    double r_min_px, r_max_px;   /* annuli span; 0: the larger of 0.1 height and the distance to
                                    the image (vanishing point outside), and the farthest corner */
    int n_theta;                 /* angular samples per turn; 0: 1024 */
    int m_max;                   /* highest angular frequency; 0: 256 (at most GR_STRUCT_MAX_M) */
    int m_min;                   /* lowest angular frequency in the summaries; 0: 2 */
    const unsigned char *scored; /* per pixel, may be NULL (all); unscored pixels are left out of
                                    every sum, blur and ring */
    const float *radial;         /* per pixel, may be NULL: the radial coordinate whose rings the
                                    de-glow divides out; NULL: the distance (px) to the vanishing
                                    point. Pass the angle to the sun (report/profile's
                                    gr_profile_angles) to make any function of it exactly flat. */
    double radial_bin;           /* ring width in radial's unit (required with radial) */
} gr_structure_options;

typedef struct gr_structure_image {
    double mean_y;               /* mean luminance over scored pixels */
    double streak_contrast;      /* RMS of C over scored pixels */
    int n_annuli, m_max, m_min;
    double r0[GR_STRUCT_MAX_ANNULI], r1[GR_STRUCT_MAX_ANNULI]; /* annulus radii, px */
    double arc_deg[GR_STRUCT_MAX_ANNULI]; /* angular extent analysed; 0: annulus unusable */
    /* P[a][m]: 2 |sum_j w_j f_j e^{-i m theta_j}|^2 / (sum_j w_j)^2 for m >= 1 (so a fluctuation
     * A cos(m theta + phi) gives A^2 / 2 at m); P[a][0] = 0. */
    double spectrum[GR_STRUCT_MAX_ANNULI][GR_STRUCT_MAX_M + 1];
    double angular_power;        /* mean over usable annuli of sum_{m_min..m_max} P */
    int peak_m;                  /* m of the largest mean-over-annuli P in [m_min, m_max] */
    int n_usable;                /* usable annuli */
} gr_structure_image;

typedef struct gr_structure_compare {
    gr_structure_image ref, test;
    double bandpass_corr;        /* Pearson correlation of C_test and C_ref (0 if either is flat) */
    double contrast_ratio;       /* test / ref streak contrast (0 when ref's is 0) */
    double contrast_log_err;     /* |ln contrast_ratio| (large finite value when a side is 0) */
    double spectrum_log_dist;    /* RMS over shared usable annuli and m_min..m_max of
                                    log10((P_t + f) / (P_r + f)), f = 0.01 mean P_r: 0 same shape
                                    and level, 2 = a flat test against a structured truth */
    double power_ratio;          /* test / ref angular power */
} gr_structure_compare;

/* Where the lines of direction dir (either sense; world) converge on cam's image, in image
 * coordinates. GR_E_INPUT when dir is (nearly) perpendicular to the view direction: the
 * lines are then parallel on the image and have no finite vanishing point. */
gr_status gr_structure_vanishing_point(const gr_camera *cam, const double dir[3], double *x, double *y,
                                       gr_error *err);
/* The vanishing point of the god rays of scene s (the refracted sun direction, seed eq. 5.5.1
 * at the rest surface, as gr_profile_sun_view_dir), on s's camera scaled to width x height. */
gr_status gr_structure_scene_vp(const gr_scene *s, int width, int height, double *x, double *y, gr_error *err);

/* The relative angular fluctuation of img's de-glowed, finely smoothed luminance S around the
 * vanishing point on the annulus [r0, r1] (radii in 1-px steps), at theta_j = 2 pi j / n_theta:
 * f[j] = mean over the radii sampling inside the image (and scored pixels) of S - 1, valid[j] = 1
 * where at least half the radii do (f[j] = 0 elsewhere). f and valid have n_theta entries (after
 * defaults). For following beams over time (compare/temporal). */
gr_status gr_structure_angular_profile(const gr_image *img, const gr_structure_options *opt, double r0, double r1,
                                       double *f, unsigned char *valid, gr_error *err);

/* The measures of one image. contrast (may be NULL) receives the field C, width * height. */
gr_status gr_structure_image_compute(const gr_image *img, const gr_structure_options *opt, gr_structure_image *out,
                                     float *contrast, gr_error *err);

/* Both images' measures and their comparison (same size). */
gr_status gr_structure_compare_images(const gr_image *ref, const gr_image *test, const gr_structure_options *opt,
                                      gr_structure_compare *out, gr_error *err);

/* The reference's half of a comparison, kept to compare many test images with one reference
 * under the same options (a search: the same cases again and again). compare_images is
 * create + compare_ref + destroy, so both give the same numbers to the bit. The options'
 * arrays (scored, radial) are copied. */
typedef struct gr_structure_ref gr_structure_ref;
gr_status gr_structure_ref_create(const gr_image *ref, const gr_structure_options *opt, gr_structure_ref **out,
                                  gr_error *err);
void gr_structure_ref_destroy(gr_structure_ref *r); /* accepts NULL */
/* 1 when r was made from this reference (its R, G, B) with these options (values and arrays). */
int gr_structure_ref_matches(const gr_structure_ref *r, const gr_image *ref, const gr_structure_options *opt);
gr_status gr_structure_compare_ref(const gr_structure_ref *r, const gr_image *test, gr_structure_compare *out,
                                   gr_error *err);

#endif
