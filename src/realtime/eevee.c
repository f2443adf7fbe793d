/* Blender Eevee's volumetrics as a technique (eevee.h; docs/engines.md section 5). */
#include "realtime/eevee.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "common/signals.h"
#include "core/optics.h"
#include "export/gltf.h"
#include "image/exr.h"
#include "realtime/frame.h"
#include "realtime/toolkit.h"

extern char **environ;

#define EV_TAIL_LINES 6   /* Blender's last lines kept for an error message */
#define EV_LINE_MAX 200
#define EV_PATH_MAX 1024

#define SL(f) offsetof(gr_eevee_settings, f)
static const gr_param params[] = {
    {.name = "tile_size", .type = GR_PT_INT, .offset = SL(tile_size), .min = 2, .max = 16, .def = 8, .unit = "px",
     .doc = "Eevee's volumetric tile size: froxels are this many pixels wide (2, 4, 8 or 16)"},
    {.name = "samples", .type = GR_PT_INT, .offset = SL(samples), .min = 1, .max = 256, .def = 64, .unit = "",
     .doc = "Eevee's volumetric samples: depth slices of the froxel grid (an integer: godrays sweep)"},
    {.name = "distribution", .type = GR_PT_DOUBLE, .offset = SL(distribution), .min = 0, .max = 1, .def = 0.8,
     .unit = "", .doc = "slice distribution: 0 linear, 1 exponential (Eevee's sample distribution)"},
    {.name = "start_m", .type = GR_PT_DOUBLE, .offset = SL(start_m), .min = 0, .max = 1e4, .flags = GR_PF_MIN_EXCL,
     .def = 0.1, .unit = "m", .doc = "volumetric start: view depth of the first slice"},
    {.name = "end_m", .type = GR_PT_DOUBLE, .offset = SL(end_m), .min = 0, .max = 1e4, .flags = GR_PF_MIN_EXCL,
     .def = 40, .unit = "m", .doc = "volumetric end: view depth of the last slice, also the camera's far plane"},
    {.name = "light_clamp", .type = GR_PT_DOUBLE, .offset = SL(light_clamp), .min = 0, .max = 1e9, .def = 0,
     .unit = "", .doc = "Eevee's volumetric light clamp (0: off)"},
    {.name = "soft_shadows", .type = GR_PT_BOOL, .offset = SL(soft_shadows), .min = 0, .max = 1, .def = 1, .unit = "",
     .doc = "soft shadows from the sun's disc"},
    {.name = "volumetric_shadows", .type = GR_PT_BOOL, .offset = SL(volumetric_shadows), .min = 0, .max = 1, .def = 1,
     .unit = "", .doc = "attenuate the sun through the medium (marched through the froxels)"},
    {.name = "shadow_samples", .type = GR_PT_INT, .offset = SL(shadow_samples), .min = 1, .max = 128, .def = 64,
     .unit = "", .doc = "steps of the sun's march through the froxels (volumetric shadow samples)"},
    {.name = "taa_samples", .type = GR_PT_INT, .offset = SL(taa_samples), .min = 1, .max = 64, .def = 1, .unit = "",
     .doc = "Eevee's render samples: frames with jittered froxels, averaged"},
    {.name = "cascade_size", .type = GR_PT_INT, .offset = SL(cascade_size), .min = 512, .max = 4096, .def = 1024,
     .unit = "px", .doc = "the sun's shadow cascade resolution (512, 1024, 2048 or 4096)"},
    {.name = "density_scale", .type = GR_PT_DOUBLE, .offset = SL(density_scale), .min = 0, .max = 100,
     .flags = GR_PF_MIN_EXCL, .def = 1, .unit = "", .doc = "multiplies the medium's scattering and absorption",
     .tune_lo = 0.25, .tune_hi = 4.0},
    {.name = "anisotropy", .type = GR_PT_DOUBLE, .offset = SL(anisotropy), .min = -1, .max = 1,
     .flags = GR_PF_MIN_EXCL | GR_PF_MAX_EXCL | GR_PF_FROM_SCENE, .def = NAN, .unit = "", .scene_source = "medium.g",
     .doc = "HG g of Eevee's volume; default: the medium's", .tune_lo = 0.3, .tune_hi = 0.98},
    {.name = "intensity", .type = GR_PT_RGB, .offset = SL(intensity), .min = 0, .max = 1e9, .def = 1, .unit = "",
     .doc = "gain on Eevee's radiance (1: none)", .tune_lo = 0.2, .tune_hi = 5.0},
    {.name = "water_grid", .type = GR_PT_INT, .offset = SL(water_grid), .min = 8, .max = 1024, .def = 256, .unit = "",
     .doc = "cells per side of the exported water mesh (it ends the view rays)"},
    {.name = "difference", .type = GR_PT_BOOL, .offset = SL(difference), .min = 0, .max = 1, .def = 1, .unit = "",
     .doc = "also render without the medium and subtract (docs/engines.md's capture); off: one render"},
};
#undef SL

