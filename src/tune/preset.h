/* A preset: one technique's full settings as a JSON file (docs/tuning.md "Presets"), written
 * by the budget table of `pareto --suite --tune` (one per budget) and applied with `--preset
 * FILE` by render, run, sweep, tune and export --constants (each setting becomes the scene
 * override NAME.KEY=VALUE, in command-line order with --set). Numbers are written so that they
 * read back to the same double (cJSON: 15 significant digits, 17 where 15 do not round-trip),
 * so a preset reproduces the image it was scored on byte for byte. A scene-derived setting
 * left unresolved (NaN) is not written: it follows the scene it is applied to.
 *
 * {"godrays_preset": 1, "technique": "NAME", "settings": {KEY: VALUE, ...},
 *  "timed": {"renderer": GL_RENDERER, "width": W, "height": H, "time_ms": T, "cpu_rasterizer": B},
 *  "score": {"budget_ms": B, "test_error": E, "train_error": E, "eq_blur_px": P, "suite": PATH,
 *            "error_size": [W, H]}}   ("timed" and "score" optional) */
#ifndef GR_TUNE_PRESET_H
#define GR_TUNE_PRESET_H

#include "common/status.h"
#include "realtime/technique.h"

#define GR_PRESET_VERSION 1
#define GR_PRESET_MAX_SETS 128

/* What a preset says besides the settings; NaN / 0 / "" = not stated. */
typedef struct gr_preset_info {
    char renderer[128];
    int timing_width, timing_height;
    double time_ms;
    int cpu_rasterizer;
    double budget_ms, test_error, train_error, eq_blur_px;
    char suite[1024];
    int error_width, error_height;
} gr_preset_info;

void gr_preset_info_clear(gr_preset_info *info); /* every figure NaN, strings empty */

/* A preset as read: its technique and the overrides "NAME.KEY=JSON" that apply it. */
typedef struct gr_preset {
    char technique[GR_TECH_NAME_MAX];
    int n_sets;
    char *sets[GR_PRESET_MAX_SETS]; /* owned */
    gr_preset_info info;
} gr_preset;

/* The preset's JSON text for cls's settings (unresolved NaN settings left out) and info (may be
 * NULL); malloc'd (caller frees), NULL when out of memory. */
char *gr_preset_text(const gr_technique_class *cls, const void *settings, const gr_preset_info *info);
gr_status gr_preset_write(const char *path, const gr_technique_class *cls, const void *settings,
                          const gr_preset_info *info, gr_error *err);

/* Reads a preset: GR_E_IO when unreadable, GR_E_INPUT "FILE: JSON.PATH: reason" for bad
 * content (not JSON, no "technique", a technique not registered, a key that is not one of its
 * settings, a value of the wrong JSON type). The values' ranges are checked when the scene is
 * loaded with the overrides. */
gr_status gr_preset_load(const char *path, gr_preset *out, gr_error *err);
void gr_preset_free(gr_preset *p); /* the sets; accepts NULL */

/* Applies p's settings to settings (cls's struct) through the overrides' values: what loading
 * a scene with the overrides does, for code that holds settings rather than a scene. */
gr_status gr_preset_apply(const gr_preset *p, const gr_technique_class *cls, void *settings, gr_error *err);

#endif
