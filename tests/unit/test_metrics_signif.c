/* Significance counts of gr_metrics_compute with a reference that carries stderr.* and bias.*
 * channels (docs/metrics.md): a sample is not significant when |t - r| <= z stderr + |bias|,
 * z = Student's t975 with stderr_dof degrees of freedom (2.3646 for 7, the default 8
 * batches), z = 2 when the degrees of freedom are unknown. Differences are placed by hand at
 * known multiples of the stderr, so the expected counts are exact. */
#include "check.h"

#include <math.h>
#include "compare/metrics.h"

int main(void)
{
    static const char *const rn[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "bias.R", "bias.G", "bias.B"};
    static const char *const tn[] = {"R", "G", "B"};
    /* 5 pixels, differences of 1.5, 2.2, 2.5, 3.0 and 4.0 stderr in every channel; stderr 0.01 */
    const double k[5] = {1.5, 2.2, 2.5, 3.0, 4.0};
    for (int with_bias = 0; with_bias < 2; with_bias++) {
        gr_image *ref = gr_image_create(5, 1, with_bias ? 9 : 6, rn), *test = gr_image_create(5, 1, 3, tn);
        CHECK(ref && test);
        if (!ref || !test) return 1;
        for (int x = 0; x < 5; x++)
            for (int c = 0; c < 3; c++) {
                float *rp = ref->pixels + (size_t)x * ref->nchannels, *tp = test->pixels + (size_t)x * 3;
                rp[c] = 1.0f;
                rp[3 + c] = 0.01f;
                if (with_bias) rp[6 + c] = (x == 3) ? -0.007f : 0.0f; /* pixel 3: 3.0 se = 2.365 se + 0.7 se */
                tp[c] = (float)(1.0 + 0.01 * k[x]);
            }
        gr_error err = {GR_OK, ""};
        gr_metrics m;
        gr_metrics_options o = {0};
        o.skip_ssim = o.skip_blur = 1;
        CHECK_OK(gr_metrics_compute(ref, test, &o, &m, &err), err);
        /* unknown dof: z = 2, only 1.5 se is explained (bias adds 0.7 se to pixel 3: 2.7 < 3.0) */
        CHECK(m.raw.ch[GR_MCH_R].n_not_significant == 1);
        CHECK_NEAR(m.stderr_z, 2.0, 1e-12);
        o.stderr_dof = 7;
        CHECK_OK(gr_metrics_compute(ref, test, &o, &m, &err), err);
        CHECK_NEAR(m.stderr_z, 2.3646243, 1e-6);
        /* Student t (7 dof): 1.5 and 2.2 se explained; with the bias channel also 3.0 se */
        long long want = with_bias ? 3 : 2;
        CHECK_MSG(m.raw.ch[GR_MCH_R].n_not_significant == want, "R: %lld not significant, want %lld",
                  m.raw.ch[GR_MCH_R].n_not_significant, want);
        CHECK(m.raw.ch[GR_MCH_RGB].n_not_significant == 3 * want);
        CHECK(m.raw.ch[GR_MCH_Y].n_not_significant == want);
        CHECK(m.have_bias == with_bias);
        gr_image_destroy(ref);
        gr_image_destroy(test);
    }
    CHECK_DONE();
}
