/* Presets (preset.h). */
#include "tune/preset.h"
#include "common/outfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include "scene/scene.h"

#define PRESET_MAX_BYTES (1 << 20)

void gr_preset_info_clear(gr_preset_info *info)
{
    memset(info, 0, sizeof *info);
    info->time_ms = info->budget_ms = info->test_error = info->train_error = info->eq_blur_px = NAN;
}

/* One setting as JSON: NULL for an unresolved (NaN) scene-derived value or out of memory. */
static cJSON *setting_json(const gr_param *p, const void *s)
{
    switch (p->type) {
    case GR_PT_BOOL: return cJSON_CreateBool(gr_param_get_number(p, s, 0) != 0.0);
    case GR_PT_ENUM: {
        const char *name = gr_param_enum_name(p, (int)gr_param_get_number(p, s, 0));
        return name ? cJSON_CreateString(name) : NULL;
    }
    case GR_PT_RGB: {
        double v[3];
        for (int c = 0; c < 3; c++)
            if (!isfinite(v[c] = gr_param_get_number(p, s, c))) return NULL;
        return cJSON_CreateDoubleArray(v, 3);
    }
    default: {
        const double v = gr_param_get_number(p, s, 0);
        return isfinite(v) ? cJSON_CreateNumber(v) : NULL;
    }
    }
}

static void add_num(cJSON *o, const char *key, double v)
{
    if (isfinite(v)) cJSON_AddNumberToObject(o, key, v);
}

char *gr_preset_text(const gr_technique_class *cls, const void *settings, const gr_preset_info *info)
{
    cJSON *root = cJSON_CreateObject();
    if (!root) return NULL;
    cJSON_AddNumberToObject(root, "godrays_preset", GR_PRESET_VERSION);
    cJSON_AddStringToObject(root, "technique", cls->name);
    cJSON *set = cJSON_AddObjectToObject(root, "settings");
    for (size_t i = 0; set && i < cls->params->count; i++) {
        const gr_param *p = &cls->params->params[i];
        cJSON *v = setting_json(p, settings);
        if (v) cJSON_AddItemToObject(set, p->name, v);
    }
    if (info && (info->renderer[0] || info->timing_width > 0)) {
        cJSON *t = cJSON_AddObjectToObject(root, "timed");
        if (t && info->renderer[0]) cJSON_AddStringToObject(t, "renderer", info->renderer);
        if (t && info->timing_width > 0) {
            cJSON_AddNumberToObject(t, "width", info->timing_width);
            cJSON_AddNumberToObject(t, "height", info->timing_height);
        }
        if (t) add_num(t, "time_ms", info->time_ms);
        if (t) cJSON_AddBoolToObject(t, "cpu_rasterizer", info->cpu_rasterizer);
    }
    if (info && (isfinite(info->budget_ms) || isfinite(info->test_error) || isfinite(info->train_error))) {
        cJSON *sc = cJSON_AddObjectToObject(root, "score");
        if (sc) {
            add_num(sc, "budget_ms", info->budget_ms);
            add_num(sc, "test_error", info->test_error);
            add_num(sc, "train_error", info->train_error);
            if (isfinite(info->test_error) && isfinite(info->train_error))
                cJSON_AddNumberToObject(sc, "generalization_gap", info->test_error - info->train_error);
            add_num(sc, "eq_blur_px", info->eq_blur_px);
            if (info->suite[0]) cJSON_AddStringToObject(sc, "suite", info->suite);
            if (info->error_width > 0) {
                const int wh[2] = {info->error_width, info->error_height};
                cJSON_AddItemToObject(sc, "error_size", cJSON_CreateIntArray(wh, 2));
            }
        }
    }
    char *text = set ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    return text;
}

gr_status gr_preset_write(const char *path, const gr_technique_class *cls, const void *settings,
                          const gr_preset_info *info, gr_error *err)
{
    char *text = gr_preset_text(cls, settings, info);
    if (!text) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    gr_status st = gr_outfile_write(path, text, -1, err);
    free(text);
    return st;
}


/* The override for one setting: "NAME.KEY=JSON", its JSON type checked against the table. */
static gr_status setting_override(const char *path, const gr_technique_class *cls, const cJSON *v, char **out,
                                  gr_error *err)
{
    const gr_param *p = gr_param_find(cls->params, v->string);
    if (!p) return gr_fail(err, GR_E_INPUT, "%s: settings.%s: not a setting of technique %s", path, v->string, cls->name);
    const int ok = p->type == GR_PT_BOOL ? cJSON_IsBool(v)
                   : p->type == GR_PT_ENUM ? cJSON_IsString(v)
                   : p->type == GR_PT_RGB ? (cJSON_IsNumber(v) || (cJSON_IsArray(v) && cJSON_GetArraySize(v) == 3))
                                          : cJSON_IsNumber(v);
    if (!ok)
        return gr_fail(err, GR_E_INPUT, "%s: settings.%s: expected %s, got %s", path, v->string,
                       p->type == GR_PT_BOOL ? "true or false" : p->type == GR_PT_ENUM ? "a string"
                       : p->type == GR_PT_RGB ? "[r, g, b] or a number" : "a number",
                       gr_json_type_name(v));
    char *val = cJSON_PrintUnformatted(v);
    size_t n = val ? strlen(cls->name) + strlen(v->string) + strlen(val) + 3 : 0;
    *out = val ? malloc(n) : NULL;
    if (*out) snprintf(*out, n, "%s.%s=%s", cls->name, v->string, val);
    free(val);
    return *out ? GR_OK : gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
}

