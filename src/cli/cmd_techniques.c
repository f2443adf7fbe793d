/* godrays techniques [NAME...] [--json] [--technique-dir DIR]...: the real-time techniques
 * this build knows (built-in and the user's), or only those named, and every setting of each
 * (src/realtime/technique.h). */
#include "cli/cli.h"
#include "cli/args.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "realtime/technique.h"
#include "scene/params.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays techniques [NAME...] [--json] [--technique-dir DIR]...\n"
            "\n"
            "Lists the real-time god-ray techniques (the built-in ones and those added with\n"
            "--technique-dir; only the NAMEs given, if any) with a one-line description and every\n"
            "setting of each: the key of its scene section (NAME.KEY, as --set and --param take\n"
            "it), type (number, int, bool, rgb, choice, int64: a manifest's own names), valid\n"
            "range, default, unit, default tuning box and a one-line doc.\n"
            "\n"
            "options:\n"
            "  --json               one JSON document instead of text\n"
            "  --technique-dir DIR  add the user technique in DIR (its manifest.json; repeatable)\n"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage or a bad technique folder.\n");
}

static const char *type_name(gr_param_type t)
{
    switch (t) {
    case GR_PT_DOUBLE: return "number";
    case GR_PT_INT: return "int"; /* a user manifest's own type names (docs/techniques.md) */
    case GR_PT_BOOL: return "bool";
    case GR_PT_RGB: return "rgb";
    case GR_PT_ENUM: return "choice";
    case GR_PT_U64: return "int64";
    }
    return "?";
}

/* The default as the scene file would hold it. */
static void default_text(const gr_param *p, char *buf, size_t n)
{
    char num[40];
    if (p->flags & GR_PF_FROM_SCENE) {
        snprintf(buf, n, "from %s", p->scene_source ? p->scene_source : "the scene");
    } else if (p->type == GR_PT_BOOL) {
        snprintf(buf, n, "%s", p->def != 0 ? "true" : "false");
    } else if (p->type == GR_PT_ENUM) {
        const char *nm = gr_param_enum_name(p, (int)p->def);
        snprintf(buf, n, "%s", nm ? nm : "?");
    } else {
        snprintf(buf, n, "%s", gr_format_double(p->def, num, sizeof num));
    }
}

static cJSON *param_json(const gr_param *p)
{
    char buf[256];
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddStringToObject(o, "key", p->name);
    cJSON_AddStringToObject(o, "type", type_name(p->type));
    cJSON_AddStringToObject(o, "range", gr_param_range_text(p, buf, sizeof buf));
    if (isfinite(p->min)) cJSON_AddNumberToObject(o, "min", p->min);
    if (isfinite(p->max)) cJSON_AddNumberToObject(o, "max", p->max);
    cJSON_AddBoolToObject(o, "min_exclusive", (p->flags & GR_PF_MIN_EXCL) != 0);
    cJSON_AddBoolToObject(o, "max_exclusive", (p->flags & GR_PF_MAX_EXCL) != 0);
    if (p->flags & GR_PF_FROM_SCENE) {
        cJSON_AddNullToObject(o, "default");
        cJSON_AddStringToObject(o, "default_from", p->scene_source ? p->scene_source : "");
    } else if (p->type == GR_PT_BOOL) {
        cJSON_AddBoolToObject(o, "default", p->def != 0);
    } else if (p->type == GR_PT_ENUM) {
        const char *nm = gr_param_enum_name(p, (int)p->def);
        cJSON_AddStringToObject(o, "default", nm ? nm : "");
    } else {
        cJSON_AddNumberToObject(o, "default", p->def);
    }
    if (p->type == GR_PT_ENUM && p->enum_names) {
        cJSON *ch = cJSON_AddArrayToObject(o, "choices");
        for (int i = 0; ch && p->enum_names[i]; i++) cJSON_AddItemToArray(ch, cJSON_CreateString(p->enum_names[i]));
    }
    cJSON_AddStringToObject(o, "unit", p->unit ? p->unit : "");
    cJSON_AddStringToObject(o, "doc", p->doc ? p->doc : "");
    if (p->tune_hi > p->tune_lo) {
        double box[2] = {p->tune_lo, p->tune_hi};
        cJSON_AddItemToObject(o, "tune_box", cJSON_CreateDoubleArray(box, 2));
    }
    return o;
}

/* Whether technique c is listed: no names given, or c among them. */
static int wanted(const gr_technique_class *c, char **names, int n)
{
    for (int k = 0; k < n; k++)
        if (!strcmp(names[k], c->name)) return 1;
    return n == 0;
}