static const gr_param_table table = {"eevee", params, sizeof params / sizeof params[0]};

static const gr_technique_level ladder[] = {
    {"tile_size=16,samples=32,shadow_samples=16", 1},
    {"tile_size=8,samples=64", 0},
    {"tile_size=4,samples=64", 1},
    {"tile_size=2,samples=128,shadow_samples=128", 0},
};

/* ---- finding the programs ---------------------------------------------------------------- */

/* name on $PATH (or name itself when it holds a slash) into out; 1 if executable. */
static int find_program(const char *name, char *out, size_t n)
{
    if (strchr(name, '/')) {
        snprintf(out, n, "%s", name);
        return access(out, X_OK) == 0;
    }
    const char *path = getenv("PATH");
    if (!path) return 0;
    for (const char *p = path;;) {
        const char *e = strchr(p, ':');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len > 0 && snprintf(out, n, "%.*s/%s", (int)len, p, name) < (int)n && access(out, X_OK) == 0) return 1;
        if (!e) break;
        p = e + 1;
    }
    return 0;
}

typedef struct ev_programs {
    char blender[EV_PATH_MAX], xvfb[EV_PATH_MAX], script[EV_PATH_MAX];
    int use_xvfb; /* 0: a $DISPLAY is used directly */
} ev_programs;

static int locate(ev_programs *p, char *why, size_t n)
{
    const char *b = getenv("GODRAYS_BLENDER");
    if (!find_program(b && b[0] ? b : "blender", p->blender, sizeof p->blender)) {
        snprintf(why, n, "%.300s not found%s (Blender 3.4: scripts/setup.sh installs it; or set GODRAYS_BLENDER)",
                 b && b[0] ? b : "blender", b && b[0] ? "" : " on PATH");
        return 0;
    }
    const char *display = getenv("DISPLAY");
    p->use_xvfb = find_program("xvfb-run", p->xvfb, sizeof p->xvfb);
    if (!p->use_xvfb && !(display && display[0])) {
        snprintf(why, n, "xvfb-run not found on PATH and no $DISPLAY: Eevee needs an X display (install xvfb: "
                 "scripts/setup.sh)");
        return 0;
    }
    const char *s = getenv("GODRAYS_EEVEE_SCRIPT");
    snprintf(p->script, sizeof p->script, "%s", s && s[0] ? s : GR_SOURCE_DIR "/data/blender/eevee_godrays.py");
    if (access(p->script, R_OK) != 0) {
        snprintf(why, n, "the Blender script %.300s cannot be read (%s; set GODRAYS_EEVEE_SCRIPT)", p->script,
                 strerror(errno));
        return 0;
    }
    return 1;
}

int gr_eevee_available(char *why, size_t n)
{
    ev_programs p;
    char tmp[512];
    if (!why || !n) {
        why = tmp;
        n = sizeof tmp;
    }
    why[0] = '\0';
    return locate(&p, why, n);
}

static int ev_available(const gr_technique_class *cls, char *why, size_t n)
{
    (void)cls;
    return gr_eevee_available(why, n);
}

