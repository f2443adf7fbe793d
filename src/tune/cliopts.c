/* Shared options of sweep and tune (cliopts.h). */
#include "tune/cliopts.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The options after --metric and --objective (which list the registry's keys). */
static const char help_rest[] =
    "  --technique NAME     the real-time technique (default: the one the parameters name, else\n"
    "                       the first of `godrays techniques`); its settings are NAME.KEY\n"
    "  --technique-dir DIR  add the user technique in DIR (its manifest.json; repeatable)\n"
    "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
    "  --fit MODE           score the technique after a least-squares fit of its image: scale\n"
    "                       (one factor a = <t,r>/<t,t>; a bare --fit), rgb (one per channel) or\n"
    "                       none (= --no-fit); default: scale, unless its gain setting (e.g.\n"
    "                       intensity) is a parameter: none\n"
    "  --rgb-per-channel    tune the technique's colour too: score after the per-channel fit\n"
    "                       (--fit rgb) and fold the three fitted factors into its RGB gain\n"
    "                       setting (e.g. intensity) in the snippet; exit 2 for a technique whose\n"
    "                       gain is one number (docs/tuning.md)\n"
    "  --normalize          divide a metric in image units (rmse, msrmse) by each case's mean\n"
    "                       reference Y, so that every frame and view weighs the same in the mean\n"
    "  --preset FILE        apply a preset's settings as overrides (docs/tuning.md \"Presets\")\n"
    "  --set KEY=VALUE      override a scene value before validation (repeatable), e.g.\n"
    "                       reference.spp=2 or NAME.KEY=V\n"
    "  --size WxH           image size (camera.width/height)\n"
    "  --frames A:B:S       frames A, A+S, ..., B of the animated waves at water.time_s + frame/fps\n"
    "  --fps F              frames per second for --frames (default 30)\n"
    "  --times T1,T2,...    water times (s) instead of --frames\n"
    "  --view YAW,PITCH     an extra camera view (degrees, the scene camera's position and fov;\n"
    "                       repeatable; the scene's own view is always included)\n"
    "  --no-cache           render the ground truths even if cached, and do not store them\n"
    "  --max-memory SIZE    refuse (exit 2) a ground truth estimated to need more (e.g. 8G;\n"
    "                       default $GODRAYS_MAX_MEMORY, else 80 % of the memory)\n"
    "  --gl-platform P      auto, surfaceless or device\n"
    "  --yes                start more than 20000 technique renders (without it such a run is\n"
    "                       refused before the ground truths; docs/tuning.md \"Budgets\")\n"
    "  -q, --quiet          no progress messages\n";

const char *gr_tune_cli_help(void)
{
    static char text[4096];
    char keys[512], wrapped[768];
    gr_metric_keys(keys, sizeof keys, ", ", 1);
    /* the keys wrapped under the option column */
    size_t w = 0, col = 23;
    w += (size_t)snprintf(wrapped + w, sizeof wrapped - w, "%23s", "");
    for (char *save = NULL, *t = strtok_r(keys, " ", &save); t && w < sizeof wrapped; t = strtok_r(NULL, " ", &save)) {
        if (col + strlen(t) + 1 > 96) w += (size_t)snprintf(wrapped + w, sizeof wrapped - w, "\n%23s", ""), col = 23;
        if (w < sizeof wrapped) w += (size_t)snprintf(wrapped + w, sizeof wrapped - w, "%s%s", col > 23 ? " " : "", t);
        col += strlen(t) + 1;
    }
    snprintf(text, sizeof text,
             "  -o, --output DIR     report folder (default: out/SCENE_NAME/COMMAND)\n"
             "  --metric M           the error, a key of the metric registry (docs/metrics.md):\n"
             "%s\n"
             "                       (rmse: sweep's default; a higher-is-better metric is scored as\n"
             "                       best - value, ssim as 1 - SSIM; flip: mean HDR-FLIP)\n"
             "  --objective W        a weighted sum instead (tune's default: " GR_TUNE_DEFAULT_OBJECTIVE "),\n"
             "                       e.g. rmse=1,structure=1,flip=0.5: each class\n"
             "                       dimensionless (those in image units, rmse, msrmse, relative to the\n"
             "                       mean reference Y), the weights normalized to sum 1 (docs/tuning.md)\n"
             "%s",
             wrapped, help_rest);
    return text;
}

