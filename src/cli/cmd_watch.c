/* godrays watch TECHNIQUE_DIR SCENE: the edit-to-verdict loop (src/watch/watch.h): the ground
 * truth once (reference/truth.h), then the user technique in TECHNIQUE_DIR rendered again and
 * scored on every save, shown on a local page (src/watch/server.h) until Ctrl-C. */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/signals.h"
#include "reference/truth.h"
#include "watch/server.h"
#include "watch/watch.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays watch TECHNIQUE_DIR SCENE [options]\n"
            "\n"
            "The edit-to-verdict loop of a user technique (docs/techniques.md \"The edit-to-verdict loop\"):\n"
            "renders SCENE's ground truth once (cached as for `godrays run`), then renders the technique\n"
            "in TECHNIQUE_DIR (its manifest.json) and compares it with the truth at the start and again\n"
            "after every save of a file in the folder (100 ms after the last write of a burst). A page on\n"
            "http://127.0.0.1:PORT/ (printed at the start) follows each render within a second: the\n"
            "render at the truth's exposure, the truth, the difference and FLIP images, the verdict and\n"
            "every registry metric, or the manifest, compiler or render error with the compiler's log.\n"
            "One line per render on stdout. Ctrl-C (or SIGTERM) stops it: exit 0.\n"
            "\n"
            "options:\n"
            "  --port N             listen on 127.0.0.1:N (default 0: a free port, printed)\n"
            "  --set KEY=VALUE      override a scene value before validation, e.g. NAME.KEY=V for the\n"
            "                       technique's settings (used while the manifest keeps its settings)\n"
            "  --size WxH           image size (same as --set camera.width=W --set camera.height=H)\n"
            "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --max-memory SIZE    memory limit of the ground truth's render\n"
            "  --technique-dir DIR  also register the user technique in DIR (repeatable)\n"
            "  --preset FILE        apply a preset (docs/tuning.md \"Presets\")\n"
            "  --gl-platform P      auto, surfaceless or device (default auto)\n"
            "  -q, --quiet          no ground-truth progress and no line per render (the URL is printed)\n"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 stopped by Ctrl-C, 1 runtime failure, 2 bad usage or input (a bad manifest\n"
            "at the start, a port in use).\n");
}

typedef struct watch_opts {
    const char *dir;
    long port;
    int quiet, help;
    gr_gl_platform platform;
} watch_opts;

static int parse_args(gr_args *args, watch_opts *o)
{
    int rc = 0, taken = 0;
    const char *outdir = NULL;
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i], *v = NULL;
        if ((rc = gr_args_take_common(args, &outdir, &o->platform, &taken)) != 0 || taken) {
            if (outdir) return gr_cli_usage_error("watch", "%s: watch writes no files (its page is served)", a);
            continue; /* --set, --size, --time-limit, --max-memory, --gl-platform, ... */
        } else if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            o->help = 1;
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (!strcmp(a, "--port")) {
            char *end = NULL;
            if ((rc = gr_args_value(args, &v)) != 0) break;
            errno = 0;
            o->port = strtol(v, &end, 10);
            if (errno || end == v || *end || o->port < 0 || o->port > 65535)
                return gr_cli_usage_error("watch", "--port %s: expected an integer in [0, 65535] (0: a free port)", v);
        } else if (!o->dir && !(a[0] == '-' && a[1])) {
            o->dir = a; /* the first positional argument */
        } else {
            rc = gr_args_take_scene(args);
        }
    }
    if (rc) return rc;
    if (!o->dir) return gr_cli_usage_error("watch", "no technique folder given");
    if (args->n_tech_dirs >= GR_TECH_MAX) return gr_cli_usage_error("watch", "too many technique folders");
    args->tech_dirs[args->n_tech_dirs++] = o->dir; /* registered as with --technique-dir */
    return gr_args_need_scene(args);
}

/* The ground truth (cache, or rendered with progress on stderr). */
static gr_status get_truth(const gr_scene *scene, int quiet, gr_ref_result *res, gr_error *err)
{
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.ref.progress = !quiet;
    gr_truth_info ti;
    gr_status st = gr_truth_get(scene, &to, res, &ti, err);
    if (st == GR_OK && !quiet)
        fprintf(stderr, "godrays watch: ground truth %s (%.1f s)\n", ti.cached ? "from the cache" : "rendered", ti.seconds);
    if (st == GR_OK && ti.note[0]) fprintf(stderr, "godrays watch: warning: %s\n", ti.note);
    return st;
}

static void print_line(void *user, const char *line)
{
    (void)user;
    printf("%s\n", line);
    fflush(stdout); /* a pipe sees each render as it happens */
}

static int watch_with(gr_args *args)
{
    watch_opts o;
    memset(&o, 0, sizeof o);
    o.platform = GR_GL_AUTO;
    int rc = parse_args(args, &o);
    if (rc || o.help) return rc;
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    /* the folder's technique is the one registered last (gr_args_add_technique_dirs, in order) */
    const gr_technique_class *cls = gr_technique_at(gr_technique_count() - 1);
    gr_scene *scene = NULL;
    if ((rc = gr_args_load_scene(args, &scene)) != 0) return rc;
    gr_error err = {GR_OK, ""};
    gr_ref_result truth;
    memset(&truth, 0, sizeof truth);
    gr_watch_server *srv = NULL;
    gr_status st = get_truth(scene, o.quiet, &truth, &err);
    if (st == GR_OK) st = gr_watch_server_create((int)o.port, gr_watch_page(), &srv, &err);
    if (st == GR_OK) {
        printf("godrays watch: http://127.0.0.1:%d/ (watching %s; Ctrl-C ends)\n", gr_watch_server_port(srv), o.dir);
        fflush(stdout);
        gr_watch_options wo = {.dir = o.dir, .cls = cls, .scene = scene, .truth = truth.image,
                               .truth_meta = &truth.meta, .platform = o.platform, .stop = gr_signals_flag(),
                               .log = o.quiet ? NULL : print_line};
        gr_signals_hold_begin(); /* a first Ctrl-C ends the loop, not the process */
        st = gr_watch_run(&wo, srv, &err);
        gr_signals_hold_end();
    }
    gr_watch_server_destroy(srv);
    if (truth.image) gr_ref_result_free(&truth);
    free(scene);
    if (st != GR_OK) return gr_cli_report("watch", &err);
    if (!o.quiet) fprintf(stderr, "godrays watch: stopped\n");
    return 0;
}

int cmd_watch(int argc, char **argv)
{
    return gr_args_main("watch", argc, argv, watch_with);
}
