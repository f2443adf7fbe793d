/* Table-driven renderer settings: one descriptor per setting gives its JSON key, type,
 * range, default, unit and one-line doc. The scene loader, `--set` overrides, the
 * normalized printout, sweeps and tuning all go through these tables, so a setting is
 * declared in exactly one place (src/scene/settings.c). */
#ifndef GR_PARAMS_H
#define GR_PARAMS_H

#include <stddef.h>
#include "common/status.h"

typedef enum gr_param_type {
    GR_PT_DOUBLE, /* double */
    GR_PT_INT,    /* int */
    GR_PT_BOOL,   /* int holding 0 or 1; JSON true/false */
    GR_PT_RGB,    /* double[3]; JSON [r, g, b] or one number for all three */
    GR_PT_ENUM,   /* int index into enum_names; JSON string */
    GR_PT_U64     /* unsigned long long; JSON number (integer-valued, < 2^53) */
} gr_param_type;

enum {
    GR_PF_MIN_EXCL = 1u << 0, /* value must be > min rather than >= min */
    GR_PF_MAX_EXCL = 1u << 1, /* value must be < max rather than <= max */
    GR_PF_FROM_SCENE = 1u << 2 /* default is derived from the scene (NaN until resolved) */
};

typedef struct gr_param {
    const char *name;               /* JSON key inside the section, e.g. "K" */
    gr_param_type type;
    size_t offset;                  /* offset of the field in the settings struct */
    double min, max;                /* valid range (see flags) */
    unsigned flags;
    double def;                     /* default; NaN with GR_PF_FROM_SCENE */
    const char *const *enum_names;  /* GR_PT_ENUM: NULL-terminated names */
    const char *unit;               /* "m", "1/m", "" ... */
    const char *doc;                /* one line for docs and --help */
    /* GR_PF_FROM_SCENE: the scene quantity the default is taken from, e.g.
     * "medium.extinction" or "medium.g" (resolved by the scene loader). */
    const char *scene_source;
    /* Default tuning box of `godrays tune` (the descriptor range is a sanity bound, often far
     * wider than useful): [tune_lo, tune_hi] when tune_hi > tune_lo, else none. For an RGB
     * setting, tuned as a scale on the scene's value, the box is of that scale. */
    double tune_lo, tune_hi;
} gr_param;

typedef struct gr_param_table {
    const char *section;            /* "reference" or "shafts" */
    const gr_param *params;
    size_t count;
} gr_param_table;

/* Finds a descriptor by key; NULL if none. */
const gr_param *gr_param_find(const gr_param_table *t, const char *name);
/* Fills every field of settings with its default (NaN for GR_PF_FROM_SCENE). */
void gr_param_defaults(const gr_param_table *t, void *settings);
/* Sets one numeric setting (channel -1 = all channels of an RGB) after range checks.
 * Errors name "section.name" and the reason (GR_E_INPUT). */
gr_status gr_param_set_number(const gr_param_table *t, void *settings, const char *name,
                              int channel, double value, gr_error *err);
/* Reads one numeric setting (channel 0..2 for RGB, ignored otherwise). */
double gr_param_get_number(const gr_param *p, const void *settings, int channel);

/* Index of an enum value by name; -1 if p is not an enum or the name is unknown. */
int gr_param_enum_index(const gr_param *p, const char *name);
/* Name of enum value `index`; NULL if out of range or p is not an enum. */
const char *gr_param_enum_name(const gr_param *p, int index);
/* Sets an enum setting by name. Errors list the valid names (GR_E_INPUT). */
gr_status gr_param_set_enum(const gr_param_table *t, void *settings, const char *name,
                            const char *value, gr_error *err);
/* Checks a value against p's type and range (integer-valued for INT/U64/ENUM, 0/1 for
 * BOOL, finite). Returns GR_OK or GR_E_INPUT with "section.name: reason, got V". */
gr_status gr_param_check(const gr_param_table *t, const gr_param *p, double value, int channel,
                         gr_error *err);
/* Checks every field of settings (NaN is accepted only for unresolved
 * GR_PF_FROM_SCENE fields when allow_unresolved is nonzero). */
gr_status gr_param_validate(const gr_param_table *t, const void *settings, int allow_unresolved,
                            gr_error *err);
/* Writes p's valid range as text, e.g. "[1, 4096]", "(0, 1)", ">= 0"; returns buf. */
const char *gr_param_range_text(const gr_param *p, char *buf, size_t n);
/* Shortest "%.*g" text of v (15..17 digits) that reads back as exactly v; returns buf. */
const char *gr_format_double(double v, char *buf, size_t n);

#endif
