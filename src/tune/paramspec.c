/* Parameter specs for sweep and tune (paramspec.h). */
#include "tune/paramspec.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int gr_tune_param_default_bounds(const gr_param *p, gr_tune_kind kind, double *lo, double *hi)
{
    /* The technique's own tuning box: descriptor ranges are sanity bounds that would waste an
     * optimizer's evaluations. */
    if (p->tune_hi > p->tune_lo) {
        *lo = p->tune_lo;
        *hi = p->tune_hi;
        return 1;
    }
    if (kind == GR_TK_RGB_SCALE) {
        *lo = 0.1;
        *hi = 10.0;
        return 1;
    }
    if (isfinite(p->min) && isfinite(p->max) && p->max - p->min <= 1e3 && p->max > p->min) {
        *lo = p->min;
        *hi = p->max;
        return 1;
    }
    return 0;
}

gr_status gr_tune_param_lookup(const char *flag, const char *key, gr_tune_param *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    const char *dot = strchr(key, '.');
    char tech[GR_TECH_NAME_MAX];
    const gr_technique_class *cls = NULL;
    if (dot && (size_t)(dot - key) < sizeof tech) {
        memcpy(tech, key, (size_t)(dot - key));
        tech[dot - key] = '\0';
        cls = gr_technique_find(tech);
    }
    if (!cls)
        return gr_fail(err, GR_E_USAGE, "%s %s: unknown parameter (sweeps and tuning take TECHNIQUE.KEY, e.g. %s.%s; "
                       "`godrays techniques` lists them)", flag, key, gr_technique_at(0)->name,
                       gr_technique_at(0)->params->count ? gr_technique_at(0)->params->params[0].name : "KEY");
    const char *name = dot + 1;
    const gr_param *p = gr_param_find(cls->params, name);
    if (!p) return gr_fail(err, GR_E_USAGE, "%s %s: unknown %s setting '%s'", flag, key, cls->name, name);
    out->cls = cls;
    switch (p->type) {
    case GR_PT_DOUBLE: out->kind = GR_TK_SCALAR; break;
    case GR_PT_INT: out->kind = GR_TK_INT; break;
    case GR_PT_RGB: out->kind = GR_TK_RGB_SCALE; break;
    default:
        return gr_fail(err, GR_E_USAGE, "%s %s: not a numeric setting (%s); set it with --set instead", flag, key,
                       p->type == GR_PT_ENUM ? "a choice" : p->type == GR_PT_BOOL ? "true/false" : "an id");
    }
    if (snprintf(out->key, sizeof out->key, "%s", key) >= (int)sizeof out->key)
        return gr_fail(err, GR_E_USAGE, "%s %s: key too long", flag, key);
    out->p = p;
    double lo = 0, hi = 0;
    if (gr_tune_param_default_bounds(p, out->kind, &lo, &hi)) {
        out->lo = lo;
        out->hi = hi;
    } else {
        out->lo = out->hi = NAN; /* no default: --bounds required (checked by the caller) */
    }
    return GR_OK;
}

/* strtod of the whole string; -1 if not a finite number. */
static int parse_num(const char *s, double *v)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(x)) return -1;
    *v = x;
    return 0;
}

/* Splits "KEY=A:B[:C]" into key and up to 3 number texts. Returns the number of fields, -1
 * for no '=' or too long. */
static int split_spec(const char *spec, char *key, size_t key_n, char fields[3][64])
{
    const char *eq = strchr(spec, '=');
    if (!eq || (size_t)(eq - spec) >= key_n) return -1;
    memcpy(key, spec, (size_t)(eq - spec));
    key[eq - spec] = '\0';
    int n = 0;
    const char *p = eq + 1;
    for (;;) {
        const char *c = strchr(p, ':');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        if (n >= 3 || len >= 64) return 4;
        memcpy(fields[n], p, len);
        fields[n][len] = '\0';
        n++;
        if (!c) break;
        p = c + 1;
    }
    return n;
}

