/* godrays: entry point and subcommand dispatch. */
#include "cli/cli.h"
#include "common/signals.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "realtime/technique.h"

static const gr_command commands[] = {
    {"validate", "load and check a scene, print it normalized with defaults filled in", cmd_validate},
    {"info", "print library versions and the GL renderer of a headless EGL context", cmd_info},
    {"compare", "error metrics between two images (any format), with mask, stderr, scale fit", cmd_compare},
    {"techniques", "list the real-time techniques and their settings (text or --json)", cmd_techniques},
    {"render", "render the god-ray layer with a real-time technique (OpenGL) to EXR + PNG", cmd_render},
    {"reference", "render the ground-truth god-ray layer (Embree, single scattering) to EXR + PNG", cmd_reference},
    {"run", "the main job: ground truth (cached) + every real-time technique + leaderboard report", cmd_run},
    {"tune", "find a technique's settings that minimize the error over frames and views (Nelder-Mead)", cmd_tune},
    {"sweep", "error surface of a technique over a grid of one or two settings (CSV, JSON, heat map)", cmd_sweep},
    {"pareto", "speed against error of the ground truth and each technique: Pareto fronts, CSV + plot", cmd_pareto},
    {"export", "the scene for other engines: glTF 2.0 (water, camera, sun, occluders), shader constants", cmd_export},
    {"merge", "assemble the parts of a ground-truth render (reference --tile) into one EXR, bit for bit", cmd_merge},
    {"farm", "ground truths of frames and views as a Slurm job array of parts, merged into the cache", cmd_farm},
    {"watch", "re-render and score a user technique on every save of its files; a local page shows it", cmd_watch},
    {"suite", "check and list a view suite: cases (scene, camera, sun, time) split into train and test", cmd_suite},
};
static const int n_commands = (int)(sizeof commands / sizeof commands[0]);

/* Aliases: NAME ARGS... runs COMMAND ARG ARGS... */
static const struct {
    const char *name, *summary, *command, *arg;
} aliases[] = {
    {"shafts", "same as `render shafts` (seed 000's shafts)", "render", "shafts"},
};
static const int n_aliases = (int)(sizeof aliases / sizeof aliases[0]);

static void print_help(FILE *f)
{
    fprintf(f,
            "usage: godrays COMMAND [ARGS...]\n"
            "\n"
            "A physically based validation harness for real-time underwater god rays.\n"
            "\n"
            "commands:\n");
    for (int i = 0; i < n_commands; i++) fprintf(f, "  %-10s %s\n", commands[i].name, commands[i].summary);
    for (int i = 0; i < n_aliases; i++) fprintf(f, "  %-10s %s\n", aliases[i].name, aliases[i].summary);
    fprintf(f,
            "\n"
            "Run `godrays COMMAND --help` for a command's options.\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad input.\n");
}

int gr_cli_report(const char *cmd, const gr_error *err)
{
    fprintf(stderr, "godrays %s: %s\n", cmd, err->msg);
    return gr_status_exit_code(err->status);
}

int gr_cli_usage_error(const char *cmd, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fprintf(stderr, "godrays %s: %s (see godrays %s --help)\n", cmd, msg, cmd);
    return 2;
}

int main(int argc, char **argv)
{
#if defined(__GLIBC__)
    /* The ground truth builds and frees beam sets of tens of MB every pass: blocks up to
     * 32 MB (glibc's largest mmap threshold) stay in the heap for the next set instead of
     * being unmapped and faulted in again (issue 30: -0.5 s of kernel time and -0.06 s of
     * serial time at 640x360; docs/benchmarks.md) */
    mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
    mallopt(M_TRIM_THRESHOLD, 512 * 1024 * 1024);
#endif
    if (argc < 2) {
        print_help(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        print_help(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("godrays 0.1.0\n");
        return 0;
    }
    /* the built-in techniques (and so their scene sections) before any scene is read */
    gr_technique_count();
    gr_signals_install(); /* SIGINT, SIGTERM: temporary files removed, renders stopped cleanly */
    for (int i = 0; i < n_commands; i++)
        if (!strcmp(argv[1], commands[i].name)) return commands[i].run(argc - 1, argv + 1);
    for (int i = 0; i < n_aliases; i++) {
        if (strcmp(argv[1], aliases[i].name)) continue;
        /* "NAME ARGS..." -> "COMMAND ARG ARGS..." */
        char **av = calloc((size_t)argc + 1, sizeof *av);
        if (!av) {
            fprintf(stderr, "godrays: out of memory\n");
            return 1;
        }
        av[0] = (char *)(uintptr_t)aliases[i].command;
        av[1] = (char *)(uintptr_t)aliases[i].arg;
        for (int k = 2; k < argc; k++) av[k] = argv[k];
        int rc = 2;
        for (int j = 0; j < n_commands; j++)
            if (!strcmp(aliases[i].command, commands[j].name)) rc = commands[j].run(argc, av);
        free(av);
        return rc;
    }
    fprintf(stderr, "godrays: unknown command '%s' (see godrays --help)\n", argv[1]);
    return 2;
}
