/* The technique registry and instances (technique.h). */
#include "realtime/technique.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"
#include "realtime/toolkit.h"

/* ---- the built-in techniques: ONE LINE EACH (their header declares the class) -------- */
#include "realtime/shafts.h"
#include "realtime/radial_blur.h"
#include "realtime/slicing.h"
#include "realtime/froxel.h"
#include "realtime/lightrays.h"
#include "realtime/eevee.h"

static const gr_technique_class *const builtins[] = {
    &gr_shafts_class,
    &gr_radial_blur_class,
    &gr_radial_blur_local_class,
    &gr_slicing_class,
    &gr_froxel_class,
    &gr_light_rays_class,
    &gr_eevee_class,
};

/* ---- registry ------------------------------------------------------------------------- */

static const gr_technique_class *classes[GR_TECH_MAX];
static int section_of[GR_TECH_MAX];          /* the class's scene section index */
static gr_section_store defaults[GR_TECH_MAX]; /* for scenes loaded before the class came */
static int n_classes;
static pthread_once_t builtins_once = PTHREAD_ONCE_INIT;
static gr_status builtins_status = GR_OK;
static char builtins_msg[GR_ERROR_MSG_MAX];

static int valid_name(const char *s)
{
    if (!s || !(s[0] >= 'a' && s[0] <= 'z')) return 0;
    size_t n = 0;
    for (; s[n]; n++)
        if (!((s[n] >= 'a' && s[n] <= 'z') || (s[n] >= '0' && s[n] <= '9') || s[n] == '_')) return 0;
    return n < GR_TECH_NAME_MAX;
}

static gr_status register_class(const gr_technique_class *cls, gr_error *err)
{
    if (!cls) return gr_fail(err, GR_E_INPUT, "technique: no class");
    if (!valid_name(cls->name))
        return gr_fail(err, GR_E_INPUT, "technique name '%s': must match [a-z][a-z0-9_]* and be at most %d characters",
                       cls->name ? cls->name : "", GR_TECH_NAME_MAX - 1);
    for (int i = 0; i < n_classes; i++)
        if (!strcmp(classes[i]->name, cls->name))
            return gr_fail(err, GR_E_INPUT, "technique %s: already defined (%s)", cls->name,
                           classes[i]->origin ? classes[i]->origin : "built-in");
    if (!cls->params || !cls->params->section || strcmp(cls->params->section, cls->name))
        return gr_fail(err, GR_E_INPUT, "technique %s: its settings table must be the scene section '%s'", cls->name,
                       cls->name);
    if (cls->settings_size > GR_TECH_SETTINGS_MAX)
        return gr_fail(err, GR_E_INPUT, "technique %s: settings of %zu bytes, at most %d", cls->name,
                       cls->settings_size, GR_TECH_SETTINGS_MAX);
    if (!cls->create || !cls->render || !cls->destroy)
        return gr_fail(err, GR_E_INPUT, "technique %s: create, render and destroy are required", cls->name);
    if (n_classes >= GR_TECH_MAX)
        return gr_fail(err, GR_E_INPUT, "technique %s: too many techniques (at most %d)", cls->name, GR_TECH_MAX);
    int sec = -1;
    gr_status st = gr_sections_add(cls->params, cls->settings_size, &sec, err);
    if (st != GR_OK) return gr_error_prefix(err, "technique %s", cls->name);
    classes[n_classes] = cls;
    section_of[n_classes] = sec;
    gr_param_defaults(cls->params, defaults[n_classes].bytes);
    n_classes++;
    return GR_OK;
}

static void register_builtins(void)
{
    gr_error err = {GR_OK, ""};
    for (size_t i = 0; i < sizeof builtins / sizeof builtins[0]; i++) {
        if (register_class(builtins[i], &err) != GR_OK) {
            /* a programming error in a built-in table: reported by the next registration */
            builtins_status = err.status;
            snprintf(builtins_msg, sizeof builtins_msg, "%s", err.msg);
            return;
        }
    }
}

static void ensure_builtins(void) { pthread_once(&builtins_once, register_builtins); }

int gr_technique_count(void)
{
    ensure_builtins();
    return n_classes;
}

const gr_technique_class *gr_technique_at(int i)
{
    ensure_builtins();
    return i >= 0 && i < n_classes ? classes[i] : NULL;
}