void gr_tune_cli_init(gr_tune_cli *c)
{
    memset(c, 0, sizeof *c);
    c->metric = GR_METRIC_RMSE;
    c->fit = -1;
    c->fps = 30.0;
    c->so.use_cache = 1;
    c->so.progress = 1;
}

static int needs_value(const char *a)
{
    static const char *const with_value[] = {"--metric", "--frames",    "--fps",
                                             "--times",  "--view",      "--technique", "--objective"};
    for (size_t k = 0; k < sizeof with_value / sizeof with_value[0]; k++)
        if (!strcmp(a, with_value[k])) return 1;
    return 0;
}

int gr_tune_cli_option(gr_tune_cli *c, int argc, char **argv, int *i, gr_error *err)
{
    const char *a = argv[*i];
    if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
        c->quiet = 1;
        return 1;
    }
    if (!strcmp(a, "--yes")) {
        c->yes = 1;
        return 1;
    }
    if (!strcmp(a, "--normalize")) {
        c->normalize = 1;
        return 1;
    }
    if (!strcmp(a, "--no-cache")) {
        c->so.use_cache = 0;
        return 1;
    }
    if (!strcmp(a, "--rgb-per-channel")) {
        c->rgb_per_channel = 1;
        return 1;
    }
    gr_fit_mode fit;
    const int fr = gr_fit_mode_option(argc, argv, i, &fit, err);
    if (fr > 0) c->fit = (int)fit;
    if (fr) return fr;
    if (!needs_value(a)) return 0;
    if (*i + 1 >= argc) {
        gr_fail(err, GR_E_USAGE, "%s needs a value", a);
        return -1;
    }
    const char *v = argv[++*i];
    gr_status st = GR_OK;
    if (!strcmp(a, "--metric")) {
        st = gr_tune_metric_parse(a, v, &c->metric, err);
    } else if (!strcmp(a, "--objective")) {
        st = gr_tune_weights_parse(a, v, c->weights, err);
        if (st == GR_OK) c->metric = GR_TM_WEIGHTED;
    } else if (!strcmp(a, "--technique")) {
        c->technique_name = v; /* looked up in gr_tune_cli_open, after --technique-dir */
    } else if (!strcmp(a, "--frames")) {
        c->frames_spec = v;
    } else if (!strcmp(a, "--times")) {
        c->times_spec = v;
    } else if (!strcmp(a, "--fps")) {
        char *end = NULL;
        errno = 0;
        double f = strtod(v, &end);
        if (errno || end == v || *end || !isfinite(f) || !(f > 0))
            st = gr_fail(err, GR_E_USAGE, "--fps %s: expected a number > 0", v);
        c->fps = f;
    } else if (!strcmp(a, "--view")) {
        if (c->so.n_views >= GR_TUNE_MAX_VIEWS)
            st = gr_fail(err, GR_E_USAGE, "--view: more than %d extra views", GR_TUNE_MAX_VIEWS);
        else if ((st = gr_tune_parse_view(a, v, &c->so.views[c->so.n_views], err)) == GR_OK)
            c->so.n_views++;
    }
    return st == GR_OK ? 1 : -1;
}

