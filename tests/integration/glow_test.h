/* The featureless glow of the structure tests (header-only): the best image that depends only
 * on the angle to the refracted sun, i.e. the truth's own mean R, G, B per 0.5-degree bin of
 * that angle (report/profile), linearly interpolated between bin centres. Shared by
 * integration.structure_views and integration.tune_default. */
#ifndef GR_GLOW_TEST_H
#define GR_GLOW_TEST_H

#include <math.h>

#include "check.h"
#include "image/image.h"
#include "report/profile.h"

/* ang: the angle (degrees) of every pixel to the refracted sun (gr_profile_angles). */
static inline gr_image *glow_test_image(const gr_image *truth, const float *ang)
{
    const int w = truth->width, h = truth->height, nb = 400;
    const double bw = 0.5;
    gr_radial_profile pr;
    gr_error err;
    gr_image *g = gr_image_create(w, h, 3, NULL);
    CHECK_OK(gr_radial_profile_compute(truth, ang, NULL, nb, bw, 1.0, &pr, &err), err);
    for (size_t q = 0; q < (size_t)w * h; q++) {
        const double x = ang[q] / bw - 0.5;
        int i0 = (int)floor(x);
        double fr = x - i0;
        if (i0 < 0) i0 = 0, fr = 0.0;
        if (i0 > nb - 2) i0 = nb - 2, fr = 1.0;
        for (int c = 0; c < 3; c++) {
            double v0 = pr.mean[c][i0], v1 = pr.mean[c][i0 + 1];
            if (isnan(v0)) v0 = v1;
            if (isnan(v1)) v1 = v0;
            g->pixels[3 * q + (size_t)c] = (float)((1.0 - fr) * v0 + fr * v1);
        }
    }
    gr_radial_profile_free(&pr);
    return g;
}

#endif