const gr_technique_class *gr_technique_find(const char *name)
{
    ensure_builtins();
    if (!name) return NULL;
    for (int i = 0; i < n_classes; i++)
        if (!strcmp(classes[i]->name, name)) return classes[i];
    return NULL;
}

int gr_technique_index(const gr_technique_class *cls)
{
    ensure_builtins();
    for (int i = 0; i < n_classes; i++)
        if (classes[i] == cls) return i;
    return -1;
}

gr_status gr_technique_register(const gr_technique_class *cls, gr_error *err)
{
    ensure_builtins();
    if (builtins_status != GR_OK) return gr_fail(err, builtins_status, "%s", builtins_msg);
    return register_class(cls, err);
}

static void known_list(char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < n_classes; i++) {
        int w = snprintf(buf + used, n - used, "%s%s", i ? ", " : "", classes[i]->name);
        if (w < 0 || (size_t)w >= n - used) break;
        used += (size_t)w;
    }
}

gr_status gr_technique_parse_list(const char *flag, const char *list, const gr_technique_class **out, int max,
                                  int *n, gr_error *err)
{
    ensure_builtins();
    *n = 0;
    char why[512];
    if (!list || !list[0]) {
        for (int i = 0; i < n_classes && *n < max; i++)
            if (!classes[i]->by_name_only && gr_technique_available(classes[i], why, sizeof why)) out[(*n)++] = classes[i];
        return GR_OK;
    }
    const char *p = list;
    for (;;) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        char name[GR_TECH_NAME_MAX + 8], known[512];
        if (len == 0) return gr_fail(err, GR_E_USAGE, "%s %s: empty technique name", flag, list);
        snprintf(name, sizeof name, "%.*s", (int)(len < sizeof name - 1 ? len : sizeof name - 1), p);
        const gr_technique_class *c = len < GR_TECH_NAME_MAX ? gr_technique_find(name) : NULL;
        if (!c) {
            known_list(known, sizeof known);
            return gr_fail(err, GR_E_USAGE, "%s %s: unknown technique '%s' (known: %s; a user technique needs its "
                           "--technique-dir)", flag, list, name, known);
        }
        for (int i = 0; i < *n; i++)
            if (out[i] == c) return gr_fail(err, GR_E_USAGE, "%s %s: technique '%s' given twice", flag, list, name);
        if (!gr_technique_available(c, why, sizeof why))
            return gr_fail(err, GR_E_USAGE, "%s %s: technique '%s' is unavailable here: %s", flag, list, name, why);
        if (*n >= max) return gr_fail(err, GR_E_USAGE, "%s %s: more than %d techniques", flag, list, max);
        out[(*n)++] = c;
        if (!e) break;
        p = e + 1;
    }
    return GR_OK;
}

int gr_technique_available(const gr_technique_class *cls, char *why, size_t n)
{
    if (n) why[0] = '\0';
    return !cls->available || cls->available(cls, why, n);
}

/* ---- settings ------------------------------------------------------------------------- */

const void *gr_technique_scene_settings(const gr_technique_class *cls, const gr_scene *scene)
{
    int i = gr_technique_index(cls);
    if (i < 0) return NULL;
    const void *s = gr_scene_section_const(scene, section_of[i]);
    return s ? s : defaults[i].bytes;
}

void *gr_technique_scene_settings_rw(const gr_technique_class *cls, gr_scene *scene)
{
    int i = gr_technique_index(cls);
    return i < 0 ? NULL : gr_scene_section(scene, section_of[i]);
}

void gr_technique_resolve(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out)
{
    if (cls->resolve) {
        cls->resolve(cls, scene, in, out);
        return;
    }
    if (out != in) memcpy(out, in, cls->settings_size);
    gr_scene_resolve_settings(cls->params, out, scene);
}

gr_status gr_technique_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    gr_status st = gr_param_validate(cls->params, settings, 1, err);
    if (st != GR_OK) return st;
    return cls->check ? cls->check(cls, settings, err) : GR_OK;
}

int gr_technique_tune_example(const gr_technique_class *cls, const gr_param **out, int max)
{
    int n = 0;
    for (size_t i = 0; cls && i < cls->params->count && n < max; i++) {
        const gr_param *p = &cls->params->params[i];
        if (p->tune_hi > p->tune_lo && (p->type == GR_PT_DOUBLE || p->type == GR_PT_RGB)) out[n++] = p;
    }
    return n;
}

