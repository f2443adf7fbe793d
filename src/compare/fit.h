/* The test image's scale fit: the factor(s) that bring a real-time image (whose intensity unit is
 * arbitrary) to the reference's level before comparing. One least-squares factor for R, G and B
 * (`scale`, the default), one per channel (`rgb`: a tint is fitted too) or none. Derivations:
 * docs/metrics.md, "Scale fits". Pure functions on images, no I/O. */
#ifndef GR_FIT_H
#define GR_FIT_H

#include "common/status.h"
#include "image/image.h"

/* The values are those of gr_metrics_options.fit_scale (0 none, 1 one scale): kept so that a
 * caller that set fit_scale = 1 before per-channel fits existed keeps its meaning. */
typedef enum gr_fit_mode { GR_FIT_NONE = 0, GR_FIT_SCALE = 1, GR_FIT_RGB = 2 } gr_fit_mode;

/* "none", "scale", "rgb"; NULL for anything else. */
const char *gr_fit_mode_name(gr_fit_mode m);

/* "none", "scale" or "rgb" into *m; GR_E_USAGE naming flag and the three words otherwise. */
gr_status gr_fit_mode_parse(const char *flag, const char *s, gr_fit_mode *m, gr_error *err);

/* A fit option at argv[*i], as every command that fits reads it: `--fit MODE` (MODE: none, scale
 * or rgb; consumed), a bare `--fit` (scale: what it meant before there were modes), `--fit=MODE`,
 * and the older spellings `--fit-scale` (scale) and `--no-fit` (none). Returns 1 when it was one
 * (*m set, *i on its last word), 0 when argv[*i] is not a fit option, -1 for `--fit=` with
 * another word (GR_E_USAGE in err). */
int gr_fit_mode_option(int argc, char *const *argv, int *i, gr_fit_mode *m, gr_error *err);

/* The least-squares factors over the scored pixels (scored: width * height, 1 = scored; NULL:
 * all) between ref's channels rr[0..2] and test's channels tr[0..2] (the same index three times
 * for a grey image). GR_FIT_SCALE: a[0] = a[1] = a[2] = <t, r> / <t, t> pooled over the three
 * channels; GR_FIT_RGB: a[c] = <t_c, r_c> / <t_c, t_c> per channel; GR_FIT_NONE: 1. A factor
 * whose <t, t> is 0 (the test black there) is 1. Returns how many of the three channels have
 * a defined factor: 3, or 0 for a black test (GR_FIT_SCALE), images of another size or
 * GR_FIT_NONE; GR_FIT_RGB may give 1 or 2 (a channel the test leaves black). */
int gr_fit_scales(const gr_image *ref, const gr_image *test, const unsigned char *scored, const int rr[3],
                  const int tr[3], gr_fit_mode mode, double a[3]);

/* One number for per-channel factors a[3] on a test whose scored channel means are mean_t[3]:
 * the factor on the test's mean luminance, sum w_c a_c m_c / sum w_c m_c (Rec. 709 w); the
 * plain mean of a when the test's mean luminance is 0. What a consumer that can only scale
 * (a preview's exposure, a gain setting of one number) uses for the per-channel fit. */
double gr_fit_luminance_scale(const double a[3], const double mean_t[3]);

#endif
