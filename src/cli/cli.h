/* The godrays command line: one cmd_*.c per subcommand, dispatched from main.c.
 * Each command returns a process exit code: 0 ok, 1 runtime failure, 2 bad usage/input. */
#ifndef GR_CLI_H
#define GR_CLI_H

#include "common/status.h"

typedef struct gr_command {
    const char *name;
    const char *summary;          /* one line for `godrays --help` */
    int (*run)(int argc, char **argv); /* argv[0] is the subcommand name */
} gr_command;

int cmd_validate(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_techniques(int argc, char **argv);
int cmd_reference(int argc, char **argv);
int cmd_run(int argc, char **argv);
int cmd_sweep(int argc, char **argv);
int cmd_tune(int argc, char **argv);
int cmd_pareto(int argc, char **argv);
int cmd_export(int argc, char **argv);
int cmd_merge(int argc, char **argv);
int cmd_farm(int argc, char **argv);
int cmd_suite(int argc, char **argv);
int cmd_watch(int argc, char **argv);

/* Prints "godrays NAME: message" on one line to stderr and returns the exit code. */
int gr_cli_report(const char *cmd, const gr_error *err);
/* Prints a usage error "godrays NAME: message (see godrays NAME --help)" and returns 2. */
int gr_cli_usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