gr_status gr_technique_apply_text(const gr_technique_class *cls, void *settings, const char *text, gr_error *err)
{
    const char *p = text;
    while (p && *p) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        char item[160], *eq;
        snprintf(item, sizeof item, "%.*s", (int)(len < sizeof item - 1 ? len : sizeof item - 1), p);
        if (!(eq = strchr(item, '=')))
            return gr_fail(err, GR_E_INPUT, "%s: '%s': expected KEY=VALUE", cls->name, item);
        *eq++ = '\0';
        const gr_param *prm = gr_param_find(cls->params, item);
        if (!prm) return gr_fail(err, GR_E_INPUT, "%s.%s: unknown setting", cls->name, item);
        gr_status st;
        if (prm->type == GR_PT_ENUM) {
            st = gr_param_set_enum(cls->params, settings, item, eq, err);
        } else if (prm->type == GR_PT_BOOL && (!strcmp(eq, "true") || !strcmp(eq, "false"))) {
            st = gr_param_set_number(cls->params, settings, item, -1, !strcmp(eq, "true") ? 1.0 : 0.0, err);
        } else {
            char *end = NULL;
            double v = strtod(eq, &end);
            if (end == eq || *end) return gr_fail(err, GR_E_INPUT, "%s.%s: '%s' is not a number", cls->name, item, eq);
            st = gr_param_set_number(cls->params, settings, item, -1, v, err);
        }
        if (st != GR_OK) return st;
        p = e ? e + 1 : NULL;
    }
    return GR_OK;
}

/* ---- time limit ----------------------------------------------------------------------- */

static double time_limit_flag_s; /* gr_technique_set_time_limit; 0: none */

/* The render in progress on this thread (gr_technique_render), for gr_technique_wait_pass:
 * one context is used from one thread, so each thread has at most one render running. */
static _Thread_local struct {
    const char *name;
    double deadline_ms, limit_s;
    const char *source;
    double start_ms, next_report_ms; /* gr_technique_set_wait_report's next call */
} cur_render;

static gr_technique_wait_fn wait_fn; /* gr_technique_set_wait_report */
static void *wait_user;
static double wait_every_ms;

void gr_technique_set_wait_report(gr_technique_wait_fn fn, void *user, double every_s)
{
    wait_fn = every_s > 0 ? fn : NULL;
    wait_user = user;
    wait_every_ms = 1000.0 * every_s;
}

gr_status gr_technique_parse_time_limit(const char *what, const char *text, double *seconds, gr_error *err)
{
    char *end = NULL;
    double v = text ? strtod(text, &end) : NAN;
    if (!text || end == text || *end || !(v > 0 && v <= GR_TECH_TIME_LIMIT_MAX_S))
        return gr_fail(err, GR_E_USAGE, "%s %s: expected a number of seconds in (0, %g]", what, text ? text : "",
                       GR_TECH_TIME_LIMIT_MAX_S);
    *seconds = v;
    return GR_OK;
}

void gr_technique_set_time_limit(double seconds) { time_limit_flag_s = seconds > 0 ? seconds : 0; }

gr_status gr_technique_time_limit(double *seconds, const char **source, gr_error *err)
{
    if (time_limit_flag_s > 0) {
        *seconds = time_limit_flag_s;
        *source = "--time-limit";
        return GR_OK;
    }
    const char *env = getenv("GODRAYS_TIME_LIMIT");
    if (env && env[0]) {
        *source = "GODRAYS_TIME_LIMIT";
        return gr_technique_parse_time_limit("GODRAYS_TIME_LIMIT", env, seconds, err);
    }
    *seconds = GR_TECH_TIME_LIMIT_DEFAULT_S;
    *source = "default";
    return GR_OK;
}

