/* The edit-to-verdict loop (watch.h): inotify, the debounce, one render and its comparison. */
#define _GNU_SOURCE
#include "watch/watch.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <time.h>
#include <unistd.h>

#include "compare/diffmap.h"
#include "compare/flip.h"
#include "compare/metrics.h"
#include "compare/registry.h"
#include "image/png.h"
#include "realtime/toolkit.h"
#include "realtime/usertech.h"
#include "report/profile.h"
#include "report/report.h"
#include "scene/sections.h"

#define WATCH_DEBOUNCE_MS 100.0

/* What the loop keeps between renders. */
typedef struct watch_ctx {
    const gr_watch_options *o;
    gr_watch_server *srv;
    gr_gl *gl;                    /* made at the first render, remade after a time-out */
    double exposure;              /* the truth's, fixed for the session ("exposure fixed") */
    float *angles;                /* the structure metric's angles (report/profile.h) */
    gr_structure_options so;
    int with_structure;
    gr_flip_reference *fref;      /* the truth's half of HDR-FLIP, made at the first score */
    int id;                       /* renders so far */
    int truth_published;
} watch_ctx;

/* One render's outcome. */
typedef struct outcome {
    const char *stage;            /* NULL: rendered and scored; else "manifest", "compile", "render", ... */
    gr_error terr;                /* the technique's error (stage != NULL) */
    char name[GR_TECH_NAME_MAX];  /* the technique as loaded ("" when its manifest failed) */
    const char *note;             /* NULL, or why the settings are the manifest's defaults */
    gr_technique_stats stats;
    gr_metrics m;
    gr_image *img;
} outcome;

/* 1 if b's settings have the keys, types and layout of a's (so the scene's values of a, with
 * their --set overrides, fit b). */
static int same_settings(const gr_technique_class *a, const gr_technique_class *b)
{
    if (strcmp(a->name, b->name) || a->settings_size != b->settings_size || a->params->count != b->params->count)
        return 0;
    for (size_t i = 0; i < a->params->count; i++) {
        const gr_param *p = &a->params->params[i], *q = &b->params->params[i];
        if (strcmp(p->name, q->name) || p->type != q->type || p->offset != q->offset) return 0;
    }
    return 1;
}

/* Loads the folder again and renders it once into out->img (a failure fills out->stage). */
static gr_status render_once(watch_ctx *c, outcome *out, gr_error *err)
{
    const gr_watch_options *o = c->o;
    gr_technique_class *cls = NULL;
    gr_technique *t = NULL;
    gr_section_store store;
    if (gr_usertech_load(o->dir, &cls, &out->terr) != GR_OK) {
        out->stage = "manifest";
        return GR_OK;
    }
    snprintf(out->name, sizeof out->name, "%s", cls->name);
    const void *settings = gr_technique_scene_settings(o->cls, o->scene);
    if (!same_settings(o->cls, cls)) {
        gr_param_defaults(cls->params, store.bytes); /* a new table: its own defaults, not the scene's */
        settings = store.bytes;
        out->note = "the manifest's settings changed: their defaults are used (restart watch for the scene's and --set)";
    }
    if (!c->gl) {
        gr_gl_options glo = {.platform = o->platform};
        if (gr_gl_create(&glo, &c->gl, &out->terr) != GR_OK) out->stage = "GL";
    }
    if (!out->stage && gr_technique_create(cls, c->gl, NULL, &t, &out->terr) != GR_OK)
        out->stage = out->terr.status == GR_E_GL ? "compile" : "create";
    if (!out->stage) {
        out->img = gr_image_create(o->scene->camera.width, o->scene->camera.height, 3, NULL);
        if (!out->img) {
            gr_technique_destroy(t);
            gr_usertech_free(cls);
            return gr_fail(err, GR_E_NOMEM, "watch: out of memory for the image");
        }
        if (gr_technique_render(t, o->scene, settings, out->img, &out->stats, &out->terr) != GR_OK) out->stage = "render";
    }
    gr_technique_destroy(t);
    if (out->terr.status == GR_E_TIMEOUT) { /* the context is abandoned: a new one next time */
        gr_gl_destroy(c->gl);
        c->gl = NULL;
    }
    gr_usertech_free(cls);
    return GR_OK;
}

