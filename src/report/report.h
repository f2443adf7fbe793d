/* The report of `godrays run`: a self-contained folder DIR with
 *   index.html          reference, real-time and false-colour difference images side by side
 *                       with colorbars, the metrics tables (raw and after the best scale fit),
 *                       the charts, timings and counters of both renderers, the scene and
 *                       every setting; inline CSS, relative links only, no JavaScript
 *   summary.png         labelled contact sheet (reference | real-time | difference + numbers)
 *   metrics.json        every number, for scripts
 *   reference.png, shafts.png (x the fitted scale, same exposure as the reference),
 *   shafts_raw.png (own exposure), diff.png, diff_signed.png, radial_profile.png,
 *   radial_profile_rgb.png, error_vs_blur.png
 * index.html links the pages of `godrays sweep`, `tune` and `pareto` in DIR/sweep, DIR/tune and
 * DIR/pareto that exist when it is written, and gives the command for each one that does not.
 * How to read it: docs/report.md. Library code: writes files, prints nothing. */
#ifndef GR_REPORT_H
#define GR_REPORT_H

#include "common/status.h"
#include "compare/flip.h"
#include "compare/metrics.h"
#include "image/image.h"
#include "scene/scene.h"

typedef struct gr_report_input {
    const gr_scene *scene;
    const gr_image *ref;            /* ground truth: R, G, B [, stderr.R/G/B] */
    const gr_metadata *ref_meta;    /* its godrays:* attributes (NULL: none) */
    const gr_image *test;           /* real-time layer: R, G, B */
    const gr_metadata *test_meta;   /* NULL: none */
    const gr_metrics *metrics;      /* gr_metrics_compute(ref, test) with fit_scale = 1 */
    /* provenance and timings; NULL strings and negative times are "unknown" */
    const char *command_line;
    int ref_cached;                 /* 1: the ground truth was read from the cache */
    const char *ref_cache_path;     /* cache file read or written (NULL: cache not used) */
    const char *ref_cache_note;     /* one line about the cache (why an entry was ignored...) */
    double ref_seconds;             /* obtaining the reference in this run (render or read) */
    double shafts_seconds;          /* real-time renderer: context, render, readback */
    double compare_seconds;
    const char *ref_exr, *test_exr; /* names (inside DIR) of EXR copies written beside; NULL: none */
    const char *scene_words;        /* the scene and its --set/--size options, shell-quoted, for the
                                       commands that make DIR/{sweep,tune,pareto} (NULL: the scene file) */
    const float *flip_map;          /* per-pixel HDR-FLIP of a * test (NULL: no FLIP picture) */
    const gr_flip_result *flip;     /* its statistics (with flip_map) */
} gr_report_input;

typedef struct gr_report_result {
    double exposure;                /* preview exposure: reference 99th percentile -> 0.8 */
    double fit_scale;               /* a used for shafts.png and the difference images */
    int charts;                     /* charts drawn (0 without PLplot) */
    int labelled;                   /* 1 if summary.png carries text (a font was found) */
    double seconds;                 /* time spent writing the report */
} gr_report_result;

/* Writes the report into dir (created if missing). Every file goes through a temporary name,
 * so a failure leaves no half-written file. GR_E_INPUT for missing inputs or images of
 * different sizes; GR_E_IO; GR_E_NOMEM. res may be NULL. */
gr_status gr_report_write(const char *dir, const gr_report_input *in, gr_report_result *res, gr_error *err);

/* Creates dir and its missing parents (GR_E_IO naming the part that failed). */
gr_status gr_report_make_dir(const char *dir, gr_error *err);

/* The summary contact sheet: the three panels (display-encoded RGB images in [0, 1], any
 * heights) side by side under their titles, and the lines of text below, on a dark background.
 * Panels wider than max_panel_w are shrunk by an integer factor (box filter), panels narrower
 * than min_panel_w enlarged by one (pixel replication) so that small renders stay legible; the
 * sheet widens for long text lines. Text is optional: without a usable font the sheet is drawn
 * unlabelled and *labelled = 0. */
gr_status gr_report_contact_sheet(const gr_image *const panels[3], const char *const titles[3],
                                  const char *const *lines, int n_lines, int min_panel_w, int max_panel_w,
                                  gr_image **out, int *labelled, gr_error *err);

/* Exposure mapping the q-th quantile (0..1) of max(R, G, B) of img (times scale) to `target`
 * (1 if that quantile is not > 0). */
double gr_report_exposure(const gr_image *img, double scale, double q, double target);

/* A display-encoded copy (sRGB transfer, [0, 1]) of channels R, G, B of img times exposure. */
gr_status gr_report_display(const gr_image *img, double exposure, gr_image **out, gr_error *err);

#endif