gr_status gr_technique_wait_pass(const char *what, gr_error *err)
{
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    if (!fence) return gr_gl_check(what, err);
    /* The first wait flushes, so the fence (and the pass before it) reaches the GPU; short
     * waits then, so that the deadline is met within 50 ms. */
    GLbitfield flags = GL_SYNC_FLUSH_COMMANDS_BIT;
    for (;;) {
        double left_ms = cur_render.name ? cur_render.deadline_ms - gr_clock_ms() : 50.0;
        if (left_ms <= 0) break;
        const double now_ms = gr_clock_ms();
        if (cur_render.name && wait_fn && now_ms >= cur_render.next_report_ms) { /* a long wait: say so */
            cur_render.next_report_ms = now_ms + wait_every_ms;
            wait_fn(wait_user, cur_render.name, what, 1e-3 * (now_ms - cur_render.start_ms), cur_render.limit_s);
        }
        GLuint64 wait_ns = (GLuint64)((left_ms < 50.0 ? left_ms : 50.0) * 1e6);
        GLenum r = glClientWaitSync(fence, flags, wait_ns);
        flags = 0;
        if (r == GL_ALREADY_SIGNALED || r == GL_CONDITION_SATISFIED) {
            glDeleteSync(fence);
            return GR_OK;
        }
        if (r == GL_WAIT_FAILED) {
            glDeleteSync(fence);
            gr_status st = gr_gl_check(what, err);
            return st != GR_OK ? st : gr_fail(err, GR_E_GL, "%s: glClientWaitSync failed", what);
        }
    }
    /* the fence is left to the abandoned context: deleting it is GL work there */
    return gr_fail(err, GR_E_TIMEOUT,
                   "%s: %s: not done after the time limit of %g s (%s; change it with --time-limit SECONDS): "
                   "render abandoned with its GL context",
                   cur_render.name, what, cur_render.limit_s, cur_render.source);
}

/* ---- instances ------------------------------------------------------------------------ */

struct gr_technique {
    const gr_technique_class *cls;
    gr_gl *gl;
    void *state;
    int abandoned; /* a render went over the time limit: state and context are never touched again */
};

gr_status gr_technique_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                              gr_technique **out, gr_error *err)
{
    gr_technique_options o;
    memset(&o, 0, sizeof o);
    if (opts) o = *opts;
    *out = NULL;
    if (gr_gl_abandoned(gl))
        return gr_fail(err, GR_E_TIMEOUT, "technique %s: its GL context was abandoned after a render over the time "
                       "limit; make a new context", cls->name);
    gr_technique *t = calloc(1, sizeof *t);
    if (!t) return gr_fail(err, GR_E_NOMEM, "technique %s: out of memory", cls->name);
    t->cls = cls;
    t->gl = gl;
    gr_status st = cls->create(cls, gl, &o, &t->state, err);
    if (st != GR_OK) {
        free(t);
        return st;
    }
    *out = t;
    return GR_OK;
}

/* An abandoned instance's state stays with its abandoned context, which a driver may still be
 * working for (its buffers, its programs): it is parked here, reachable until the process
 * ends, rather than freed under the driver or lost (a leak the sanitizer build reports). */
#define GR_PARKED_MAX 64
static void *parked[GR_PARKED_MAX];
static int n_parked;
static pthread_mutex_t parked_lock = PTHREAD_MUTEX_INITIALIZER;

static void park(void *state)
{
    pthread_mutex_lock(&parked_lock);
    if (n_parked < GR_PARKED_MAX) parked[n_parked++] = state; /* beyond 64 timeouts: let it go */
    pthread_mutex_unlock(&parked_lock);
}

void gr_technique_destroy(gr_technique *t)
{
    if (!t) return;
    if (!t->abandoned) {
        if (t->gl) gr_gl_make_current(t->gl, NULL);
        t->cls->destroy(t->state);
    } else {
        park(t->state);
    }
    free(t);
}

const gr_technique_class *gr_technique_class_of(const gr_technique *t) { return t ? t->cls : NULL; }

gr_gl *gr_technique_gl(const gr_technique *t) { return t ? t->gl : NULL; }

void gr_technique_set_reuse(gr_technique *t, int on)
{
    if (t && !t->abandoned && t->cls->set_reuse) t->cls->set_reuse(t->state, on);
}