/* The metrics against the truth, as `godrays run` computes them (fit, structure, stderr). */
static gr_status score(watch_ctx *c, outcome *out, gr_error *err)
{
    gr_metrics_options mopt = {0};
    mopt.fit_scale = GR_FIT_SCALE; /* a technique's intensity is an arbitrary factor */
    if (c->with_structure) mopt.structure = &c->so;
    gr_flip_options fo = {.mode = GR_FLIP_HDR}; /* the registry's FLIP mean too (the page lists it) */
    mopt.flip = &fo;
    mopt.flip_ref = &c->fref; /* kept for every render of the session (the same numbers) */
    const gr_meta_item *dof = c->o->truth_meta ? gr_meta_get(c->o->truth_meta, "godrays:stderr_dof") : NULL;
    if (dof && dof->type != GR_META_STRING && dof->num >= 1.0) mopt.stderr_dof = (int)dof->num;
    return gr_metrics_compute(c->o->truth, out->img, &mopt, &out->m, err);
}

/* A display image (gr_report_display etc.) as the PNG blob `name`; img is destroyed. */
static gr_status to_png(gr_image *img, const char *name, gr_watch_blob *b, gr_error *err)
{
    unsigned char *buf = NULL;
    size_t len = 0;
    gr_status st = gr_png_encode_display(img, &buf, &len, err);
    gr_image_destroy(img);
    b->name = name;
    b->data = buf;
    b->len = len;
    return st;
}

/* The PNGs of a scored render: the render at the truth's exposure, |dY| after the fit, FLIP. */
static gr_status make_images(watch_ctx *c, const outcome *out, gr_watch_blob *b, int *n, gr_error *err)
{
    const gr_image *truth = c->o->truth;
    const double a = out->m.have_fit ? out->m.fit.scale : 1.0;
    gr_image *d = NULL;
    gr_status st = gr_report_display(out->img, c->exposure, &d, err);
    if (st == GR_OK) st = to_png(d, "test", &b[(*n)++], err);
    gr_diffmap_options dopt = {.kind = GR_DIFFMAP_ABS, .scale = a, .stderr_bound = out->m.stderr_bound};
    gr_diffmap_info info;
    if (st == GR_OK && (st = gr_diffmap_create(truth, out->img, &dopt, &d, &info, err)) == GR_OK)
        st = to_png(d, "diff", &b[(*n)++], err);
    if (st == GR_OK) {
        float *fm = malloc((size_t)truth->width * (size_t)truth->height * sizeof(float));
        gr_flip_options fo = {.mode = GR_FLIP_HDR, .test_scale = a};
        if (gr_flip_reference_matches(c->fref, truth, &fo)) fo.reference = c->fref;
        gr_flip_result fres;
        int undefined = 0; /* a black truth: no FLIP, a black map */
        st = fm ? gr_flip_compute_defined(truth, out->img, &fo, fm, &fres, &undefined, NULL, 0, err)
                : gr_fail(err, GR_E_NOMEM, "watch: out of memory for FLIP");
        if (st == GR_OK && (st = gr_flip_heatmap(fm, truth->width, truth->height, &d, err)) == GR_OK)
            st = to_png(d, "flip", &b[(*n)++], err);
        free(fm);
    }
    return st;
}

