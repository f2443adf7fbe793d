/* The real-time technique interface: every god-ray technique the harness measures (seed 000's
 * shafts, the radial blurs of seeds 003/004, the volume techniques, a user's own shader from a
 * manifest) is one gr_technique_class. Commands, tuning and the report only ever go through
 * this header and the registry below: they never name a technique (docs/architecture.md).
 *
 * A class describes a technique: its name (= its scene section), a one-line description, its
 * settings as a descriptor table (src/scene/params.h: key, type, range, default, unit, doc)
 * and the callbacks. An instance (gr_technique) is created once per GL context and renders
 * many (scene, settings) pairs: sweeps and tuning reuse it. A technique never prints.
 *
 * Settings: an opaque struct of cls->settings_size bytes laid out as cls->params describes
 * (offsets into it). The scene loader parses the section named cls->name with that table
 * (defaults, range checks, --set NAME.KEY=V), so a technique receives checked values. */
#ifndef GR_TECHNIQUE_H
#define GR_TECHNIQUE_H

#include <stddef.h>

#include "common/status.h"
#include "gl/glctx.h"
#include "image/image.h"
#include "scene/params.h"
#include "scene/scene.h"
#include "scene/sections.h"

#define GR_TECH_NAME_MAX 32        /* names: [a-z][a-z0-9_]*, at most 31 characters */
#define GR_TECH_MAX_PASSES 8       /* GL passes reported per render */
#define GR_TECH_SETTINGS_MAX GR_SCENE_SECTION_BYTES /* bytes of one settings struct (1024), at most */
#define GR_TECH_MAX GR_SCENE_MAX_SECTIONS           /* techniques in one registry (32, built-in + user) */

/* What one pass did: the cost model a machine without a GPU can measure (docs/techniques.md,
 * "Cost counters"). Each counter is either counted from what the pass draws or dispatches
 * (analytic: a full-screen pass shades width x height fragments) or read from a GL query
 * (bit k of `queried`): fragments from GL_SAMPLES_PASSED (fragments that reach the target:
 * one discarded in the shader is not counted), primitives from GL_PRIMITIVES_GENERATED (what
 * the vertex or geometry stage emitted, before clipping). -1: not counted. */
enum {
    GR_COST_FRAGMENTS = 0,  /* fragments shaded */
    GR_COST_TAPS = 1,       /* texture taps (texture()/texelFetch()/imageLoad() calls executed) */
    GR_COST_VERTICES = 2,   /* vertices submitted to draws (indices for an indexed draw) */
    GR_COST_PRIMITIVES = 3, /* primitives emitted by the last vertex-processing stage */
    GR_COST_BYTES = 4,      /* bytes written to render targets and images (blending: each write) */
    GR_COST_INVOCATIONS = 5,/* compute-shader invocations */
    GR_COST_N = 6
};
typedef struct gr_pass_cost {
    long long v[GR_COST_N];
    unsigned queried;       /* bit k: counter k came from a GL query, else analytic */
} gr_pass_cost;

/* What one render cost. Filled by the technique; -1 where a figure is unavailable. */
typedef struct gr_technique_stats {
    int n_passes;
    char pass_names[GR_TECH_MAX_PASSES][24]; /* "shadow", "shafts", "final", ... */
    long long gpu_ns[GR_TECH_MAX_PASSES];    /* GL_TIME_ELAPSED of each pass; -1 if no timer */
    double wall_ms;                          /* wall time of the render call, readback included */
    long long fragments;                     /* fragments shaded in the main pass(es); -1 unknown */
    gr_pass_cost cost[GR_TECH_MAX_PASSES];   /* per pass; every counter -1 until counted */
} gr_technique_stats;

/* ---- cost counters ---------------------------------------------------------------------- */

/* "fragments", "taps", "vertices", "primitives", "bytes", "invocations" (k < GR_COST_N). */
const char *gr_cost_name(int k);
/* Every counter -1, none queried. */
void gr_pass_cost_clear(gr_pass_cost *c);
/* A full-screen pass (one triangle, 3 vertices) over a w x h target: w h fragments, each
 * taking taps_per_px texture taps and writing bytes_per_px bytes; no compute. */
