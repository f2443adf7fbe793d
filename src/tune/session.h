/* What `godrays sweep` and `godrays tune` share: the scene, the cases (frames of the animated
 * waves x camera views), each case's ground truth (cached) and one technique instance; plus the
 * parsing of --frames, --times and --view. */
#ifndef GR_TUNE_SESSION_H
#define GR_TUNE_SESSION_H

#include "common/status.h"
#include "image/image.h"
#include "realtime/technique.h"
#include "scene/scene.h"
#include "tune/objective.h"
#include "reference/truth.h"

#define GR_TUNE_MAX_TIMES 16
#define GR_TUNE_MAX_VIEWS 8

typedef struct gr_tune_session_options {
    const char *scene_path;
    const char *const *sets;      /* "json.path=value" overrides */
    int n_sets;
    int n_times;                  /* 0: the scene's water.time_s only */
    int times_relative;           /* 1: times are offsets from the scene's water.time_s (--frames) */
    double times[GR_TUNE_MAX_TIMES];
    int n_views;                  /* extra views besides the scene's own camera */
    gr_tune_view views[GR_TUNE_MAX_VIEWS];
    int use_cache;
    int progress;                 /* 1: one line per ground truth on stderr + the progress bar */
    const char *progress_label;   /* "godrays sweep" ... */
    gr_gl_platform gl_platform;
    const gr_technique_class *technique; /* NULL: the first registered one */
} gr_tune_session_options;

typedef struct gr_tune_session {
    gr_scene *base;               /* the scene as loaded */
    int n_cases;                  /* n_times x (1 + n_views), time-major */
    gr_scene *cases;              /* n_cases scenes */
    gr_image *refs[GR_TUNE_MAX_CASES];
    gr_truth_info truth[GR_TUNE_MAX_CASES];
    char labels[GR_TUNE_MAX_CASES][64]; /* "t=0.5s,view0" */
    double truth_seconds;         /* all ground truths together */
    gr_gl *gl;                    /* the renderer's context */
    gr_technique *renderer;
    const gr_technique_class *cls;
} gr_tune_session;

/* Loads and checks the scene (bad input: GR_E_INPUT before any slow work), builds the cases,
 * creates the renderer (a GL failure stops before the slow ground truths), gets the ground
 * truths. s is the caller's; close it with gr_tune_session_close even after a failure. */
gr_status gr_tune_session_open(const gr_tune_session_options *o, gr_tune_session *s, gr_error *err);
void gr_tune_session_close(gr_tune_session *s); /* accepts NULL */

/* Fills a problem's cases, renderer, class and base settings (the scene's section of the
 * technique) from s. */
void gr_tune_session_problem(const gr_tune_session *s, gr_tune_problem *p);

/* --frames A:B:S (frame numbers, inclusive, at fps) -> times base + frame / fps, appended to
 * times[*n..max). GR_E_USAGE naming flag. */
gr_status gr_tune_parse_frames(const char *flag, const char *spec, double fps, double *times, int max, int *n,
                               gr_error *err);
/* --times t1,t2,... (s) appended to times. */
gr_status gr_tune_parse_times(const char *flag, const char *spec, double *times, int max, int *n, gr_error *err);
/* --view YAW,PITCH (degrees). */
gr_status gr_tune_parse_view(const char *flag, const char *spec, gr_tune_view *v, gr_error *err);

/* "out/" + the scene name (characters outside [A-Za-z0-9._-] as '_') + "/" + sub (sub NULL:
 * the folder of `godrays run`, in which sweep, tune and pareto make theirs). */
void gr_tune_default_dir(const char *scene_name, const char *sub, char *buf, size_t n);

/* tune.json's and sweep.json's common part: a new object with the scene, technique, metric,
 * fit and size (NULL: out of memory). */
struct cJSON *gr_tune_json_root(const gr_tune_session *s, const gr_tune_problem *p);
/* A new entry of their "cases" arrays: case i's label, water time and view (NULL: out of
 * memory); the command adds its own numbers. */
struct cJSON *gr_tune_json_case(const gr_tune_session *s, int i);

/* Writes text to path through a temporary file renamed into place. */
gr_status gr_tune_write_text(const char *path, const char *text, gr_error *err);

#endif