/* The registry's metrics of a scored render (raw and after the fit) into the JSON. */
static int add_metrics(cJSON *root, const gr_metrics *m)
{
    cJSON *arr = cJSON_AddArrayToObject(root, "metrics");
    if (!arr) return 0;
    for (int i = 0; i < gr_metric_count(); i++) {
        const gr_metric_desc *d = gr_metric_at(i);
        cJSON *it = cJSON_CreateObject();
        if (!it || !cJSON_AddItemToArray(arr, it)) return 0;
        const double raw = gr_metric_value(&m->raw, i), fit = m->have_fit ? gr_metric_value(&m->fit, i) : NAN;
        if (!cJSON_AddStringToObject(it, "key", d->key) || !cJSON_AddStringToObject(it, "label", d->label) ||
            !(isfinite(raw) ? cJSON_AddNumberToObject(it, "raw", raw) : cJSON_AddNullToObject(it, "raw")) ||
            !(isfinite(fit) ? cJSON_AddNumberToObject(it, "fit", fit) : cJSON_AddNullToObject(it, "fit")))
            return 0;
    }
    const gr_metrics_set *s = m->have_fit ? &m->fit : &m->raw;
    const double v = gr_metric_value(s, GR_METRIC_VERDICT);
    return cJSON_AddNumberToObject(root, "scale", s->scale) &&
           (isfinite(v) ? cJSON_AddNumberToObject(root, "verdict", v) : cJSON_AddNullToObject(root, "verdict")) != NULL;
}

/* The state document of render c->id; NULL for lack of memory. */
static char *state_json(const watch_ctx *c, const outcome *out, const char *changed)
{
    char when[16];
    time_t now = time(NULL);
    struct tm tmv;
    strftime(when, sizeof when, "%H:%M:%S", localtime_r(&now, &tmv));
    cJSON *root = cJSON_CreateObject();
    int ok = root && cJSON_AddNumberToObject(root, "id", c->id) && cJSON_AddBoolToObject(root, "ok", !out->stage) &&
             cJSON_AddStringToObject(root, "stage", out->stage ? out->stage : "") &&
             cJSON_AddStringToObject(root, "technique", out->name) && cJSON_AddStringToObject(root, "changed", changed) &&
             cJSON_AddStringToObject(root, "time", when) &&
             cJSON_AddStringToObject(root, "message", out->stage ? out->terr.msg : "") &&
             cJSON_AddStringToObject(root, "note", out->note ? out->note : "") &&
             cJSON_AddNumberToObject(root, "width", c->o->scene->camera.width) &&
             cJSON_AddNumberToObject(root, "height", c->o->scene->camera.height);
    if (ok && !out->stage) ok = cJSON_AddNumberToObject(root, "wall_ms", out->stats.wall_ms) && add_metrics(root, &out->m);
    char *s = ok ? cJSON_PrintUnformatted(root) : NULL;
    cJSON_Delete(root);
    return s;
}

/* The caller's log line of render c->id. */
static void log_line(const watch_ctx *c, const outcome *out, const char *changed)
{
    if (!c->o->log) return;
    char line[GR_ERROR_MSG_MAX + 128];
    if (out->stage) {
        /* the whole message: a compiler's log is one diagnostic per line */
        snprintf(line, sizeof line, "render %d (%s): %s error: %s", c->id, changed, out->stage, out->terr.msg);
    } else {
        const gr_metrics_set *s = out->m.have_fit ? &out->m.fit : &out->m.raw;
        snprintf(line, sizeof line, "render %d (%s): %s verdict %.4g (scale %.4g), %.1f ms%s%s", c->id, changed,
                 out->name, gr_metric_value(s, GR_METRIC_VERDICT), s->scale, out->stats.wall_ms,
                 out->note ? "; " : "", out->note ? out->note : "");
    }
    c->o->log(c->o->user, line);
}

/* One round: render, score, images, publish. Errors only for what ends the loop. */
static gr_status evaluate(watch_ctx *c, const char *changed, gr_error *err)
{
    outcome out;
    memset(&out, 0, sizeof out);
    out.terr.status = GR_OK;
    gr_watch_blob blobs[GR_WATCH_MAX_IMAGES];
    int nb = 0;
    c->id++;
    gr_status st = render_once(c, &out, err);
    if (st == GR_OK && !out.stage) st = score(c, &out, err);
    if (st == GR_OK && !out.stage) st = make_images(c, &out, blobs, &nb, err);
    if (st == GR_OK && !c->truth_published) { /* once: it does not change */
        gr_image *d = NULL;
        if ((st = gr_report_display(c->o->truth, c->exposure, &d, err)) == GR_OK) st = to_png(d, "truth", &blobs[nb++], err);
    }
    char *json = st == GR_OK ? state_json(c, &out, changed) : NULL;
    if (st == GR_OK && !json) st = gr_fail(err, GR_E_NOMEM, "watch: out of memory for the page's state");
    if (st == GR_OK) st = gr_watch_server_publish(c->srv, json, blobs, nb, err);
    if (st == GR_OK) {
        for (int i = 0; i < nb; i++) c->truth_published |= !strcmp(blobs[i].name, "truth");
        log_line(c, &out, changed);
    }
    for (int i = 0; i < nb; i++) free((void *)blobs[i].data);
    free(json);
    gr_image_destroy(out.img);
    return st;
}

