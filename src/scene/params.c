/* Generic access to the table-driven renderer settings (params.h). The tables themselves
 * are in settings.c; this file only knows descriptor types, ranges and offsets. */
#include "scene/params.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest integer a JSON number (an IEEE double) holds exactly: 2^53. */
#define GR_U64_JSON_MAX 9007199254740992.0

const char *gr_format_double(double v, char *buf, size_t n)
{
    if (!n) return buf;
    if (isnan(v)) { snprintf(buf, n, "nan"); return buf; }
    if (isinf(v)) { snprintf(buf, n, v > 0 ? "inf" : "-inf"); return buf; }
    /* Shortest precision that reads back as the same double, so printed scenes reload
     * bit for bit (17 significant digits always suffice for IEEE binary64). */
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, n, "%.*g", prec, v);
        if (strtod(buf, NULL) == v) break;
    }
    return buf;
}

const gr_param *gr_param_find(const gr_param_table *t, const char *name)
{
    if (!t || !name) return NULL;
    for (size_t i = 0; i < t->count; i++)
        if (!strcmp(t->params[i].name, name)) return &t->params[i];
    return NULL;
}

static void store(const gr_param *p, void *settings, int channel, double v)
{
    char *base = (char *)settings + p->offset;
    switch (p->type) {
    case GR_PT_DOUBLE: *(double *)(void *)base = v; break;
    case GR_PT_INT:
    case GR_PT_BOOL:
    case GR_PT_ENUM: *(int *)(void *)base = (int)v; break;
    case GR_PT_U64: *(unsigned long long *)(void *)base = (unsigned long long)v; break;
    case GR_PT_RGB: {
        double *rgb = (double *)(void *)base;
        if (channel < 0) rgb[0] = rgb[1] = rgb[2] = v;
        else rgb[channel] = v;
        break;
    }
    }
}

void gr_param_defaults(const gr_param_table *t, void *settings)
{
    if (!t || !settings) return;
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        /* FROM_SCENE fields stay NaN until the scene loader resolves them. */
        double v = (p->flags & GR_PF_FROM_SCENE) ? NAN : p->def;
        if (isnan(v) && p->type != GR_PT_DOUBLE && p->type != GR_PT_RGB) v = 0.0;
        store(p, settings, -1, v);
    }
}

double gr_param_get_number(const gr_param *p, const void *settings, int channel)
{
    if (!p || !settings) return NAN;
    const char *base = (const char *)settings + p->offset;
    switch (p->type) {
    case GR_PT_DOUBLE: return *(const double *)(const void *)base;
    case GR_PT_INT:
    case GR_PT_BOOL:
    case GR_PT_ENUM: return (double)*(const int *)(const void *)base;
    case GR_PT_U64: return (double)*(const unsigned long long *)(const void *)base;
    case GR_PT_RGB: {
        int c = channel < 0 ? 0 : channel > 2 ? 2 : channel;
        return ((const double *)(const void *)base)[c];
    }
    }
    return NAN;
}

int gr_param_enum_index(const gr_param *p, const char *name)
{
    if (!p || p->type != GR_PT_ENUM || !p->enum_names || !name) return -1;
    for (int i = 0; p->enum_names[i]; i++)
        if (!strcmp(p->enum_names[i], name)) return i;
    return -1;
}

const char *gr_param_enum_name(const gr_param *p, int index)
{
    if (!p || p->type != GR_PT_ENUM || !p->enum_names || index < 0) return NULL;
    for (int i = 0; p->enum_names[i]; i++)
        if (i == index) return p->enum_names[i];
    return NULL;
}

static int enum_count(const gr_param *p)
{
    int n = 0;
    if (p->enum_names)
        while (p->enum_names[n]) n++;
    return n;
}

const char *gr_param_range_text(const gr_param *p, char *buf, size_t n)
{
    char a[40], b[40];
    if (!n) return buf;
    if (p->type == GR_PT_BOOL) { snprintf(buf, n, "true or false"); return buf; }
    if (p->type == GR_PT_ENUM) {
        size_t used = 0;
        buf[0] = '\0';
        for (int i = 0; p->enum_names && p->enum_names[i]; i++) {
            int w = snprintf(buf + used, n - used, "%s%s", i ? ", " : "", p->enum_names[i]);
            if (w < 0 || (size_t)w >= n - used) break;
            used += (size_t)w;
        }
        return buf;
    }
    gr_format_double(p->min, a, sizeof a);
    gr_format_double(p->max, b, sizeof b);
    int lo_excl = (p->flags & GR_PF_MIN_EXCL) != 0, hi_excl = (p->flags & GR_PF_MAX_EXCL) != 0;
    if (isinf(p->max) && isinf(p->min)) snprintf(buf, n, "any finite number");
    else if (isinf(p->max)) snprintf(buf, n, "%s %s", lo_excl ? ">" : ">=", a);
    else if (isinf(p->min)) snprintf(buf, n, "%s %s", hi_excl ? "<" : "<=", b);
    else snprintf(buf, n, "%c%s, %s%c", lo_excl ? '(' : '[', a, b, hi_excl ? ')' : ']');
    return buf;
}