/* Checks the ends of a range against the setting's valid range. */
static gr_status check_range(const char *flag, const char *spec, const gr_tune_param *tp, gr_error *err)
{
    if (!(tp->lo < tp->hi))
        return gr_fail(err, GR_E_USAGE, "%s %s: empty range (need LO < HI)", flag, spec);
    if (tp->kind == GR_TK_RGB_SCALE) {
        if (tp->lo < 0)
            return gr_fail(err, GR_E_USAGE, "%s %s: %s is a scale on the scene's RGB value: must be >= 0", flag, spec,
                           tp->key);
        return GR_OK;
    }
    for (int e = 0; e < 2; e++) {
        double v = e ? tp->hi : tp->lo;
        gr_error perr;
        if (gr_param_check(tp->cls->params, tp->p, v, -1, &perr) != GR_OK)
            return gr_fail(err, GR_E_USAGE, "%s %s: %s", flag, spec, perr.msg);
    }
    return GR_OK;
}

gr_status gr_tune_param_parse_sweep(const char *flag, const char *spec, gr_tune_param *out, gr_error *err)
{
    char key[64], f[3][64];
    int n = split_spec(spec, key, sizeof key, f);
    if (n < 0) return gr_fail(err, GR_E_USAGE, "%s %s: expected TECHNIQUE.KEY=LO:HI:COUNT", flag, spec);
    gr_status st = gr_tune_param_lookup(flag, key, out, err);
    if (st != GR_OK) return st;
    if (n != 3) return gr_fail(err, GR_E_USAGE, "%s %s: expected TECHNIQUE.KEY=LO:HI:COUNT", flag, spec);
    double lo, hi, cnt;
    if (parse_num(f[0], &lo) || parse_num(f[1], &hi))
        return gr_fail(err, GR_E_USAGE, "%s %s: LO and HI must be finite numbers", flag, spec);
    if (parse_num(f[2], &cnt) || cnt != floor(cnt))
        return gr_fail(err, GR_E_USAGE, "%s %s: COUNT must be an integer", flag, spec);
    if (cnt < 2 || cnt > GR_TUNE_MAX_COUNT)
        return gr_fail(err, GR_E_USAGE, "%s %s: COUNT must be in [2, %d]", flag, spec, GR_TUNE_MAX_COUNT);
    out->lo = lo;
    out->hi = hi;
    out->count = (int)cnt;
    if ((st = check_range(flag, spec, out, err)) != GR_OK) return st;
    if (out->kind == GR_TK_INT) {
        if (lo != floor(lo) || hi != floor(hi))
            return gr_fail(err, GR_E_USAGE, "%s %s: %s is an integer setting: LO and HI must be integers", flag, spec,
                           out->key);
        if (cnt > hi - lo + 1)
            return gr_fail(err, GR_E_USAGE, "%s %s: %d values but only %.0f integers in the range", flag, spec,
                           out->count, hi - lo + 1);
    }
    return GR_OK;
}

gr_status gr_tune_param_parse_list(const char *flag, const char *spec, gr_tune_param *out, int max, int *n,
                                   gr_error *err)
{
    *n = 0;
    const char *p = spec;
    if (!*p) return gr_fail(err, GR_E_USAGE, "%s: empty list of parameters", flag);
    for (;;) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        char key[64];
        if (len == 0) return gr_fail(err, GR_E_USAGE, "%s %s: empty parameter name in the list", flag, spec);
        if (len >= sizeof key) return gr_fail(err, GR_E_USAGE, "%s %s: parameter name too long", flag, spec);
        memcpy(key, p, len);
        key[len] = '\0';
        if (*n >= max) return gr_fail(err, GR_E_USAGE, "%s %s: at most %d parameters", flag, spec, max);
        gr_status st = gr_tune_param_lookup(flag, key, &out[*n], err);
        if (st != GR_OK) return st;
        if (out[*n].kind == GR_TK_INT)
            return gr_fail(err, GR_E_USAGE, "%s %s: %s is an integer setting; the optimizer is continuous (sweep it "
                           "with godrays sweep instead)", flag, spec, key);
        for (int j = 0; j < *n; j++)
            if (!strcmp(out[j].key, key)) return gr_fail(err, GR_E_USAGE, "%s %s: %s given twice", flag, spec, key);
        (*n)++;
        if (!c) break;
        p = c + 1;
    }
    return GR_OK;
}