gr_status gr_technique_render(gr_technique *t, const gr_scene *scene, const void *settings, gr_image *out,
                              gr_technique_stats *stats, gr_error *err)
{
    const gr_technique_class *cls = t->cls;
    gr_section_store rs;
    gr_technique_stats local;
    if (!stats) stats = &local;
    gr_technique_stats_clear(stats);
    if (!settings) settings = gr_technique_scene_settings(cls, scene);
    gr_status st = gr_technique_check(cls, settings, err);
    if (st != GR_OK) return st;
    gr_technique_resolve(cls, scene, settings, rs.bytes);
    if ((st = gr_param_validate(cls->params, rs.bytes, 0, err)) != GR_OK) return st;
    if (!out || out->width != scene->camera.width || out->height != scene->camera.height)
        return gr_fail(err, GR_E_RUNTIME, "technique %s: output image is not %dx%d", cls->name, scene->camera.width,
                       scene->camera.height);
    int ch[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
    if (ch[0] < 0 || ch[1] < 0 || ch[2] < 0)
        return gr_fail(err, GR_E_RUNTIME, "technique %s: output image lacks channels R, G, B", cls->name);
    if (t->abandoned)
        return gr_fail(err, GR_E_TIMEOUT, "technique %s: abandoned after a render over the time limit", cls->name);
    double limit_s = 0;
    const char *source = NULL;
    if ((st = gr_technique_time_limit(&limit_s, &source, err)) != GR_OK) return st;
    double t0 = gr_clock_ms();
    cur_render.name = cls->name;
    cur_render.limit_s = limit_s;
    cur_render.source = source;
    cur_render.deadline_ms = t0 + 1000.0 * limit_s;
    cur_render.start_ms = t0;
    cur_render.next_report_ms = t0 + wait_every_ms;
    st = cls->render(t->state, scene, rs.bytes, out, stats, err);
    cur_render.name = NULL;
    if (st == GR_E_TIMEOUT) {
        t->abandoned = 1;
        gr_gl_abandon(t->gl);
    }
    if (st != GR_OK) return st;
    if (!(stats->wall_ms >= 0)) stats->wall_ms = gr_clock_ms() - t0;
    /* The harness's guarantee, whatever the technique (a user's shader included): no NaN
     * or Inf reaches an image. */
    const size_t n = (size_t)out->width * (size_t)out->height;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(out->pixels[i * (size_t)out->nchannels + (size_t)ch[k]]))
                return gr_fail(err, GR_E_RUNTIME, "technique %s: non-finite value at pixel (%zu, %zu)", cls->name,
                               i % (size_t)out->width, i / (size_t)out->width);
    return GR_OK;
}

void gr_technique_stats_clear(gr_technique_stats *s)
{
    memset(s, 0, sizeof *s);
    for (int p = 0; p < GR_TECH_MAX_PASSES; p++) {
        s->gpu_ns[p] = -1;
        gr_pass_cost_clear(&s->cost[p]);
    }
    s->wall_ms = -1;
    s->fragments = -1;
}

/* ---- cost counters --------------------------------------------------------------------- */

static const char *const cost_names[GR_COST_N] = {"fragments", "taps", "vertices", "primitives", "bytes",
                                                  "invocations"};

const char *gr_cost_name(int k) { return k >= 0 && k < GR_COST_N ? cost_names[k] : "?"; }

void gr_pass_cost_clear(gr_pass_cost *c)
{
    for (int k = 0; k < GR_COST_N; k++) c->v[k] = -1;
    c->queried = 0;
}

gr_pass_cost gr_pass_cost_screen(long long w, long long h, long long taps_per_px, long long bytes_per_px)
{
    gr_pass_cost c;
    c.v[GR_COST_FRAGMENTS] = w * h;
    c.v[GR_COST_TAPS] = w * h * taps_per_px;
    c.v[GR_COST_VERTICES] = 3;
    c.v[GR_COST_PRIMITIVES] = 1;
    c.v[GR_COST_BYTES] = w * h * bytes_per_px;
    c.v[GR_COST_INVOCATIONS] = 0;
    c.queried = 0;
    return c;
}

void gr_technique_cost_set(gr_technique_stats *s, int p, int k, long long v, int queried)
{
    if (p < 0 || p >= GR_TECH_MAX_PASSES || k < 0 || k >= GR_COST_N) return;
    s->cost[p].v[k] = v;
    if (queried) s->cost[p].queried |= 1u << k;
    else s->cost[p].queried &= ~(1u << k);
}

void gr_technique_cost_total(const gr_technique_stats *s, gr_pass_cost *out)
{
    gr_pass_cost_clear(out);
    for (int p = 0; p < s->n_passes && p < GR_TECH_MAX_PASSES; p++)
        for (int k = 0; k < GR_COST_N; k++)
            if (s->cost[p].v[k] >= 0) {
                out->v[k] = (out->v[k] < 0 ? 0 : out->v[k]) + s->cost[p].v[k];
                out->queried |= s->cost[p].queried & (1u << k);
            }
}

long long gr_technique_stats_work(const gr_technique_stats *s)
{
    static const int counted[] = {GR_COST_FRAGMENTS, GR_COST_VERTICES, GR_COST_PRIMITIVES, GR_COST_INVOCATIONS};
    long long w = 0;
    for (int p = 0; p < s->n_passes && p < GR_TECH_MAX_PASSES; p++)
        for (size_t k = 0; k < sizeof counted / sizeof counted[0]; k++)
            if (s->cost[p].v[counted[k]] > 0) w += s->cost[p].v[counted[k]];
    return w;
}

