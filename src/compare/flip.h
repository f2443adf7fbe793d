/* FLIP: the perceptual difference of two images seen alternately (Andersson, Nilsson,
 * Akenine-Moller, Oskarsson, Astrom, Fairchild, "FLIP: A Difference Evaluator for Alternating
 * Images", HPG 2020) and its high-dynamic-range extension (Andersson, Nilsson, Shirley,
 * Akenine-Moller, "Visualizing Errors in Rendered High Dynamic Range Images", Eurographics
 * 2021 short papers). Implemented from the papers; derivation and constants in
 * docs/metrics.md ("FLIP"). Per-pixel values lie in [0, 1]: 0 identical, 1 maximal.
 *
 * Inputs are linear RGB images (channels as gr_metrics_pick_rgb picks them). LDR-FLIP clamps
 * them to [0, 1] (the sRGB display range, decoded to linear); HDR-FLIP tone maps a series of
 * exposures of both images and keeps the per-pixel maximum of LDR-FLIP over them. */
#ifndef GR_FLIP_H
#define GR_FLIP_H

#include "common/status.h"
#include "image/image.h"

typedef enum gr_flip_mode { GR_FLIP_LDR = 0, GR_FLIP_HDR = 1 } gr_flip_mode;
typedef enum gr_flip_tonemapper {
    GR_FLIP_TM_ACES = 0,     /* Narkowicz's fit of ACES with a 0.6 pre-exposure (the paper's default) */
    GR_FLIP_TM_REINHARD = 1  /* colour / (1 + Y): x / (1 + x) on luminance */
} gr_flip_tonemapper;

/* The default observer: 0.7 m from a 0.7 m wide 3840-pixel display, in pixels per degree:
 * 0.7 m * (3840 / 0.7 m) * pi / 180. */
#define GR_FLIP_DEFAULT_PPD (3840.0 * 3.14159265358979323846 / 180.0)

/* The reference's half of FLIP, prepared once for many tests against it (gr_flip_reference_create). */
typedef struct gr_flip_reference gr_flip_reference;

/* Zero-initialized = defaults: LDR, 67.02 ppd, ACES, exposures from the reference. */
typedef struct gr_flip_options {
    gr_flip_mode mode;
    double ppd;                    /* pixels per degree of visual angle; 0: GR_FLIP_DEFAULT_PPD */
    gr_flip_tonemapper tonemapper; /* HDR only */
    int exposures_given;           /* HDR: 1 = use start/stop/count below; 0 = from the reference */
    double start_exposure, stop_exposure; /* log2 factors, start <= stop */
    int n_exposures;               /* >= 1 (1: the start exposure only) */
    double test_scale;             /* the test is multiplied by this first; 0: 1 */
    const unsigned char *scored;   /* per pixel, may be NULL: the pooled statistics use only
                                      pixels with scored[p] != 0 (filters still see every pixel) */
    const gr_flip_reference *reference; /* may be NULL: the reference's half, prepared from the same
                                           image with the same mode, ppd, tone mapper and exposures
                                           (else GR_E_INPUT); the same numbers, faster */
} gr_flip_options;

typedef struct gr_flip_result {
    gr_flip_mode mode;
    double ppd;
    gr_flip_tonemapper tonemapper;
    double start_exposure, stop_exposure; /* HDR: what was used */
    int n_exposures;                      /* HDR: what was used; 0 for LDR */
    long long n_pooled;                   /* pixels in the statistics */
    double mean, min, max;                /* of the per-pixel FLIP values over pooled pixels */
    double median, q1, q3;                /* plain (unweighted) quantiles, linear interpolation */
} gr_flip_result;

/* FLIP between ref and test (same size). map (may be NULL) receives width * height per-pixel
 * values, row-major, top row first. GR_E_INPUT for NULL or differently sized images, non-finite
 * samples, a ppd that is not > 0 and finite, bad exposures; GR_E_NOMEM. */
gr_status gr_flip_compute(const gr_image *ref, const gr_image *test, const gr_flip_options *opt, float *map,
                          gr_flip_result *res, gr_error *err);

/* The exposure range HDR-FLIP derives from a reference (HDR-FLIP paper, section 3): with
 * x_0.85 the input that the tone mapper maps to 0.85, start = log2(x_0.85 / Y_max),
 * stop = log2(x_0.85 / Y_median) (Rec. 709 luminance), count = max(2, ceil(stop - start)). */
gr_status gr_flip_exposures(const gr_image *ref, gr_flip_tonemapper tm, double *start, double *stop, int *count,
                            gr_error *err);

/* gr_flip_compute, except that a reference that HDR-FLIP derives no exposure range from (all
 * zero, or a zero median: a black ground truth) is not an error: *undefined = 1, res's
 * statistics NaN (n_pooled 0), map zeros, the reason in why (may be NULL). */
gr_status gr_flip_compute_defined(const gr_image *ref, const gr_image *test, const gr_flip_options *opt, float *map,
                                  gr_flip_result *res, int *undefined, char *why, size_t why_n, gr_error *err);

/* Prepares ref's half of FLIP for opt's mode, ppd, tone mapper and exposures (test_scale and
 * scored do not matter): per exposure, per pixel, the CSF-filtered colour as Hunt-adjusted Lab
 * and the feature magnitudes (40 bytes), the exposures on up to `threads` threads (common/
 * parallel.h; 1 inside another parallel job; the same numbers for any count). Every FLIP against ref with
 * these settings and .reference set then computes only the test's half: the same numbers.
 * When that would take more than max_bytes, the result holds no planes (a FLIP given it
 * computes both halves, as without; it keeps the resolved exposure range, and a kept one is
 * not remade at every call). An HDR reference with no exposure range (a black truth) is
 * prepared as such (gr_flip_compute_defined says undefined at once). ref must outlive the
 * result. GR_E_INPUT as gr_flip_compute; GR_E_NOMEM. */
gr_status gr_flip_reference_create(const gr_image *ref, const gr_flip_options *opt, size_t max_bytes, int threads,
                                   gr_flip_reference **out, gr_error *err);
void gr_flip_reference_destroy(gr_flip_reference *r);
/* 1 if r was prepared from ref with opt's mode, ppd, tone mapper and exposures (given, or
 * derived from ref); 0 otherwise or for NULL. */
int gr_flip_reference_matches(const gr_flip_reference *r, const gr_image *ref, const gr_flip_options *opt);
size_t gr_flip_reference_bytes(const gr_flip_reference *r); /* what it holds (0 for NULL) */
int gr_flip_reference_has_planes(const gr_flip_reference *r); /* 0: over its bound, or NULL */

/* The heat map: per-pixel FLIP values (clamped to [0, 1]) through the magma colour map, as a
 * new 3-channel display-encoded image (write it with gr_oiio_write). */
gr_status gr_flip_heatmap(const float *map, int width, int height, gr_image **out, gr_error *err);

const char *gr_flip_mode_name(gr_flip_mode m);             /* "ldr", "hdr" */
const char *gr_flip_tonemapper_name(gr_flip_tonemapper t); /* "aces", "reinhard" */

#endif
