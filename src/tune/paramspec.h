/* Parameter specs of `godrays sweep` and `godrays tune`: which technique setting a sweep axis
 * or an optimizer coordinate moves, and over what range. Keys are "NAME.KEY" with NAME a
 * registered technique (src/realtime/technique.h), looked up in its descriptor table, so
 * ranges and checks are the scene loader's. docs/tuning.md.
 *
 * Value of a parameter:
 *  - a number setting (double): the setting itself (NAME.K = 0.8);
 *  - an integer setting: the setting, sweep only, integer values;
 *  - an RGB setting: a SCALE on the scene's resolved value (an extinction that defaults to
 *    the medium's sigma_t at 1 is the physical value, 0.5 halves all three channels).
 * Booleans and enums (caps, target_format) are not numeric: specs naming them are rejected. */
#ifndef GR_TUNE_PARAMSPEC_H
#define GR_TUNE_PARAMSPEC_H

#include "common/status.h"
#include "realtime/technique.h"
#include "scene/params.h"

#define GR_TUNE_MAX_PARAMS 8
#define GR_TUNE_MAX_COUNT 4096 /* values along one sweep axis */

typedef enum gr_tune_kind {
    GR_TK_SCALAR = 0,   /* double setting: the value is the setting */
    GR_TK_INT = 1,      /* int setting: the value (an integer) is the setting */
    GR_TK_RGB_SCALE = 2 /* RGB setting: the value scales the base RGB */
} gr_tune_kind;

typedef struct gr_tune_param {
    char key[64];          /* "NAME.KEY" */
    const gr_technique_class *cls; /* the technique NAME */
    const gr_param *p;     /* its descriptor in cls->params */
    gr_tune_kind kind;
    double lo, hi;         /* sweep range (inclusive) or optimizer box, lo < hi */
    int count;             /* sweep: values along the axis (>= 2); tune: 0 */
} gr_tune_param;

/* Looks up "NAME.KEY" for the option `flag` (named in errors). GR_E_USAGE for an unknown
 * technique or key, or a boolean/enum setting. On success out->lo/hi are the default tuning
 * bounds (gr_tune_param_default_bounds) and count is 0. */
gr_status gr_tune_param_lookup(const char *flag, const char *key, gr_tune_param *out, gr_error *err);

/* Parses a sweep axis "NAME.K=0.4:1.2:16" (lo:hi:count, inclusive). GR_E_USAGE, naming
 * flag and spec, for a missing '=', an unknown or non-numeric key, a non-numeric or
 * non-finite number, lo >= hi, count < 2 or > GR_TUNE_MAX_COUNT, non-integer ends or more
 * values than integers in the range for an integer setting, ends outside the setting's
 * valid range (scale < 0 for an RGB scale). */
gr_status gr_tune_param_parse_sweep(const char *flag, const char *spec, gr_tune_param *out, gr_error *err);

/* Parses a comma-separated list of keys "NAME.K,NAME.E" into at most max
 * params with default bounds. Integer settings are rejected (the optimizer is continuous:
 * sweep them instead), as are repeated keys and an empty list. */
gr_status gr_tune_param_parse_list(const char *flag, const char *spec, gr_tune_param *out, int max, int *n,
                                   gr_error *err);

/* The --params list `godrays tune` uses when none is given: "NAME.KEY,..." from the class's
 * tune_keys, else the non-integer numeric settings with a tuning box except its gain_key, the
 * first GR_TUNE_MAX_PARAMS of them (the optimizer's limit). 0 on success, -1 if it does not fit in n bytes or is empty. */
int gr_tune_default_params(const gr_technique_class *cls, char *buf, size_t n);

/* Parses "NAME.K=0.2:2" and sets the bounds of the matching entry of params[0..n).
 * GR_E_USAGE if the key is not among them or the range is empty/invalid. */
gr_status gr_tune_param_parse_bounds(const char *flag, const char *spec, gr_tune_param *params, int n,
                                     gr_error *err);

/* Default optimizer bounds of a setting: its descriptor's tuning box (tune_lo, tune_hi) when it
 * has one; else 0.1..10 for an RGB scale; otherwise the descriptor's range when it is finite
 * and narrower than 1e3. Returns 0 and leaves lo/hi alone if there is none. */
int gr_tune_param_default_bounds(const gr_param *p, gr_tune_kind kind, double *lo, double *hi);

/* Value i (0..count-1) of a sweep axis: lo + i (hi - lo) / (count - 1), rounded for ints. */
double gr_tune_param_value(const gr_tune_param *tp, int i);

/* The parameter's value in settings relative to base (both resolved: no NaN): the setting
 * itself, or for an RGB scale the ratio of the largest channel to base's (1 if base is 0). */
double gr_tune_param_current(const gr_tune_param *tp, const void *base, const void *settings);

/* *s = the result of setting the parameter to v starting from *s, with RGB scales applied
 * to base (resolved). Range-checked through the descriptor table: GR_E_INPUT naming the key. */
gr_status gr_tune_param_apply(const gr_tune_param *tp, const void *base, double v, void *s, gr_error *err);

#endif
