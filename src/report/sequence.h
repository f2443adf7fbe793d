/* The sequence report of `godrays run SCENE --frames A:B:S` (or --times): every technique
 * against the ground truth on each frame of the animated water, and over time. Written into
 * its own folder (DIR/sequence):
 *   index.html             a table of the temporal metrics per technique, a chart per metric
 *                          over time, an animation per technique, the per-frame numbers
 *   T.gif                  per technique: ground truth | technique x a | signed difference,
 *                          one frame per rendered frame (OpenImageIO's animated GIF writer;
 *                          the same exposure and difference scale in every frame)
 *   seq_METRIC.png         PLplot charts: rel. RMSE of Y after the fit, SSIM, HDR-FLIP,
 *                          structure score, frame-difference error, flicker ratio, beam drift
 * and returns the JSON of the sequence, which metrics.json carries as "sequence".
 * Metrics: compare/metrics.h per frame (fit, HDR-FLIP, structure), compare/temporal.h between
 * consecutive frames with the technique's one scale a (the median of its per-frame fits).
 * How to read it: docs/report.md "Sequence report". Library code: prints nothing. */
#ifndef GR_SEQUENCE_H
#define GR_SEQUENCE_H

#include "common/status.h"
#include "image/image.h"
#include "scene/scene.h"

#define GR_SEQUENCE_MAX_FRAMES 64
/* The frames' prepared FLIP halves (compare/flip.h) kept across techniques, at most this much in all. */
#define GR_SEQUENCE_FLIP_KEEP_MAX ((size_t)512 << 20)
#define GR_SEQUENCE_MAX_TECHNIQUES 32

typedef struct gr_sequence_input {
    int n_frames;                    /* 2..GR_SEQUENCE_MAX_FRAMES */
    const double *times;             /* each frame's water.time_s (s) */
    const long *frame_numbers;       /* each frame's number (--frames), NULL with --times */
    const gr_scene *const *scenes;   /* each frame's scene (camera and sun: the vanishing point) */
    const gr_image *const *refs;     /* ground truths: R, G, B [, stderr.R/G/B] */
    int n_techniques;                /* 1..GR_SEQUENCE_MAX_TECHNIQUES */
    const char *const *names;        /* technique names ([a-z][a-z0-9_]*) */
    const gr_image *const *tests;    /* tests[k * n_frames + i]: technique k, frame i (R, G, B) */
    double playback_fps;             /* the animations' rate; 0: 4 frames per second */
    const char *up_href;             /* link back to the run's page (NULL: none) */
    const char *command_line;        /* shown (NULL: none) */
} gr_sequence_input;

typedef struct gr_sequence_result {
    int charts;                      /* charts drawn (0 without PLplot) */
    int animations;                  /* GIFs written */
    double seconds;                  /* computing and writing */
    double scale[GR_SEQUENCE_MAX_TECHNIQUES]; /* the a used per technique */
    double flicker_ratio[GR_SEQUENCE_MAX_TECHNIQUES];
    double rel_diff_rmse[GR_SEQUENCE_MAX_TECHNIQUES];
    double drift_err_deg[GR_SEQUENCE_MAX_TECHNIQUES]; /* NaN: no drift measured */
} gr_sequence_result;

/* Computes the metrics and writes the folder dir (created if missing; every file through a
 * temporary name). *json (may be NULL) receives the sequence as JSON text (free() it).
 * GR_E_INPUT for counts out of range, missing or differently sized images; GR_E_IO; GR_E_NOMEM.
 * A chart PLplot cannot draw is noted in the page, not fatal. */
gr_status gr_sequence_write(const char *dir, const gr_sequence_input *in, char **json, gr_sequence_result *res,
                            gr_error *err);

#endif
