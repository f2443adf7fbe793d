/* Command-line options shared by `godrays sweep` and `godrays tune` (scene overrides, size,
 * frames, views, metric, scale fit, cache, output folder), parsed in one place so that both
 * commands accept and check them the same way. */
#ifndef GR_TUNE_CLIOPTS_H
#define GR_TUNE_CLIOPTS_H

#include "common/status.h"
#include "tune/objective.h"
#include "tune/session.h"

#define GR_TUNE_MAX_SETS 256

typedef struct gr_tune_cli {
    gr_tune_session_options so;
    const char *sets[GR_TUNE_MAX_SETS + 2];
    char size_sets[2][48];
    const char *outdir;           /* NULL: out/SCENE/<command> */
    gr_tune_metric metric;
    int fit;                      /* -1: auto (on unless shafts.intensity is a parameter) */
    int normalize;                /* --normalize */
    int quiet;
    double fps;
    const char *frames_spec;      /* parsed in gr_tune_cli_finish (needs --fps) */
    const char *times_spec;
} gr_tune_cli;

/* Defaults: metric rmse, fit auto, fps 30, cache on, progress on. */
void gr_tune_cli_init(gr_tune_cli *c);

/* Tries argv[*i] as a shared option; consumes its value (advancing *i). Returns 1 if it was
 * one, 0 if not, -1 with err (GR_E_USAGE naming the flag) for a bad value. */
int gr_tune_cli_option(gr_tune_cli *c, int argc, char **argv, int *i, gr_error *err);

/* After all arguments: the frames/times lists; progress follows quiet. */
gr_status gr_tune_cli_finish(gr_tune_cli *c, gr_error *err);

/* The help text of the shared options. */
extern const char gr_tune_cli_help[];

#endif