void gr_pass_cost_text(const gr_pass_cost *c, char *buf, size_t n)
{
    size_t used = 0;
    if (n) buf[0] = '\0';
    for (int k = 0; k < GR_COST_N && used < n; k++) {
        if (c->v[k] < 0) continue;
        int w = snprintf(buf + used, n - used, "%s%s %lld%s", used ? ", " : "", cost_names[k], c->v[k],
                         (c->queried & (1u << k)) ? "*" : "");
        if (w < 0) break;
        used += (size_t)w;
    }
}

double gr_technique_stats_gpu_ms(const gr_technique_stats *s)
{
    double sum = 0;
    int any = 0;
    for (int p = 0; p < s->n_passes && p < GR_TECH_MAX_PASSES; p++)
        if (s->gpu_ns[p] >= 0) {
            sum += (double)s->gpu_ns[p] * 1e-6;
            any = 1;
        }
    return any ? sum : -1.0;
}

static int cmp_ll(const void *a, const void *b)
{
    long long x = *(const long long *)a, y = *(const long long *)b;
    return (x > y) - (x < y);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void gr_technique_stats_median(const gr_technique_stats *all, int n, gr_technique_stats *out)
{
    *out = all[n - 1];
    if (n < 2) return;
    long long *tmp = malloc((size_t)n * sizeof *tmp);
    double *dt = malloc((size_t)n * sizeof *dt);
    if (tmp && dt) {
        for (int p = 0; p < out->n_passes && p < GR_TECH_MAX_PASSES; p++) {
            for (int i = 0; i < n; i++) tmp[i] = all[i].gpu_ns[p];
            qsort(tmp, (size_t)n, sizeof *tmp, cmp_ll);
            out->gpu_ns[p] = tmp[n / 2];
        }
        for (int i = 0; i < n; i++) dt[i] = all[i].wall_ms;
        qsort(dt, (size_t)n, sizeof *dt, cmp_double);
        out->wall_ms = dt[n / 2];
    }
    free(tmp);
    free(dt);
}

void gr_technique_summary(const gr_technique *t, const gr_technique_stats *stats, char *buf, size_t n)
{
    if (n) buf[0] = '\0';
    if (t && t->cls->summary && n) t->cls->summary(t->state, stats, buf, n);
}

gr_status gr_technique_read_target(gr_technique *t, gr_image **out, gr_error *err)
{
    *out = NULL;
    if (!t->cls->read_target)
        return gr_fail(err, GR_E_USAGE, "technique %s has no intermediate render target to save", t->cls->name);
    return t->cls->read_target(t->state, out, err);
}

/* ---- metadata ------------------------------------------------------------------------- */

/* "godrays:cost.PASS.COUNTER" for every counted figure, "godrays:cost.COUNTER" summed over the
 * passes, "godrays:cost_queried" = "PASS.COUNTER ..." for those read from GL queries. */
static gr_status cost_metadata(const gr_technique_stats *stats, gr_metadata *meta)
{
    char key[96], queried[512] = "";
    gr_status st = GR_OK;
    size_t used = 0;
    for (int p = 0; p < stats->n_passes && p < GR_TECH_MAX_PASSES && st == GR_OK; p++)
        for (int k = 0; k < GR_COST_N && st == GR_OK; k++) {
            if (stats->cost[p].v[k] < 0) continue;
            snprintf(key, sizeof key, "godrays:cost.%s.%s", stats->pass_names[p], cost_names[k]);
            st = gr_meta_set_int(meta, key, stats->cost[p].v[k]);
            if ((stats->cost[p].queried & (1u << k)) && used < sizeof queried) {
                int w = snprintf(queried + used, sizeof queried - used, "%s%s.%s", used ? " " : "",
                                 stats->pass_names[p], cost_names[k]);
                if (w > 0) used += (size_t)w;
            }
        }
    gr_pass_cost tot;
    gr_technique_cost_total(stats, &tot);
    for (int k = 0; k < GR_COST_N && st == GR_OK; k++) {
        if (tot.v[k] < 0) continue;
        snprintf(key, sizeof key, "godrays:cost.%s", cost_names[k]);
        st = gr_meta_set_int(meta, key, tot.v[k]);
    }
    if (st == GR_OK && used > 0) st = gr_meta_set_string(meta, "godrays:cost_queried", queried);
    return st;
}

gr_status gr_technique_metadata(const gr_technique *t, const gr_scene *scene, const void *settings,
                                const gr_technique_stats *stats, gr_metadata *meta, gr_error *err)
{
    const gr_technique_class *cls = t->cls;
    gr_section_store rs;
    char key[96], val[256];
    gr_status st = GR_OK;
    if (!settings) settings = gr_technique_scene_settings(cls, scene);
    gr_technique_resolve(cls, scene, settings, rs.bytes);
#define CK(call) do { if ((st = (call)) != GR_OK) goto fail; } while (0)
    CK(gr_meta_set_string(meta, "godrays:renderer", cls->name));
    CK(gr_meta_set_string(meta, "godrays:technique", cls->name));
    CK(gr_meta_set_string(meta, "godrays:technique_description", cls->description ? cls->description : ""));
    CK(gr_meta_set_string(meta, "godrays:technique_origin", cls->origin ? cls->origin : "built-in"));
    if (t->gl) {
        CK(gr_meta_set_string(meta, "godrays:gl_renderer", gr_gl_renderer(t->gl)));
        CK(gr_meta_set_string(meta, "godrays:gl_version", gr_gl_version(t->gl)));
        CK(gr_meta_set_string(meta, "godrays:gl_platform", gr_gl_platform_name(t->gl)));
    }
    CK(gr_meta_set_string(meta, "godrays:scene", scene->name));
    CK(gr_meta_set_string(meta, "godrays:scene_hash", scene->hash));
    CK(gr_meta_set_double(meta, "godrays:time_s", scene->water.time_s));
    const gr_param_table *tab = cls->params;
    for (size_t i = 0; i < tab->count; i++) {
        const gr_param *p = &tab->params[i];
        snprintf(key, sizeof key, "godrays:%s.%s", cls->name, p->name);
        switch (p->type) {
        case GR_PT_RGB:
            snprintf(val, sizeof val, "%.9g %.9g %.9g", gr_param_get_number(p, rs.bytes, 0),
                     gr_param_get_number(p, rs.bytes, 1), gr_param_get_number(p, rs.bytes, 2));
            CK(gr_meta_set_string(meta, key, val));
            break;
        case GR_PT_ENUM: {
            const char *nm = gr_param_enum_name(p, (int)gr_param_get_number(p, rs.bytes, 0));
            CK(gr_meta_set_string(meta, key, nm ? nm : "?"));
            break;
        }
        case GR_PT_U64:
            snprintf(val, sizeof val, "%llu",
                     *(const unsigned long long *)(const void *)((const char *)rs.bytes + p->offset));
            CK(gr_meta_set_string(meta, key, val));
            break;
        case GR_PT_INT:
        case GR_PT_BOOL:
            CK(gr_meta_set_int(meta, key, (long long)gr_param_get_number(p, rs.bytes, 0)));
            break;
        case GR_PT_DOUBLE:
            CK(gr_meta_set_double(meta, key, gr_param_get_number(p, rs.bytes, 0)));
            break;
        }
    }
    if (stats) {
        snprintf(val, sizeof val, "%s", "");
        for (int p = 0; p < stats->n_passes && p < GR_TECH_MAX_PASSES; p++) {
            snprintf(key, sizeof key, "godrays:gpu_ns.%s", stats->pass_names[p]);
            CK(gr_meta_set_int(meta, key, stats->gpu_ns[p]));
            size_t used = strlen(val);
            snprintf(val + used, sizeof val - used, "%s%s", p ? " " : "", stats->pass_names[p]);
        }
        CK(gr_meta_set_string(meta, "godrays:passes", val));
        CK(gr_meta_set_double(meta, "godrays:gpu_ms", gr_technique_stats_gpu_ms(stats)));
        CK(gr_meta_set_double(meta, "godrays:wall_ms", stats->wall_ms));
        CK(gr_meta_set_int(meta, "godrays:fragments", stats->fragments));
        CK(cost_metadata(stats, meta));
    }
#undef CK
    if (cls->metadata) return cls->metadata(t->state, scene, rs.bytes, stats, meta, err);
    return GR_OK;
fail:
    return gr_fail(err, st, "technique %s metadata: cannot add an entry (%s)", cls->name, gr_status_name(st));
}