/* Reads the pending events; the name of the last one that counts into changed (editors' hidden
 * and backup files do not: ".x.swp", "x~"). Returns 1 if one counted. */
static int read_events(int fd, char *changed, size_t n)
{
    _Alignas(struct inotify_event) char buf[8192];
    int counted = 0;
    for (;;) {
        ssize_t len = read(fd, buf, sizeof buf);
        if (len <= 0) break;
        for (char *p = buf; p < buf + len;) {
            const struct inotify_event *ev = (const struct inotify_event *)p;
            const char *nm = ev->len ? ev->name : "";
            const size_t l = strlen(nm);
            if (l && nm[0] != '.' && nm[l - 1] != '~' && strcmp(nm, "4913")) { /* 4913: vim's probe */
                snprintf(changed, n, "%s", nm);
                counted = 1;
            }
            p += sizeof *ev + ev->len;
        }
    }
    return counted;
}

static gr_status loop(watch_ctx *c, int fd, gr_error *err)
{
    const gr_watch_options *o = c->o;
    const double debounce = o->debounce_ms > 0 ? o->debounce_ms : WATCH_DEBOUNCE_MS;
    char changed[256] = "start";
    gr_status st = evaluate(c, changed, err);
    double due = -1.0; /* when the next render is due (-1: none pending) */
    while (st == GR_OK && !*o->stop) {
        double wait = due < 0 ? 100.0 : due - gr_clock_ms();
        struct pollfd p = {.fd = fd, .events = POLLIN};
        int r = poll(&p, 1, wait < 0 ? 0 : (int)(wait < 100.0 ? wait : 100.0)); /* the stop flag every 0.1 s */
        if (r < 0 && errno != EINTR) return gr_fail(err, GR_E_IO, "%s: poll: %s", o->dir, strerror(errno));
        if (r > 0 && read_events(fd, changed, sizeof changed)) due = gr_clock_ms() + debounce; /* a burst: the last + debounce */
        if (due >= 0 && gr_clock_ms() >= due && !*o->stop) {
            due = -1.0;
            st = evaluate(c, changed, err);
        }
    }
    return st;
}

gr_status gr_watch_run(const gr_watch_options *o, gr_watch_server *srv, gr_error *err)
{
    watch_ctx c;
    memset(&c, 0, sizeof c);
    c.o = o;
    c.srv = srv;
    c.exposure = gr_report_exposure(o->truth, 1.0, 0.99, 0.8); /* the report's choice */
    c.angles = malloc((size_t)o->scene->camera.width * (size_t)o->scene->camera.height * sizeof(float));
    if (!c.angles) return gr_fail(err, GR_E_NOMEM, "watch: out of memory");
    c.with_structure = gr_profile_structure_options(o->scene, c.angles, &c.so);
    gr_status st = GR_OK;
    int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd < 0) st = gr_fail(err, GR_E_IO, "%s: inotify_init1: %s", o->dir, strerror(errno));
    /* a save is a close after writing, or a rename over the file (most editors, sed -i) */
    else if (inotify_add_watch(fd, o->dir, IN_CLOSE_WRITE | IN_MOVED_TO | IN_MOVED_FROM | IN_DELETE) < 0)
        st = gr_fail(err, GR_E_IO, "%s: cannot watch the folder: %s", o->dir, strerror(errno));
    if (st == GR_OK) st = loop(&c, fd, err);
    if (fd >= 0) close(fd);
    gr_gl_destroy(c.gl);
    free(c.angles);
    gr_flip_reference_destroy(c.fref);
    return st;
}