static void param_path(const gr_param_table *t, const gr_param *p, int channel, char *buf, size_t n)
{
    if (p->type == GR_PT_RGB && channel >= 0)
        snprintf(buf, n, "%s.%s[%d]", t ? t->section : "?", p->name, channel);
    else
        snprintf(buf, n, "%s.%s", t ? t->section : "?", p->name);
}

gr_status gr_param_check(const gr_param_table *t, const gr_param *p, double v, int channel,
                         gr_error *err)
{
    char path[160], got[40], range[160];
    param_path(t, p, channel, path, sizeof path);
    gr_format_double(v, got, sizeof got);
    if (!isfinite(v)) return gr_fail(err, GR_E_INPUT, "%s: must be a finite number, got %s", path, got);
    switch (p->type) {
    case GR_PT_BOOL:
        if (v != 0.0 && v != 1.0) return gr_fail(err, GR_E_INPUT, "%s: must be true or false, got %s", path, got);
        return GR_OK;
    case GR_PT_ENUM:
        if (v != floor(v) || v < 0 || v >= enum_count(p))
            return gr_fail(err, GR_E_INPUT, "%s: must be one of %s, got %s", path,
                           gr_param_range_text(p, range, sizeof range), got);
        return GR_OK;
    case GR_PT_INT:
    case GR_PT_U64:
        if (v != floor(v)) return gr_fail(err, GR_E_INPUT, "%s: must be an integer, got %s", path, got);
        if (p->type == GR_PT_U64 && (v < 0 || v >= GR_U64_JSON_MAX))
            return gr_fail(err, GR_E_INPUT, "%s: must be an integer in [0, 2^53), got %s", path, got);
        break;
    case GR_PT_DOUBLE:
    case GR_PT_RGB: break;
    }
    int lo_ok = (p->flags & GR_PF_MIN_EXCL) ? v > p->min : v >= p->min;
    int hi_ok = (p->flags & GR_PF_MAX_EXCL) ? v < p->max : v <= p->max;
    if (!lo_ok || !hi_ok)
        return gr_fail(err, GR_E_INPUT, "%s: must be %s%s, got %s", path,
                       (isinf(p->min) || isinf(p->max)) ? "" : "in ",
                       gr_param_range_text(p, range, sizeof range), got);
    return GR_OK;
}

gr_status gr_param_set_number(const gr_param_table *t, void *settings, const char *name,
                              int channel, double value, gr_error *err)
{
    const gr_param *p = gr_param_find(t, name);
    if (!p)
        return gr_fail(err, GR_E_INPUT, "%s.%s: unknown key", t ? t->section : "?", name ? name : "(null)");
    if (!settings) return gr_fail(err, GR_E_RUNTIME, "%s.%s: no settings to write", t->section, name);
    if (channel > 2 || (channel >= 0 && p->type != GR_PT_RGB))
        return gr_fail(err, GR_E_INPUT, "%s.%s: no channel %d", t->section, name, channel);
    gr_status st = gr_param_check(t, p, value, channel, err);
    if (st != GR_OK) return st;
    store(p, settings, channel, value);
    return GR_OK;
}

gr_status gr_param_set_enum(const gr_param_table *t, void *settings, const char *name,
                            const char *value, gr_error *err)
{
    const gr_param *p = gr_param_find(t, name);
    char names[160];
    if (!p)
        return gr_fail(err, GR_E_INPUT, "%s.%s: unknown key", t ? t->section : "?", name ? name : "(null)");
    if (p->type != GR_PT_ENUM) return gr_fail(err, GR_E_INPUT, "%s.%s: not a named choice", t->section, name);
    int idx = gr_param_enum_index(p, value);
    if (idx < 0) {
        gr_fail(err, GR_E_INPUT, "%s.%s: unknown value, expected one of %s, got \"%s\"", t->section, name,
                gr_param_range_text(p, names, sizeof names), value ? value : "");
        /* the value is user text: keep the message on one line */
        for (char *q = err ? err->msg : NULL; q && *q; q++)
            if ((unsigned char)*q < 0x20 || *q == 0x7f) *q = '?';
        return GR_E_INPUT;
    }
    store(p, settings, -1, idx);
    return GR_OK;
}

gr_status gr_param_validate(const gr_param_table *t, const void *settings, int allow_unresolved,
                            gr_error *err)
{
    if (!t || !settings) return gr_fail(err, GR_E_RUNTIME, "no settings to validate");
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        int nch = p->type == GR_PT_RGB ? 3 : 1;
        for (int c = 0; c < nch; c++) {
            double v = gr_param_get_number(p, settings, c);
            if (isnan(v) && allow_unresolved && (p->flags & GR_PF_FROM_SCENE)) continue;
            gr_status st = gr_param_check(t, p, v, p->type == GR_PT_RGB ? c : -1, err);
            if (st != GR_OK) return st;
        }
    }
    return GR_OK;
}