gr_pass_cost gr_pass_cost_screen(long long w, long long h, long long taps_per_px, long long bytes_per_px);
/* Sets counter k of pass p of stats to v, marking it queried or not (ignores p out of range). */
void gr_technique_cost_set(gr_technique_stats *s, int p, int k, long long v, int queried);
/* The sum over the passes of each counter (-1 where no pass counted it). */
void gr_technique_cost_total(const gr_technique_stats *s, gr_pass_cost *out);
/* A render's work for search budgets (docs/tuning.md "Search budgets"): the sum over its passes
 * of the fragments, vertices, primitives and invocations counted (taps and bytes left out: a
 * full-screen pass's taps are cheap beside a rasterized primitive); 0 when none is counted. */
long long gr_technique_stats_work(const gr_technique_stats *s);
/* "fragments 2073600, taps 8294400, ..." of a pass cost (counters not counted left out; a
 * queried one marked with '*'), "" when nothing was counted. */
void gr_pass_cost_text(const gr_pass_cost *c, char *buf, size_t n);

/* Options of an instance; zero = defaults. */
typedef struct gr_technique_options {
    const char *shader_dir; /* NULL: the technique's embedded shaders; else files there override */
} gr_technique_options;

typedef struct gr_technique_class gr_technique_class;

/* One point of a technique's speed/quality ladder for `godrays pareto`: settings changed from
 * the scene's, as "KEY=VALUE,KEY=VALUE" (numbers, true/false, choice names). */
typedef struct gr_technique_level {
    const char *settings;
    int quick;            /* 1: also in `godrays pareto --quick` */
} gr_technique_level;

struct gr_technique_class {
    const char *name;          /* "shafts", "radial_blur", ...: CLI name and scene section */
    const char *description;   /* one line for `godrays techniques` */
    const gr_param_table *params; /* params->section == name */
    size_t settings_size;      /* <= GR_TECH_SETTINGS_MAX */
    const char *origin;        /* "built-in" or the manifest's path (user techniques) */
    const void *class_data;    /* the class's own data (a descriptor; a user technique's parsed manifest) */
    /* A setting (double or RGB) that scales the whole output linearly ("intensity",
     * "exposure"): where `godrays tune` puts the fitted scale in its snippet, and the scale
     * fit is off by default when it is tuned. NULL: none. */
    const char *gain_key;
    /* Settings that trade speed for quality, from cheap to costly, for `godrays pareto`
     * (NULL / 0: the scene's settings only). */
    const gr_technique_level *ladder;
    int n_ladder;
    /* The settings `godrays tune` tunes when --params is not given, "KEY,KEY,..." (NULL: every
     * setting with a tuning box except gain_key). */
    const char *tune_keys;
    /* 1: left out of gr_technique_parse_list's default list (every technique): a slow technique
     * that runs only when named (eevee: Blender as a child process). */
    int by_name_only;
    /* May be NULL (always available). Else 1, or 0 with the reason in why (naming the missing
     * program): an unavailable class is listed by `godrays techniques` with its reason, left
     * out of the default list and refused when named (GR_E_USAGE, exit 2). */
    int (*available)(const gr_technique_class *cls, char *why, size_t n);

    /* Checks across settings beyond each one's range (e.g. N >= 2 and a target that fits).
     * May be NULL. Errors name "NAME.KEY" and the reason (GR_E_INPUT). Called only by
     * gr_technique_check, after the table's ranges passed: the ONE validation of a class's
     * settings; a class never re-validates its table, and its render receives settings that
     * passed both (and gr_technique_render's check of the resolved ones). */
    gr_status (*check)(const gr_technique_class *cls, const void *settings, gr_error *err);
    /* Copies in to out with scene-derived defaults (GR_PF_FROM_SCENE, NaN) resolved from the
     * scene (e.g. extinction from the medium). May be NULL: the generic resolution by each
     * descriptor's scene_source is applied. */
    void (*resolve)(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out);
    /* Creates the technique's GL state (programs, buffers) in the CURRENT context gl, which
     * outlives the instance. A shader compile/link failure is GR_E_GL with the GLSL log; a bad
     * shader_dir GR_E_INPUT. */
    gr_status (*create)(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                        void **state, gr_error *err);
    void (*destroy)(void *state); /* accepts NULL */
    /* Renders the god-ray layer of scene at scene->water.time_s with RESOLVED settings into
     * out: camera.width x camera.height, channels "R", "G", "B" (linear radiance, the same
     * units as the ground truth; others left alone). Never writes NaN or Inf. stats may be
     * NULL. */
    gr_status (*render)(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                        gr_technique_stats *stats, gr_error *err);
    /* Adds technique-specific "godrays:*" metadata of a render (placement, counts, ...).
     * May be NULL; the generic keys (technique, settings, pass times) are written by
     * gr_technique_metadata. */
    gr_status (*metadata)(void *state, const gr_scene *scene, const void *settings,
                          const gr_technique_stats *stats, gr_metadata *meta, gr_error *err);
    /* Optional (may be NULL), for `godrays render`: one line of the technique's own figures
     * of the last render (counts, target size, ...) written into buf, without a newline. */
    void (*summary)(void *state, const gr_technique_stats *stats, char *buf, size_t n);
    /* Optional (may be NULL), for `godrays render --save-target`: the technique's main
     * intermediate render target of the last render as an RGBA float image (*out is the
     * caller's). */
    gr_status (*read_target)(void *state, gr_image **out, gr_error *err);
    /* Optional (may be NULL): gr_technique_set_reuse's switch for this class's state. */
    void (*set_reuse)(void *state, int on);
};