static double num_or_nan(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* The optional "timed" and "score" parts (informative: a wrong type is left out). */
static void read_info(const cJSON *root, gr_preset_info *info)
{
    gr_preset_info_clear(info);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(root, "timed"), *s = cJSON_GetObjectItemCaseSensitive(root, "score");
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(t, "renderer");
    if (cJSON_IsString(r)) snprintf(info->renderer, sizeof info->renderer, "%s", r->valuestring);
    const double w = num_or_nan(t, "width"), h = num_or_nan(t, "height");
    if (w >= 1 && h >= 1 && w < 1e6 && h < 1e6) info->timing_width = (int)w, info->timing_height = (int)h;
    info->time_ms = num_or_nan(t, "time_ms");
    info->budget_ms = num_or_nan(s, "budget_ms");
    info->test_error = num_or_nan(s, "test_error");
    info->train_error = num_or_nan(s, "train_error");
    info->eq_blur_px = num_or_nan(s, "eq_blur_px");
}

gr_status gr_preset_load(const char *path, gr_preset *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    char *text = NULL;
    cJSON *root = NULL;
    gr_status st = gr_json_read_file(path, "preset", PRESET_MAX_BYTES, &text, err);
    if (st == GR_OK) st = gr_json_parse(text, path, &root, err);
    free(text);
    if (st != GR_OK) return st;
    const cJSON *tech = cJSON_GetObjectItemCaseSensitive(root, "technique");
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(root, "settings");
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "godrays_preset");
    const gr_technique_class *cls = cJSON_IsString(tech) ? gr_technique_find(tech->valuestring) : NULL;
    if (!cJSON_IsObject(root)) st = gr_fail(err, GR_E_INPUT, "%s: expected a JSON object, got %s", path, gr_json_type_name(root));
    else if (ver && !(cJSON_IsNumber(ver) && ver->valuedouble == GR_PRESET_VERSION))
        st = gr_fail(err, GR_E_INPUT, "%s: godrays_preset: expected %d (this version's presets)", path, GR_PRESET_VERSION);
    else if (!cJSON_IsString(tech))
        st = gr_fail(err, GR_E_INPUT, "%s: technique: expected a technique's name, got %s", path, gr_json_type_name(tech));
    else if (!cls)
        st = gr_fail(err, GR_E_INPUT, "%s: technique: unknown technique '%s' (`godrays techniques` lists them; a user "
                     "technique needs --technique-dir)", path, tech->valuestring);
    else if (!cJSON_IsObject(set))
        st = gr_fail(err, GR_E_INPUT, "%s: settings: expected an object of KEY: VALUE, got %s", path, gr_json_type_name(set));
    for (const cJSON *v = st == GR_OK ? set->child : NULL; v && st == GR_OK; v = v->next) {
        if (out->n_sets >= GR_PRESET_MAX_SETS) {
            st = gr_fail(err, GR_E_INPUT, "%s: settings: more than %d settings", path, GR_PRESET_MAX_SETS);
            break;
        }
        st = setting_override(path, cls, v, &out->sets[out->n_sets], err);
        if (st == GR_OK) out->n_sets++;
    }
    if (st == GR_OK) {
        snprintf(out->technique, sizeof out->technique, "%s", cls->name);
        read_info(root, &out->info);
    } else {
        gr_preset_free(out);
    }
    cJSON_Delete(root);
    return st;
}

void gr_preset_free(gr_preset *p)
{
    if (!p) return;
    for (int i = 0; i < p->n_sets; i++) free(p->sets[i]);
    p->n_sets = 0;
}

gr_status gr_preset_apply(const gr_preset *p, const gr_technique_class *cls, void *settings, gr_error *err)
{
    for (int i = 0; i < p->n_sets; i++) {
        const char *dot = strchr(p->sets[i], '.'), *eq = dot ? strchr(dot, '=') : NULL;
        if (!dot || !eq) continue;
        char key[128];
        snprintf(key, sizeof key, "%.*s", (int)(eq - dot - 1), dot + 1);
        cJSON *v = cJSON_Parse(eq + 1);
        const gr_param *prm = gr_param_find(cls->params, key);
        gr_status st = GR_OK;
        if (!v || !prm) st = gr_fail(err, GR_E_INPUT, "preset: %s: not a setting of %s", key, cls->name);
        else if (cJSON_IsString(v)) st = gr_param_set_enum(cls->params, settings, key, v->valuestring, err);
        else if (cJSON_IsBool(v)) st = gr_param_set_number(cls->params, settings, key, -1, cJSON_IsTrue(v) ? 1 : 0, err);
        else if (cJSON_IsArray(v))
            for (int c = 0; c < 3 && st == GR_OK; c++)
                st = gr_param_set_number(cls->params, settings, key, c, cJSON_GetArrayItem(v, c)->valuedouble, err);
        else st = gr_param_set_number(cls->params, settings, key, -1, v->valuedouble, err);
        cJSON_Delete(v);
        if (st != GR_OK) return st;
    }
    return GR_OK;
}