gr_status gr_tune_param_parse_bounds(const char *flag, const char *spec, gr_tune_param *params, int n,
                                     gr_error *err)
{
    char key[64], f[3][64];
    int nf = split_spec(spec, key, sizeof key, f);
    if (nf < 0) return gr_fail(err, GR_E_USAGE, "%s %s: expected TECHNIQUE.KEY=LO:HI", flag, spec);
    gr_tune_param probe;
    gr_status st = gr_tune_param_lookup(flag, key, &probe, err);
    if (st != GR_OK) return st;
    if (nf != 2) return gr_fail(err, GR_E_USAGE, "%s %s: expected TECHNIQUE.KEY=LO:HI", flag, spec);
    int idx = -1;
    for (int i = 0; i < n; i++)
        if (!strcmp(params[i].key, key)) idx = i;
    if (idx < 0) return gr_fail(err, GR_E_USAGE, "%s %s: %s is not among the --params", flag, spec, key);
    double lo, hi;
    if (parse_num(f[0], &lo) || parse_num(f[1], &hi))
        return gr_fail(err, GR_E_USAGE, "%s %s: LO and HI must be finite numbers", flag, spec);
    gr_tune_param t = params[idx];
    t.lo = lo;
    t.hi = hi;
    if ((st = check_range(flag, spec, &t, err)) != GR_OK) return st;
    params[idx] = t;
    return GR_OK;
}

double gr_tune_param_value(const gr_tune_param *tp, int i)
{
    if (tp->count < 2) return tp->lo;
    double v = i == tp->count - 1 ? tp->hi : tp->lo + (double)i * (tp->hi - tp->lo) / (double)(tp->count - 1);
    return tp->kind == GR_TK_INT ? floor(v + 0.5) : v;
}

double gr_tune_param_current(const gr_tune_param *tp, const void *base, const void *settings)
{
    if (tp->kind != GR_TK_RGB_SCALE) return gr_param_get_number(tp->p, settings, 0);
    int cmax = 0;
    double bmax = -1.0;
    for (int c = 0; c < 3; c++) {
        double b = gr_param_get_number(tp->p, base, c);
        if (b > bmax) {
            bmax = b;
            cmax = c;
        }
    }
    if (!(bmax > 0)) return 1.0;
    return gr_param_get_number(tp->p, settings, cmax) / bmax;
}

gr_status gr_tune_param_apply(const gr_tune_param *tp, const void *base, double v, void *s, gr_error *err)
{
    if (!isfinite(v)) return gr_fail(err, GR_E_INPUT, "%s: value %g is not finite", tp->key, v);
    if (tp->kind != GR_TK_RGB_SCALE)
        return gr_param_set_number(tp->cls->params, s, tp->p->name, -1, v, err);
    for (int c = 0; c < 3; c++) {
        double b = gr_param_get_number(tp->p, base, c);
        gr_status st = gr_param_set_number(tp->cls->params, s, tp->p->name, c, b * v, err);
        if (st != GR_OK) return st;
    }
    return GR_OK;
}

int gr_tune_default_params(const gr_technique_class *cls, char *buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
    if (cls->tune_keys) {
        char keys[512];
        if (strlen(cls->tune_keys) >= sizeof keys) return -1;
        strcpy(keys, cls->tune_keys);
        for (char *save = NULL, *t = strtok_r(keys, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
            int w = snprintf(buf + len, n - len, "%s%s.%s", len ? "," : "", cls->name, t);
            if (w < 0 || (size_t)w >= n - len) return -1;
            len += (size_t)w;
        }
    } else {
        const gr_param_table *t = cls->params;
        int taken = 0; /* at most GR_TUNE_MAX_PARAMS: the optimizer's limit */
        for (size_t i = 0; i < t->count && taken < GR_TUNE_MAX_PARAMS; i++) {
            const gr_param *p = &t->params[i];
            if (!(p->tune_hi > p->tune_lo) || (p->type != GR_PT_DOUBLE && p->type != GR_PT_RGB)) continue;
            if (cls->gain_key && !strcmp(p->name, cls->gain_key)) continue;
            int w = snprintf(buf + len, n - len, "%s%s.%s", len ? "," : "", cls->name, p->name);
            if (w < 0 || (size_t)w >= n - len) return -1;
            len += (size_t)w;
            taken++;
        }
    }
    return len ? 0 : -1;
}