/* ---- the child process ------------------------------------------------------------------- */

typedef struct ev_state {
    ev_programs prog;
    pid_t pid;               /* Blender's process group (xvfb-run leads it); 0: not running */
    int to_child, from_child;
    char dir[EV_PATH_MAX];   /* temporary folder of the requests and frames; "" until made */
    char buf[8192];          /* Blender's output not yet split into lines */
    size_t used;
    char tail[EV_TAIL_LINES][EV_LINE_MAX];
    int n_tail;              /* lines kept (ring, the last EV_TAIL_LINES) */
    long n_requests;
    double render_ms;        /* Blender's render time of the last render (both frames) */
    double off_max;          /* largest value of the medium-off frame (0 when not rendered) */
    int froxels[3];
} ev_state;

static void tail_push(ev_state *r, const char *line, size_t len)
{
    while (len && (line[len - 1] == '\r' || line[len - 1] == ' ')) len--;
    if (!len) return;
    snprintf(r->tail[r->n_tail % EV_TAIL_LINES], EV_LINE_MAX, "%.*s", (int)(len < EV_LINE_MAX ? len : EV_LINE_MAX - 1),
             line);
    r->n_tail++;
}

/* Blender's last lines, " | "-separated, into buf. */
static void tail_text(const ev_state *r, char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    int first = r->n_tail > EV_TAIL_LINES ? r->n_tail - EV_TAIL_LINES : 0;
    for (int i = first; i < r->n_tail && used < n; i++) {
        int w = snprintf(buf + used, n - used, "%s%s", i > first ? " | " : "", r->tail[i % EV_TAIL_LINES]);
        if (w < 0) break;
        used += (size_t)w;
    }
    if (!buf[0]) snprintf(buf, n, "(no output)");
}

static void close_fd(int *fd)
{
    if (*fd >= 0) close(*fd);
    *fd = -1;
}

/* Stops Blender's whole process group (xvfb-run, Xvfb, Blender): SIGTERM lets xvfb-run stop
 * its X server; what is left after a second gets SIGKILL. Reaps the leader. */
static void stop_child(ev_state *r, int gentle)
{
    if (r->pid <= 0) return;
    close_fd(&r->to_child); /* --serve ends its loop at end of input */
    int status = 0;
    pid_t w = 0;
    for (int i = 0; gentle && i < 40 && (w = waitpid(r->pid, &status, WNOHANG)) == 0; i++) {
        struct timespec ts = {0, 50 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    if (w != r->pid) {
        kill(-r->pid, SIGTERM);
        for (int i = 0; i < 20 && (w = waitpid(r->pid, &status, WNOHANG)) == 0; i++) {
            struct timespec ts = {0, 50 * 1000 * 1000};
            nanosleep(&ts, NULL);
        }
        kill(-r->pid, SIGKILL);
        if (w != r->pid) waitpid(r->pid, &status, 0);
    } else {
        kill(-r->pid, SIGKILL); /* anything the group left behind */
    }
    close_fd(&r->from_child);
    r->pid = 0;
    r->used = 0;
}

static gr_status start_child(ev_state *r, gr_error *err)
{
    int in[2] = {-1, -1}, out[2] = {-1, -1};
    if (pipe(in) != 0 || pipe(out) != 0) {
        int e = errno;
        close_fd(&in[0]);
        close_fd(&in[1]);
        return gr_fail(err, GR_E_RUNTIME, "eevee: cannot make a pipe to Blender (%s)", strerror(e));
    }
    fcntl(in[1], F_SETFD, FD_CLOEXEC);
    fcntl(out[0], F_SETFD, FD_CLOEXEC);
    const char *argv[12];
    int k = 0;
    if (r->prog.use_xvfb) {
        argv[k++] = r->prog.xvfb;
        argv[k++] = "-a";
    }
    argv[k++] = r->prog.blender;
    argv[k++] = "-b";
    argv[k++] = "--factory-startup";
    argv[k++] = "--python";
    argv[k++] = r->prog.script;
    argv[k++] = "--";
    argv[k++] = "--serve";
    argv[k] = NULL;
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    posix_spawn_file_actions_init(&fa);
    posix_spawnattr_init(&at);
    posix_spawn_file_actions_adddup2(&fa, in[0], 0);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    posix_spawn_file_actions_adddup2(&fa, out[1], 2);
    /* its own process group: a timeout or Ctrl-C stops all of it (kill(-pgid)), and the
     * terminal's Ctrl-C reaches godrays, which decides */
    posix_spawnattr_setpgroup(&at, 0);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&at, &none);
    posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK);
    pid_t pid = 0;
    int rc = posix_spawn(&pid, argv[0], &fa, &at, (char *const *)argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&at);
    close(in[0]);
    close(out[1]);
    if (rc != 0) {
        close(in[1]);
        close(out[0]);
        return gr_fail(err, GR_E_RUNTIME, "eevee: cannot start %s (%s)", argv[0], strerror(rc));
    }
    r->pid = pid;
    r->to_child = in[1];
    r->from_child = out[0];
    r->used = 0;
    r->n_tail = 0;
    return GR_OK;
}

