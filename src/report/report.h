/* The report of `godrays run`: a self-contained folder DIR comparing every real-time technique
 * of the run against one ground truth:
 *   index.html          the LEADERBOARD (report/leaderboard.h: one row per technique and per
 *                       baseline, ranked by the verdict, with its components, the equivalent
 *                       blur, GPU and wall time; a row per failed technique), then per
 *                       technique its images beside the reference with false-colour
 *                       differences and colorbars, metrics tables (raw and after the best
 *                       scale fit), charts, timings and counters; the scene and every setting;
 *                       inline CSS, relative links only; one script: the interactive
 *                       comparison (report/viewer.h), its images inside the page
 *   summary.png         labelled contact sheet, one row per technique (reference | technique
 *                       x a | difference + numbers)
 *   metrics.json        every number, one entry per technique (docs/report.md)
 *   reference.png, radial_profile.png (every technique), and per technique T (files named
 *   after T, "rt_T" where T is one of the report's own names): T.png (x the fitted scale,
 *   same exposure as the reference), T_raw.png (own exposure), T_diff.png,
 *   T_diff_signed.png, T_radial_profile_rgb.png, T_error_vs_blur.png, T_flip.png (report/viewer.h)
 *   With --frames: DIR/sequence/ (report/sequence.h), linked from index.html (sequence_href).
 * index.html links the pages of `godrays sweep`, `tune` and `pareto` in DIR/sweep, DIR/tune and
 * DIR/pareto that exist when it is written, and gives the command for each one that does not.
 * How to read it: docs/report.md. Library code: writes files, prints nothing. */
#ifndef GR_REPORT_H
#define GR_REPORT_H

#include "common/status.h"
#include "compare/baseline.h"
#include "compare/metrics.h"
#include "image/image.h"
#include "scene/scene.h"

#define GR_REPORT_MAX_TECHNIQUES 32

/* One real-time technique's result. */
typedef struct gr_report_technique {
    const char *name;               /* the technique's name ([a-z][a-z0-9_]*) */
    const char *description;        /* one line (NULL: none) */
    const gr_image *test;           /* its god-ray layer: R, G, B */
    const gr_metadata *meta;        /* its EXR metadata: godrays:gpu_ms, godrays:wall_ms, ... (NULL: none) */
    const gr_metrics *metrics;      /* gr_metrics_compute(ref, test) with fit_scale = 1 */
    double seconds;                 /* time in this run: instance, render, readback (< 0: unknown) */
    const char *exr;                /* name (inside DIR) of its EXR copy written beside; NULL: none */
    const gr_image *targets;        /* its intermediate render targets side by side (RGBA float,
                                       gr_technique_read_target; `run --save-targets`), shown as a
                                       strip in its section; NULL: none (the default) */
} gr_report_technique;

/* A technique that has no image to score: it failed to build, to render, or rendered black or
 * NaN. A row of its own on the leaderboard, with the reason. */
typedef struct gr_report_failure {
    const char *name;               /* the technique's name */
    const char *description;        /* one line (NULL: none) */
    const char *reason;             /* one line: why it failed */
} gr_report_failure;