static int print_json(char **names, int n_names)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *arr = root ? cJSON_AddArrayToObject(root, "techniques") : NULL;
    int ok = arr != NULL;
    for (int i = 0; ok && i < gr_technique_count(); i++) {
        const gr_technique_class *c = gr_technique_at(i);
        if (!wanted(c, names, n_names)) continue;
        cJSON *t = cJSON_CreateObject();
        ok = t && cJSON_AddItemToArray(arr, t);
        if (!ok) break;
        cJSON_AddStringToObject(t, "name", c->name);
        cJSON_AddStringToObject(t, "description", c->description ? c->description : "");
        cJSON_AddStringToObject(t, "origin", c->origin ? c->origin : "built-in");
        char why[512];
        int avail = gr_technique_available(c, why, sizeof why);
        cJSON_AddBoolToObject(t, "available", avail);
        if (!avail) cJSON_AddStringToObject(t, "unavailable_reason", why);
        cJSON_AddBoolToObject(t, "by_name_only", c->by_name_only != 0);
        if (c->gain_key) cJSON_AddStringToObject(t, "gain_key", c->gain_key);
        else cJSON_AddNullToObject(t, "gain_key");
        cJSON *ld = cJSON_AddArrayToObject(t, "ladder"); /* pareto's speed/quality levels */
        for (int k = 0; ld && k < c->n_ladder; k++) {
            cJSON *lv = cJSON_CreateObject();
            if (!lv || !cJSON_AddItemToArray(ld, lv)) {
                cJSON_Delete(lv);
                ok = 0;
                break;
            }
            cJSON_AddStringToObject(lv, "settings", c->ladder[k].settings ? c->ladder[k].settings : "");
            cJSON_AddBoolToObject(lv, "quick", c->ladder[k].quick != 0);
        }
        cJSON *ps = cJSON_AddArrayToObject(t, "settings");
        for (size_t k = 0; ps && k < c->params->count; k++) {
            cJSON *po = param_json(&c->params->params[k]);
            ok = po && cJSON_AddItemToArray(ps, po);
        }
        ok = ok && ps;
    }
    char *text = ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        gr_error err;
        gr_fail(&err, GR_E_NOMEM, "out of memory printing the techniques");
        return gr_cli_report("techniques", &err);
    }
    printf("%s\n", text);
    cJSON_free(text);
    return 0;
}

static void print_text(char **names, int n_names)
{
    for (int i = 0, shown = 0; i < gr_technique_count(); i++) {
        const gr_technique_class *c = gr_technique_at(i);
        if (!wanted(c, names, n_names)) continue;
        printf("%s%s  (%s)\n  %s\n", shown++ ? "\n" : "", c->name, c->origin ? c->origin : "built-in",
               c->description ? c->description : "");
        char why[512];
        if (!gr_technique_available(c, why, sizeof why)) printf("  unavailable here: %s\n", why);
        if (c->by_name_only) printf("  not in the default list of run/pareto: runs when named\n");
        int kw = 24; /* the key column fits the longest NAME.KEY */
        for (size_t k = 0; k < c->params->count; k++) {
            int w = (int)(strlen(c->name) + 1 + strlen(c->params->params[k].name));
            if (w > kw) kw = w;
        }
        printf("  %-*s %-9s %-18s %-22s %-7s %s\n", kw, "setting", "type", "range", "default", "unit", "doc");
        for (size_t k = 0; k < c->params->count; k++) {
            const gr_param *p = &c->params->params[k];
            char key[96], range[160], def[96], doc[512];
            snprintf(key, sizeof key, "%s.%s", c->name, p->name);
            gr_param_range_text(p, range, sizeof range);
            default_text(p, def, sizeof def);
            if (p->tune_hi > p->tune_lo) {
                char lo[32], hi[32];
                snprintf(doc, sizeof doc, "%s [tune %s..%s]", p->doc ? p->doc : "",
                         gr_format_double(p->tune_lo, lo, sizeof lo), gr_format_double(p->tune_hi, hi, sizeof hi));
            } else {
                snprintf(doc, sizeof doc, "%s", p->doc ? p->doc : "");
            }
            printf("  %-*s %-9s %-18s %-22s %-7s %s\n", kw, key, type_name(p->type), range, def,
                   p->unit && p->unit[0] ? p->unit : "-", doc);
        }
    }
}

static int techniques_args(gr_args *args, char **names, int *n_names, int *json);

static int techniques_with(gr_args *args)
{
    int json = 0, rc = 0, n_names = 0;
    char **names = calloc((size_t)args->argc + 1, sizeof *names);
    if (!names) return gr_cli_usage_error("techniques", "out of memory");
    rc = techniques_args(args, names, &n_names, &json);
    if (rc == 0) rc = gr_args_add_technique_dirs(args);
    for (int k = 0; rc == 0 && k < n_names; k++)
        if (!gr_technique_find(names[k]))
            rc = gr_cli_usage_error("techniques", "unknown technique '%s' (godrays techniques lists them; a user "
                                                  "technique needs its --technique-dir)", names[k]);
    if (rc == 0) {
        if (json) rc = print_json(names, n_names);
        else print_text(names, n_names);
    }
    free(names);
    return rc < 0 ? 0 : rc;
}

/* The arguments: -1 after --help (printed), else an exit code. */
static int techniques_args(gr_args *args, char **names, int *n_names, int *json)
{
    int rc;
    for (; args->i < args->argc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return -1;
        } else if (!strcmp(a, "--json")) {
            *json = 1;
        } else if (!strcmp(a, "--technique-dir")) {
            if ((rc = gr_args_take_technique_dir(args)) != 0) return rc;
        } else if (a[0] != '-') {
            names[(*n_names)++] = args->argv[args->i];
        } else {
            return gr_cli_usage_error("techniques", "unknown argument %s", a);
        }
    }
    return 0;
}

int cmd_techniques(int argc, char **argv)
{
    return gr_args_main("techniques", argc, argv, techniques_with);
}
