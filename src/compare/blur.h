/* Separable Gaussian blur as normalized convolution, for the comparison metrics.
 *
 * out(p) = SUM_q G(p - q) w(q) x(q) / SUM_q G(p - q) w(q), over the pixels q inside the image,
 * with G the product of two 1-D Gaussians truncated at `radius` pixels. With w = 1 this is the
 * truncated kernel renormalized at the image edges; with a 0/1 weight (a mask) unscored pixels
 * neither contribute nor dilute the average. Because G is separable and the image is a
 * rectangle, two 1-D passes give exactly the 2-D result (docs/metrics.md). */
#ifndef GR_BLUR_H
#define GR_BLUR_H

#include <stddef.h>
#include "common/status.h"
#include "image/image.h"

/* Radius the metrics use for a blur of standard deviation sigma (px): ceil(3 sigma), at least 1. */
int gr_blur_radius(double sigma);

/* Fills w[0 .. 2 radius] with exp(-i^2 / (2 sigma^2)), i = -radius..radius, normalized to sum 1.
 * GR_E_INPUT for sigma <= 0, a non-finite sigma or radius < 0. */
gr_status gr_gaussian_kernel(double sigma, int radius, double *w, gr_error *err);

/* Normalized convolution of nch planar double fields src[c][width * height] (row-major, top
 * row first) with weight (NULL: all 1; weights must be >= 0). Writes dst[c] (may not alias
 * src) and, if dst_weight is not NULL, the blurred weight SUM G w (the kernel's total over
 * in-image pixels is normalized to 1 only in the interior). Where the blurred weight is 0,
 * dst is 0. Sums in double. GR_E_INPUT for bad sizes or sigma, GR_E_NOMEM. */
gr_status gr_blur_fields(const double *const *src, int nch, const double *weight, int width, int height,
                         double sigma, int radius, double *const *dst, double *dst_weight, gr_error *err);

/* Convenience for images: a blurred copy of every channel of img (w = 1, radius ceil(3 sigma)),
 * for the report's pictures. *out must be destroyed by the caller. */
gr_status gr_blur_image(const gr_image *img, double sigma, gr_image **out, gr_error *err);

#endif