/* ---- registry --------------------------------------------------------------------------- */

/* The techniques known to this process: the built-in ones (registered on first use of any
 * function below) and the user techniques added with gr_technique_add_dir. Also makes their
 * sections known to the scene loader (src/scene/sections.h), so load scenes AFTER the first
 * registry call (e.g. gr_technique_count()) and after adding user techniques: a scene loaded
 * before knows none of their sections. */
int gr_technique_count(void);
const gr_technique_class *gr_technique_at(int i);
const gr_technique_class *gr_technique_find(const char *name); /* NULL if unknown */
/* Index of a class in the registry (= index of its settings in a scene); -1 if absent. */
int gr_technique_index(const gr_technique_class *cls);
/* Registers a class (built-in or user). GR_E_INPUT for a bad or duplicate name, a table whose
 * section differs from the name, or settings over GR_TECH_SETTINGS_MAX. */
gr_status gr_technique_register(const gr_technique_class *cls, gr_error *err);
/* Loads the user technique in dir (its manifest.json, docs/techniques.md) and registers it
 * under the manifest's name. A bad manifest is GR_E_INPUT naming the file and JSON path. */
gr_status gr_technique_add_dir(const char *dir, gr_error *err);
/* "shafts,radial_blur,..." -> classes; GR_E_USAGE naming flag and the unknown name, or the
 * unavailable technique and why. NULL or "" -> every registered technique that is available
 * and not by_name_only. Returns the count in *n. */
gr_status gr_technique_parse_list(const char *flag, const char *list, const gr_technique_class **out,
                                  int max, int *n, gr_error *err);

/* 1 if cls can run here (its available callback, or none); else 0 with the reason in why. */
int gr_technique_available(const gr_technique_class *cls, char *why, size_t n);

/* The scene's settings of a technique (as loaded and overridden; the loader already resolved
 * scene-derived defaults by each descriptor's scene_source, a NaN set later stays NaN until
 * gr_technique_resolve), and the same resolved into out (settings_size bytes). For a class
 * registered after the scene was loaded, its defaults. */
const void *gr_technique_scene_settings(const gr_technique_class *cls, const gr_scene *scene);
/* The same, writable (sweeps and tests change a scene's settings in place; gr_scene_refresh
 * re-validates). NULL for a class registered after the scene was loaded. */
void *gr_technique_scene_settings_rw(const gr_technique_class *cls, gr_scene *scene);
void gr_technique_resolve(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out);
/* The table's ranges (NaN allowed where scene-derived), then the class's check. */
gr_status gr_technique_check(const gr_technique_class *cls, const void *settings, gr_error *err);
/* The first (at most max) number or RGB settings of cls that have a tuning box, in table
 * order: the example parameters commands suggest (`--params NAME.A,NAME.B`). Returns how many. */
int gr_technique_tune_example(const gr_technique_class *cls, const gr_param **out, int max);
/* Applies "KEY=VALUE,KEY=VALUE" (a ladder level) to settings through the class's table;
 * GR_E_INPUT naming "NAME.KEY" for an unknown key or a bad value. */
gr_status gr_technique_apply_text(const gr_technique_class *cls, void *settings, const char *text, gr_error *err);

/* ---- time limit ------------------------------------------------------------------------ */

/* Every render has a time limit (docs/techniques.md "Time limit"): gr_technique_set_time_limit
 * (a command's --time-limit), else $GODRAYS_TIME_LIMIT, else GR_TECH_TIME_LIMIT_DEFAULT_S,
 * far above what a sensible render takes. A class enforces it by calling
 * gr_technique_wait_pass after each pass; a render over it fails with GR_E_TIMEOUT, and the
 * instance and its GL context are abandoned (gr_gl_abandon): work still queued is never
 * waited for, the context never reused. The user techniques call it; the built-in ones,
 * whose cost their settings' ranges bound, do not. */