/* The EXIT or signal of a reaped child, for messages. */
static void child_gone(ev_state *r, char *buf, size_t n)
{
    int status = 0;
    pid_t w = r->pid > 0 ? waitpid(r->pid, &status, 0) : -1;
    if (w > 0 && WIFEXITED(status)) snprintf(buf, n, "exited with status %d", WEXITSTATUS(status));
    else if (w > 0 && WIFSIGNALED(status)) snprintf(buf, n, "was killed by signal %d", WTERMSIG(status));
    else snprintf(buf, n, "ended");
    kill(-r->pid, SIGKILL);
    close_fd(&r->to_child);
    close_fd(&r->from_child);
    r->pid = 0;
}

/* Reads Blender's output until the line that ends the request: "GODRAYS_EEVEE_DONE MS" or
 * "GODRAYS_EEVEE_ERROR MESSAGE"; every line is kept in the tail for messages. Stops Blender
 * at the deadline (GR_E_TIMEOUT) or on Ctrl-C (GR_E_INTERRUPTED). */
static gr_status wait_done(ev_state *r, double deadline_ms, double limit_s, const char *source, gr_error *err)
{
    char tail[EV_TAIL_LINES * (EV_LINE_MAX + 3)];
    for (;;) {
        /* complete lines first */
        char *nl;
        while ((nl = memchr(r->buf, '\n', r->used)) != NULL) {
            size_t len = (size_t)(nl - r->buf);
            static const char done[] = "GODRAYS_EEVEE_DONE ", fail[] = "GODRAYS_EEVEE_ERROR ";
            int is_done = len >= sizeof done - 1 && !memcmp(r->buf, done, sizeof done - 1);
            int is_fail = len >= sizeof fail - 1 && !memcmp(r->buf, fail, sizeof fail - 1);
            if (is_done) {
                char num[64];
                size_t nn = len - (sizeof done - 1);
                snprintf(num, sizeof num, "%.*s", (int)(nn < sizeof num ? nn : sizeof num - 1), r->buf + sizeof done - 1);
                r->render_ms = strtod(num, NULL);
            } else {
                tail_push(r, r->buf, len);
            }
            memmove(r->buf, nl + 1, r->used - len - 1);
            r->used -= len + 1;
            if (is_done) return GR_OK;
            if (is_fail) {
                tail_text(r, tail, sizeof tail);
                return gr_fail(err, GR_E_RUNTIME, "eevee: Blender failed; its last lines: %s", tail);
            }
        }
        if (r->used == sizeof r->buf) { /* a line longer than the buffer: keep its start */
            tail_push(r, r->buf, r->used);
            r->used = 0;
        }
        volatile sig_atomic_t *flag = gr_signals_flag();
        if (*flag) {
            stop_child(r, 0);
            return gr_fail(err, GR_E_INTERRUPTED, "eevee: interrupted (signal %d); Blender stopped", (int)*flag);
        }
        double left = deadline_ms - gr_clock_ms();
        if (left <= 0) {
            stop_child(r, 0);
            return gr_fail(err, GR_E_TIMEOUT,
                           "eevee: Blender's render not done after the time limit of %g s (%s; change it with "
                           "--time-limit SECONDS): Blender stopped",
                           limit_s, source);
        }
        struct pollfd pf = {r->from_child, POLLIN, 0};
        int pr = poll(&pf, 1, left < 100 ? (int)left + 1 : 100);
        if (pr < 0 && errno != EINTR) return gr_fail(err, GR_E_RUNTIME, "eevee: poll: %s", strerror(errno));
        if (pr <= 0) continue;
        ssize_t got = read(r->from_child, r->buf + r->used, sizeof r->buf - r->used);
        if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (got <= 0) {
            if (r->used) tail_push(r, r->buf, r->used);
            r->used = 0;
            char how[64];
            child_gone(r, how, sizeof how);
            tail_text(r, tail, sizeof tail);
            return gr_fail(err, GR_E_RUNTIME, "eevee: Blender %s before the render was done; its last lines: %s", how,
                           tail);
        }
        r->used += (size_t)got;
    }
}

