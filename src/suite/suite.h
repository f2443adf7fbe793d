/* A view suite: the cases (a scene plus camera, sun and time overrides) over which `run
 * --suite` ranks techniques and `pareto --suite --tune` tunes them on the train cases and scores
 * them on the test cases (docs/scene-format.md "Suites"). Plain data; load/destroy. */
#ifndef GR_SUITE_H
#define GR_SUITE_H

#include "common/status.h"
#include "scene/scene.h"

#define GR_SUITE_NAME_MAX 64

typedef enum gr_split { GR_SPLIT_TRAIN = 0, GR_SPLIT_TEST = 1 } gr_split;

typedef struct gr_suite_case {
    char name[GR_SUITE_NAME_MAX];  /* [a-z0-9_-]+, unique within the suite */
    gr_split split;
    char scene_path[1024];         /* the case's scene file as resolved (relative to the suite) */
    gr_scene scene;                /* loaded with the case's overrides applied and refreshed */
} gr_suite_case;

typedef struct gr_suite {
    char path[1024];               /* the suite file */
    char name[GR_SUITE_NAME_MAX];
    char description[256];
    int width, height;             /* the suite's default render size (0: the caller's) */
    int n_cases;
    gr_suite_case *cases;          /* n_cases, in file order */
} gr_suite;

/* Loads and validates a suite file; every case's scene is loaded with its overrides.
 * GR_E_INPUT with "FILE: JSON.PATH: reason" on bad content, GR_E_IO when unreadable. */
gr_status gr_suite_load(const char *path, gr_suite **out, gr_error *err);
void gr_suite_destroy(gr_suite *suite);
/* Number of cases of a split. */
int gr_suite_count(const gr_suite *suite, gr_split split);

/* gr_suite_load with the caller's scene overrides ("json.path=value", e.g. the command line's
 * --set and --size) applied to every case after the suite's own (its size, then the case's);
 * an error in one of them keeps its "--set OV" wording, under the suite file and the case. */
gr_status gr_suite_load_with(const char *path, const char *const *overrides, int n_overrides, gr_suite **out,
                             gr_error *err);
/* The index of the case called name (-1: none). */
int gr_suite_find(const gr_suite *suite, const char *name);
/* "train" or "test". */
const char *gr_split_name(gr_split split);

#endif