gr_status gr_tune_cli_finish(gr_tune_cli *c, gr_error *err)
{
    gr_status st;
    if (c->frames_spec && c->times_spec) return gr_fail(err, GR_E_USAGE, "--frames and --times: give one of them");
    if (c->frames_spec) {
        st = gr_tune_parse_frames("--frames", c->frames_spec, c->fps, c->so.times, GR_TUNE_MAX_TIMES, &c->so.n_times, err);
        if (st != GR_OK) return st;
        c->so.times_relative = 1;
    }
    if (c->times_spec) {
        st = gr_tune_parse_times("--times", c->times_spec, c->so.times, GR_TUNE_MAX_TIMES, &c->so.n_times, err);
        if (st != GR_OK) return st;
    }
    c->so.progress = !c->quiet;
    return GR_OK;
}

gr_status gr_tune_cli_open(gr_tune_cli *c, const gr_tune_param *params, int n_params, gr_tune_session *s,
                           gr_tune_problem *p, gr_error *err)
{
    const gr_technique_class *cls = n_params > 0 ? params[0].cls : gr_technique_at(0);
    if (c->technique_name) {
        const gr_technique_class *one[1];
        int n = 0;
        if (strchr(c->technique_name, ','))
            return gr_fail(err, GR_E_USAGE, "--technique %s: one technique expected", c->technique_name);
        gr_status lst = gr_technique_parse_list("--technique", c->technique_name, one, 1, &n, err);
        if (lst != GR_OK) return lst;
        if (n != 1) return gr_fail(err, GR_E_USAGE, "--technique: no technique given");
        cls = one[0];
    }
    for (int k = 0; k < n_params; k++)
        if (params[k].cls != cls)
            return gr_fail(err, GR_E_USAGE, "%s: not a setting of technique %s (its settings are %s.KEY)", params[k].key,
                           cls->name, cls->name);
    c->so.technique = cls;
    if (c->rgb_per_channel) {
        const gr_param *gain = cls->gain_key ? gr_param_find(cls->params, cls->gain_key) : NULL;
        if (!gain || gain->type != GR_PT_RGB)
            return gr_fail(err, GR_E_USAGE, "--rgb-per-channel: technique %s has no per-channel colour setting (%s%s%s); "
                           "--fit rgb scores it after a per-channel fit without tuning its colour", cls->name,
                           gain ? "its gain " : "no gain setting", gain ? gain->name : "", gain ? " is one number" : "");
        if (c->fit >= 0 && c->fit != GR_FIT_RGB)
            return gr_fail(err, GR_E_USAGE, "--rgb-per-channel folds the per-channel fit into %s.%s: it needs --fit rgb, "
                           "not --fit %s", cls->name, gain->name, gr_fit_mode_name((gr_fit_mode)c->fit));
        c->fit = GR_FIT_RGB;
    }
    if (c->fit < 0) {
        c->fit = GR_FIT_SCALE;
        for (int k = 0; k < n_params; k++)
            if (cls->gain_key && !strcmp(params[k].p->name, cls->gain_key)) c->fit = GR_FIT_NONE;
    }
    gr_status st = gr_tune_session_open(&c->so, s, err);
    if (st != GR_OK) return st;
    gr_tune_session_problem(s, p);
    p->n_params = n_params;
    memcpy(p->params, params, (size_t)n_params * sizeof *params);
    p->metric = c->metric;
    memcpy(p->weights, c->weights, sizeof p->weights);
    p->fit = c->fit;
    p->rgb_per_channel = c->rgb_per_channel;
    p->normalize = c->normalize;
    return gr_tune_problem_init(p, err);
}

void gr_tune_search_defaults(gr_opt_options *o, int n_params, const double *x0)
{
    memset(o, 0, sizeof *o);
    o->method = GR_OPT_NELDER_MEAD;
    o->n_starts = 4;
    o->x0 = x0;
    o->max_evals = 60 + 40 * n_params;
    o->coarse = 16 * n_params;
    o->polish = o->max_evals;
    o->screen = 4 * o->n_starts;
    o->screen_evals = 20 + 10 * n_params;
    o->seed = 0;
}
