/* godrays: entry point and subcommand dispatch. */
#include "cli/cli.h"
#include "common/signals.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const gr_command commands[] = {
    {"validate", "load and check a scene, print it normalized with defaults filled in", cmd_validate},
    {"info", "print library versions and the GL renderer of a headless EGL context", cmd_info},
    {"compare", "error metrics between two images (any format), with mask, stderr, scale fit", cmd_compare},
    {"shafts", "render the god-ray layer with seed 000's real-time shafts (OpenGL) to EXR + PNG", cmd_shafts},
    {"reference", "render the ground-truth god-ray layer (Embree, single scattering) to EXR + PNG", cmd_reference},
    {"run", "the main job: ground truth (cached) + real-time shafts + comparison + HTML report", cmd_run},
    {"tune", "find the shafts settings that minimize the error over frames and views (Nelder-Mead)", cmd_tune},
    {"sweep", "error surface of the shafts over a grid of one or two settings (CSV, JSON, heat map)", cmd_sweep},
    {"pareto", "speed against error of both renderers: quality ladders, Pareto fronts, CSV + plot", cmd_pareto},
};
static const int n_commands = (int)(sizeof commands / sizeof commands[0]);

static void print_help(FILE *f)
{
    fprintf(f,
            "usage: godrays COMMAND [ARGS...]\n"
            "\n"
            "A physically based validation harness for real-time underwater god rays.\n"
            "\n"
            "commands:\n");
    for (int i = 0; i < n_commands; i++) fprintf(f, "  %-10s %s\n", commands[i].name, commands[i].summary);
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
    gr_signals_install(); /* SIGINT, SIGTERM: temporary files removed, renders stopped cleanly */
    for (int i = 0; i < n_commands; i++)
        if (!strcmp(argv[1], commands[i].name)) return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "godrays: unknown command '%s' (see godrays --help)\n", argv[1]);
    return 2;
}