/* ---- the class --------------------------------------------------------------------------- */

static void remove_files(ev_state *r)
{
    if (!r->dir[0]) return;
    static const char *const names[] = {"scene.glb", "request.json", "on.exr", "off.exr"};
    char p[EV_PATH_MAX + 32];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", r->dir, names[i]);
        unlink(p);
    }
    rmdir(r->dir);
    r->dir[0] = '\0';
}

static void ev_destroy(void *state)
{
    ev_state *r = state;
    if (!r) return;
    stop_child(r, 1);
    remove_files(r);
    free(r);
}

static gr_status ev_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)cls;
    (void)gl;
    (void)opts;
    *state = NULL;
    char why[512];
    ev_state *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "eevee: out of memory");
    r->to_child = r->from_child = -1;
    if (!locate(&r->prog, why, sizeof why)) {
        free(r);
        return gr_fail(err, GR_E_USAGE, "eevee: unavailable: %s", why);
    }
    *state = r;
    return GR_OK;
}

static int pow2_in(int v, int lo, int hi)
{
    for (int p = lo; p <= hi; p *= 2)
        if (v == p) return 1;
    return 0;
}

static gr_status ev_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const gr_eevee_settings *s = settings;
    if (!pow2_in(s->tile_size, 2, 16))
        return gr_fail(err, GR_E_INPUT, "%s.tile_size: %d: must be 2, 4, 8 or 16", cls->name, s->tile_size);
    if (!pow2_in(s->cascade_size, 512, 4096))
        return gr_fail(err, GR_E_INPUT, "%s.cascade_size: %d: must be 512, 1024, 2048 or 4096", cls->name,
                       s->cascade_size);
    if (!(s->start_m < s->end_m))
        return gr_fail(err, GR_E_INPUT, "%s.start_m %g: must be below %s.end_m %g", cls->name, s->start_m, cls->name,
                       s->end_m);
    return GR_OK;
}

static cJSON *vec3_json(const double v[3])
{
    return cJSON_CreateDoubleArray(v, 3);
}

/* The request of docs/engines.md section 5: the sun as it is under a flat surface (the
 * refracted direction T, the irradiance on a plane perpendicular to T just below the surface
 * E_w = F_t E cos(theta_i) / cos(theta_t): physics-oracles.md, oracle 1), the medium's
 * coefficients times density_scale, its box (the rest plane down to the seabed), Eevee's
 * settings. */