typedef struct gr_report_input {
    const gr_scene *scene;
    const gr_image *ref;            /* ground truth: R, G, B [, stderr.R/G/B] */
    const gr_metadata *ref_meta;    /* its godrays:* attributes (NULL: none) */
    int n_techniques;               /* 0..GR_REPORT_MAX_TECHNIQUES (0 only with a failure) */
    const gr_report_technique *techniques;
    int n_failed;                   /* techniques that failed, rows of their own (0..MAX) */
    const gr_report_failure *failed;
    const gr_baselines *baselines;  /* scored like the techniques (compare/baseline.h); NULL: no
                                       baseline rows, no equivalent blur */
    const gr_flip_reference *flip_ref; /* may be NULL: ref's half of HDR-FLIP (default options),
                                       prepared by the caller (run's, shared with its baselines);
                                       else the report prepares its own */
    /* provenance and timings; NULL strings and negative times are "unknown" */
    const char *command_line;
    int ref_cached;                 /* 1: the ground truth was read from the cache */
    const char *ref_cache_path;     /* cache file read or written (NULL: cache not used) */
    const char *ref_cache_note;     /* one line about the cache (why an entry was ignored...) */
    double ref_seconds;             /* obtaining the reference in this run (render or read) */
    double compare_seconds;         /* all techniques' metrics */
    const char *ref_exr;            /* name (inside DIR) of the reference's EXR copy; NULL: none */
    const char *scene_words;        /* the scene and its --set/--size options, shell-quoted, for the
                                       commands that make DIR/{sweep,tune,pareto} (NULL: the scene file) */
    const char *sequence_json;      /* godrays run --frames: the sequence (report/sequence.h) as JSON text,
                                       carried by metrics.json as "sequence" (NULL: none) */
    const char *sequence_href;      /* its page inside DIR, linked from index.html (NULL: none) */
} gr_report_input;

typedef struct gr_report_result {
    double exposure;                /* preview exposure: reference 99th percentile -> 0.8 */
    double fit_scale[GR_REPORT_MAX_TECHNIQUES]; /* per technique: a used for T.png and its differences */
    int order[GR_REPORT_MAX_TECHNIQUES]; /* leaderboard: technique indices, best first */
    double flip[GR_REPORT_MAX_TECHNIQUES]; /* per technique: mean HDR-FLIP of a x test (its map) */
    int charts;                     /* charts drawn (0 without PLplot) */
    int labelled;                   /* 1 if summary.png carries text (a font was found) */
    double seconds;                 /* time spent writing the report */
} gr_report_result;

/* Writes the report into dir (created if missing). Every file goes through a temporary name,
 * so a failure leaves no half-written file. GR_E_INPUT for missing inputs, no technique,
 * images of different sizes or a repeated technique name; GR_E_IO; GR_E_NOMEM. res may be
 * NULL. The leaderboard ranks by the verdict after the scale fit (compare/registry.h; lower
 * first; ties: the input order), among the baselines; failed techniques are rows at its end
 * (report/leaderboard.h). */
gr_status gr_report_write(const char *dir, const gr_report_input *in, gr_report_result *res, gr_error *err);

/* 1 when the ground truth is zero everywhere scored (its luminance mean over the scored pixels,
 * from the first baseline's or technique's metrics, is 0; the truth is >= 0): every metric then
 * says nothing, which the page and `run`'s terminal both say. */
int gr_report_truth_zero(const gr_report_input *in);

/* 1 when the ground truth's surface tessellation bias (its metadata godrays:bias_surface_rel_est,
 * order 2) is above 1 % of the image mean, as `godrays reference` warns (docs/reference.md 4,
 * "Views with a wide lit region"); msg (if not NULL) gets one line saying so, with the
 * measured-order and 95th-percentile block figures and the remedy, for the page and `run`'s
 * terminal. */
int gr_report_truth_coarse(const gr_report_input *in, char *msg, size_t n);

/* Technique name's file stem in the report: its name, or "rt_NAME" for one of the report's own
 * names (reference, summary, metrics, index, radial_profile). */
void gr_report_tech_stem(const char *name, char *buf, size_t n);

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

/* The leaderboard order of techniques[0..n): indices sorted by the verdict after the scale fit
 * (compare/registry.h GR_METRIC_VERDICT), lower first, non-finite last, ties in input order. */
void gr_report_rank(const gr_report_technique *techniques, int n, int *order);

/* Exposure mapping the q-th quantile (0..1) of max(R, G, B) of img (times scale) to `target`
 * (1 if that quantile is not > 0). */
double gr_report_exposure(const gr_image *img, double scale, double q, double target);

/* A display-encoded copy (sRGB transfer, [0, 1]) of channels R, G, B of img times exposure. */
gr_status gr_report_display(const gr_image *img, double exposure, gr_image **out, gr_error *err);

#endif