#define GR_TECH_TIME_LIMIT_DEFAULT_S 60.0
#define GR_TECH_TIME_LIMIT_MAX_S 86400.0
/* "SECONDS" (a number in (0, 86400]) into *seconds; GR_E_USAGE naming what otherwise. */
gr_status gr_technique_parse_time_limit(const char *what, const char *text, double *seconds, gr_error *err);
void gr_technique_set_time_limit(double seconds); /* <= 0: back to the environment / default */
/* The limit in seconds and where it comes from ("--time-limit", "GODRAYS_TIME_LIMIT", "the
 * default"). An unparsable $GODRAYS_TIME_LIMIT is GR_E_USAGE. */
gr_status gr_technique_time_limit(double *seconds, const char **source, gr_error *err);
/* For a class's render, after a pass (what names it): flushes the GL work issued so far and
 * waits until it is done, or until the current render's time limit passes: GR_E_TIMEOUT
 * "TECHNIQUE: WHAT: not done after the time limit of S s (SOURCE) ...". Outside a render
 * (gr_technique_render) it waits without a limit. */
gr_status gr_technique_wait_pass(const char *what, gr_error *err);
/* A command's word while a render is long (issue 29: piped `run` shows progress): while
 * gr_technique_wait_pass waits inside a render, fn is called on the render's thread every
 * every_s seconds of it (elapsed_s since the render began, limit_s its time limit). fn NULL:
 * none (the default). Only the classes that wait per pass (the user techniques) report. */
typedef void (*gr_technique_wait_fn)(void *user, const char *technique, const char *what, double elapsed_s,
                                     double limit_s);
void gr_technique_set_wait_report(gr_technique_wait_fn fn, void *user, double every_s);

/* ---- instances -------------------------------------------------------------------------- */

typedef struct gr_technique gr_technique; /* a class + its GL state; one thread */

/* GR_E_TIMEOUT for a context abandoned after a time limit (gr_gl_abandoned). */
gr_status gr_technique_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                              gr_technique **out, gr_error *err);
void gr_technique_destroy(gr_technique *t); /* accepts NULL */
const gr_technique_class *gr_technique_class_of(const gr_technique *t);
/* settings NULL: the scene's own, resolved. Checks the settings first (GR_E_INPUT). Over the
 * time limit: GR_E_TIMEOUT, and t and its context are abandoned (every later render of t is
 * GR_E_TIMEOUT; gr_technique_create refuses the context; destroy t and the context as
 * usual, neither touches GL then): the caller makes a new context for what follows. */
/* A search (tuning) renders the same frames again and again with settings that change the
 * look: on, the instance may keep what depends only on the frame and on settings a search
 * does not move (the caustic stack of the volume techniques: caustics.h) and take it again
 * when the same inputs recur: the same pixels, but that pass costs no time, so a timed
 * render must have it off (the default). A class without set_reuse ignores it. */
void gr_technique_set_reuse(gr_technique *t, int on);

gr_status gr_technique_render(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out,
                              gr_technique_stats *stats, gr_error *err);
/* "godrays:technique", every setting (resolved, by name), GL strings, per-pass GPU ns, wall ms,
 * fragments, the cost counters ("godrays:cost.PASS.COUNTER" per pass, "godrays:cost.COUNTER"
 * summed, "godrays:cost_queried" naming the queried ones), then the class's own keys. */
gr_status gr_technique_metadata(const gr_technique *t, const gr_scene *scene, const void *settings,
                                const gr_technique_stats *stats, gr_metadata *meta, gr_error *err);
/* Sum of the passes' GPU times in ms; -1 if none was timed. */
double gr_technique_stats_gpu_ms(const gr_technique_stats *s);
/* Stats with nothing measured (n_passes 0, every figure -1). */
void gr_technique_stats_clear(gr_technique_stats *s);
/* Per-figure median of n stats (same passes), so that one warm-up outlier does not count. */
void gr_technique_stats_median(const gr_technique_stats *all, int n, gr_technique_stats *out);
/* The class's summary line of the last render ("" if it has none). */
void gr_technique_summary(const gr_technique *t, const gr_technique_stats *stats, char *buf, size_t n);
/* The class's intermediate target of the last render; GR_E_USAGE naming the technique if it
 * has none. */
gr_status gr_technique_read_target(gr_technique *t, gr_image **out, gr_error *err);
/* The context the instance renders in. */
gr_gl *gr_technique_gl(const gr_technique *t);

#endif