static char *request_json(const ev_state *r, const gr_scene *scene, const gr_eevee_settings *s)
{
    gr_frame f;
    gr_frame_init(scene, &f);
    const double cos_i = -f.sun_dir[1], cos_t = -f.refr_dir[1];
    double ew[3], sig_s[3], sig_a[3], lo[3], hi[3];
    for (int c = 0; c < 3; c++) {
        ew[c] = f.transmittance_flat * f.sun_irradiance[c] * cos_i / cos_t;
        sig_s[c] = s->density_scale * scene->medium.scattering[c];
        sig_a[c] = s->density_scale * scene->medium.absorption[c];
    }
    /* the sun's disc seen from below: compressed by refraction, in the plane of incidence by
     * d theta_t / d theta_i = cos_i / (n cos_t), across it by 1 / n (geometric mean) */
    double angle = 2.0 * f.sun_angular_radius_rad * sqrt(cos_i / (f.ior * cos_t)) / sqrt(f.ior);
    const double *eye = scene->camera.position_m;
    double reach = s->end_m + 1.0;
    lo[0] = eye[0] - reach;
    lo[2] = eye[2] - reach;
    hi[0] = eye[0] + reach;
    hi[2] = eye[2] + reach;
    hi[1] = scene->water.rest_height_m;
    lo[1] = scene->has_seabed ? scene->water.rest_height_m - scene->seabed_depth_m : eye[1] - reach;
    char p_glb[EV_PATH_MAX + 32], p_on[EV_PATH_MAX + 32], p_off[EV_PATH_MAX + 32];
    snprintf(p_glb, sizeof p_glb, "%s/scene.glb", r->dir);
    snprintf(p_on, sizeof p_on, "%s/on.exr", r->dir);
    snprintf(p_off, sizeof p_off, "%s/off.exr", r->dir);
    cJSON *root = cJSON_CreateObject(), *o;
    if (!root) return NULL;
    cJSON_AddStringToObject(root, "gltf", p_glb);
    cJSON_AddStringToObject(root, "out_on", p_on);
    cJSON_AddStringToObject(root, "out_off", s->difference ? p_off : "");
    cJSON_AddNumberToObject(root, "width", scene->camera.width);
    cJSON_AddNumberToObject(root, "height", scene->camera.height);
    if ((o = cJSON_AddObjectToObject(root, "sun"))) {
        cJSON_AddItemToObject(o, "dir", vec3_json(f.refr_dir));
        cJSON_AddItemToObject(o, "irradiance", vec3_json(ew));
        cJSON_AddNumberToObject(o, "angle_rad", angle);
    }
    if ((o = cJSON_AddObjectToObject(root, "medium"))) {
        cJSON_AddItemToObject(o, "scattering", vec3_json(sig_s));
        cJSON_AddItemToObject(o, "absorption", vec3_json(sig_a));
        cJSON_AddNumberToObject(o, "g", s->anisotropy);
    }
    if ((o = cJSON_AddObjectToObject(root, "box"))) {
        cJSON_AddItemToObject(o, "min", vec3_json(lo));
        cJSON_AddItemToObject(o, "max", vec3_json(hi));
    }
    if ((o = cJSON_AddObjectToObject(root, "eevee"))) {
        cJSON_AddNumberToObject(o, "tile_size", s->tile_size);
        cJSON_AddNumberToObject(o, "samples", s->samples);
        cJSON_AddNumberToObject(o, "distribution", s->distribution);
        cJSON_AddNumberToObject(o, "start", s->start_m);
        cJSON_AddNumberToObject(o, "end", s->end_m);
        cJSON_AddNumberToObject(o, "light_clamp", s->light_clamp);
        cJSON_AddBoolToObject(o, "soft_shadows", s->soft_shadows);
        cJSON_AddBoolToObject(o, "volumetric_shadows", s->volumetric_shadows);
        cJSON_AddNumberToObject(o, "shadow_samples", s->shadow_samples);
        cJSON_AddNumberToObject(o, "taa_samples", s->taa_samples);
        cJSON_AddNumberToObject(o, "cascade_size", s->cascade_size);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

static gr_status write_text(const char *path, const char *text, gr_error *err)
{
    FILE *fp = fopen(path, "w");
    if (!fp) return gr_fail(err, GR_E_IO, "eevee: %s: %s", path, strerror(errno));
    int ok = fputs(text, fp) >= 0;
    ok = (fclose(fp) == 0) && ok;
    return ok ? GR_OK : gr_fail(err, GR_E_IO, "eevee: %s: write failed", path);
}

/* Blender's frame at path into *img, checked for its size and RGB. */
static gr_status read_frame(const char *path, const gr_scene *scene, gr_image **img, int ch[3], gr_error *err)
{
    gr_status st = gr_exr_read(path, img, NULL, err);
    if (st != GR_OK) return gr_error_prefix(err, "eevee: Blender's frame");
    const gr_image *im = *img;
    if (im->width != scene->camera.width || im->height != scene->camera.height)
        return gr_fail(err, GR_E_RUNTIME, "eevee: Blender's frame %s is %dx%d, not %dx%d", path, im->width, im->height,
                       scene->camera.width, scene->camera.height);
    static const char *const names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; c++)
        if ((ch[c] = gr_image_channel(im, names[c])) < 0)
            return gr_fail(err, GR_E_RUNTIME, "eevee: Blender's frame %s has no channel %s", path, names[c]);
    return GR_OK;
}

/* out = intensity x (on - off), and the largest magnitude of off (it is 0 when the surfaces
 * are black, as the script makes them: the check that the difference removes nothing). */
static gr_status compose(ev_state *r, const gr_scene *scene, const gr_eevee_settings *s, gr_image *out, gr_error *err)
{
    char p_on[EV_PATH_MAX + 32], p_off[EV_PATH_MAX + 32];
    snprintf(p_on, sizeof p_on, "%s/on.exr", r->dir);
    snprintf(p_off, sizeof p_off, "%s/off.exr", r->dir);
    gr_image *on = NULL, *off = NULL;
    int c_on[3], c_off[3] = {0, 0, 0};
    gr_status st = read_frame(p_on, scene, &on, c_on, err);
    if (st == GR_OK && s->difference) st = read_frame(p_off, scene, &off, c_off, err);
    if (st == GR_OK) {
        int oc[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
        const size_t n = (size_t)out->width * (size_t)out->height;
        r->off_max = 0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double v = on->pixels[i * (size_t)on->nchannels + (size_t)c_on[c]];
                if (off) {
                    double o = off->pixels[i * (size_t)off->nchannels + (size_t)c_off[c]];
                    if (fabs(o) > r->off_max) r->off_max = fabs(o);
                    v -= o;
                }
                out->pixels[i * (size_t)out->nchannels + (size_t)oc[c]] = (float)(s->intensity[c] * v);
            }
    }
    gr_image_destroy(on);
    gr_image_destroy(off);
    return st;
}

static gr_status ev_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    ev_state *r = state;
    const gr_eevee_settings *s = settings;
    double limit_s = 0;
    const char *source = NULL;
    gr_status st = gr_technique_time_limit(&limit_s, &source, err);
    if (st != GR_OK) return st;
    const double deadline = gr_clock_ms() + 1000.0 * limit_s;
    if (!r->dir[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(r->dir, sizeof r->dir, "%s/godrays-eevee-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
        if (!mkdtemp(r->dir)) {
            int e = errno;
            r->dir[0] = '\0';
            return gr_fail(err, GR_E_IO, "eevee: cannot make a temporary folder under %s (%s)",
                           tmp && tmp[0] ? tmp : "/tmp", strerror(e));
        }
    }
    char p_glb[EV_PATH_MAX + 32], p_req[EV_PATH_MAX + 32];
    snprintf(p_glb, sizeof p_glb, "%s/scene.glb", r->dir);
    snprintf(p_req, sizeof p_req, "%s/request.json", r->dir);
    gr_gltf_options go;
    memset(&go, 0, sizeof go);
    go.grid_cells = s->water_grid;
    go.half_size_m = s->end_m + 1.0; /* the water must end every view ray within the froxels' reach */
    if ((st = gr_gltf_write(scene, &go, p_glb, err)) != GR_OK) return gr_error_prefix(err, "eevee: export");
    char *req = request_json(r, scene, s);
    if (!req) return gr_fail(err, GR_E_NOMEM, "eevee: out of memory for the request");
    st = write_text(p_req, req, err);
    cJSON_free(req);
    if (st != GR_OK) return st;
    char p_frame[EV_PATH_MAX + 32]; /* no frame of an earlier render may pass for this one's */
    snprintf(p_frame, sizeof p_frame, "%s/on.exr", r->dir);
    unlink(p_frame);
    snprintf(p_frame, sizeof p_frame, "%s/off.exr", r->dir);
    unlink(p_frame);
    if (r->pid <= 0 && (st = start_child(r, err)) != GR_OK) return st;
    /* a write to a Blender that died is EPIPE (SIGPIPE ignored for the call's duration) */
    char line[EV_PATH_MAX + 40];
    int len = snprintf(line, sizeof line, "%s\n", p_req);
    struct sigaction ign, old;
    memset(&ign, 0, sizeof ign);
    ign.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &ign, &old);
    ssize_t wr = write(r->to_child, line, (size_t)len);
    sigaction(SIGPIPE, &old, NULL);
    gr_signals_hold_begin();
    if (wr != len) {
        st = wait_done(r, gr_clock_ms() + 5000.0, limit_s, source, err); /* its last words */
        if (st == GR_OK) st = gr_fail(err, GR_E_RUNTIME, "eevee: cannot send the request to Blender");
    } else {
        st = wait_done(r, deadline, limit_s, source, err);
    }
    gr_signals_hold_end();
    if (st == GR_E_TIMEOUT || st == GR_E_INTERRUPTED) remove_files(r);
    if (st != GR_OK) return st;
    r->n_requests++;
    if ((st = compose(r, scene, s, out, err)) != GR_OK) return st;
    r->froxels[0] = (scene->camera.width + s->tile_size - 1) / s->tile_size;
    r->froxels[1] = (scene->camera.height + s->tile_size - 1) / s->tile_size;
    r->froxels[2] = s->samples;
    if (stats) {
        stats->n_passes = 0;
        stats->wall_ms = r->render_ms; /* Blender's own render time (start, export and reads excluded) */
    }
    return GR_OK;
}

static gr_status ev_metadata(void *state, const gr_scene *scene, const void *settings, const gr_technique_stats *stats,
                             gr_metadata *meta, gr_error *err)
{
    const ev_state *r = state;
    (void)scene;
    (void)settings;
    (void)stats;
    gr_status st;
    if ((st = gr_meta_set_double(meta, "godrays:eevee.blender_render_ms", r->render_ms)) != GR_OK ||
        (st = gr_meta_set_double(meta, "godrays:eevee.off_max", r->off_max)) != GR_OK ||
        (st = gr_meta_set_string(meta, "godrays:eevee.blender", r->prog.blender)) != GR_OK)
        return gr_fail(err, st, "eevee metadata: cannot add an entry");
    return GR_OK;
}

static void ev_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const ev_state *r = state;
    (void)stats;
    snprintf(buf, n, "Blender Eevee: %dx%dx%d froxels, Blender's render %.0f ms, medium-off frame max %g", r->froxels[0],
             r->froxels[1], r->froxels[2], r->render_ms, r->off_max);
}

const gr_technique_class gr_eevee_class = {
    .name = "eevee",
    .description = "Blender Eevee's volumetrics (froxels, sun shadow maps) run in Blender from the glTF export "
                   "(slow: only when named)",
    .params = &table,
    .settings_size = sizeof(gr_eevee_settings),
    .origin = "built-in",
    .gain_key = "intensity",
    .ladder = ladder,
    .n_ladder = sizeof ladder / sizeof ladder[0],
    .tune_keys = "density_scale,anisotropy",
    .by_name_only = 1,
    .available = ev_available,
    .check = ev_check,
    .create = ev_create,
    .destroy = ev_destroy,
    .render = ev_render,
    .metadata = ev_metadata,
    .summary = ev_summary,
};
