/* `godrays farm`: ground truths of a sequence of frames and views, split into parts
 * (src/farm/parts.h) and run as a Slurm job array, merged into the ground-truth cache
 * (reference/cache.h) where run, sweep, tune and pareto find them. docs/farm.md.
 *
 * A farm folder holds everything the jobs need, readable and submittable by hand:
 *   scene.json   the scene as normalized JSON (overrides applied): what every job renders
 *                (a suite farm: cases/NAME/scene.json, one per case of the view suite)
 *   parts.sh     the array job: task T renders one part (case, tile, batch group) into
 *                $GODRAYS_CACHE/parts/KEY/, skipping parts and cases already there, and
 *                retrying a failed attempt (a killed process, a crash) up to `retries` times
 *   merge.sh     after the array (whatever its outcome): merges every case's parts into the
 *                cache, or names the missing parts with the tail of their logs (exit 1)
 *   final.sh     after a successful merge: tune (or run) on the merged truths
 *   submit.sh    the sbatch calls with their dependencies; writes jobs.txt
 *   farm.json    the plan (cases, keys, tiles) for `godrays farm --status`
 *   logs/        one log per task and job */
#ifndef GR_FARM_FARM_H
#define GR_FARM_FARM_H

#include <stddef.h>
#include "common/status.h"
#include "scene/scene.h"
#include "suite/suite.h"

#define GR_FARM_MAX_CASES 4096

typedef struct gr_farm_case {
    int has_frame;
    long frame;
    int view;               /* 0: the scene's own camera, k: extra view k - 1 */
    double time_s;          /* water.time_s of the case */
    char args[160];         /* reference arguments that select it ("--frame 10 --fps 30 --view 30,-10") */
    char name[GR_SUITE_NAME_MAX]; /* a suite case's name ("" in a frames farm) */
    char scene[96];         /* the scene file it renders, relative to the farm folder ("scene.json",
                               "cases/NAME/scene.json") */
    char key[48];           /* its ground truth's cache key */
    int merged;             /* its truth is in the cache already */
    int parts_done;         /* parts already in the cache */
} gr_farm_case;

typedef struct gr_farm_plan {
    char dir[4096];         /* farm folder (absolute) */
    char binary[4096];      /* godrays binary the jobs run (absolute) */
    char cache[4096];       /* shared cache folder (absolute): GODRAYS_CACHE in the jobs */
    char partition[128];    /* "" = the site's default */
    char time_limit[64];    /* sbatch --time ("" = the partition's) */
    char frames[64];        /* --frames A:B:S as given ("" = the scene's time only) */
    char views[8][64];      /* --view YAW,PITCH as given */
    int n_views;
    double fps;
    int cpus;               /* --cpus-per-task (0 = not set) */
    int tiles, batch_parts, retries, max_parallel;
    /* sbatch --mem: "" (none: the site's default), a size as sbatch takes it ("1536M", "4G"),
     * written on every job, or "auto": the parts and the merge from the ground truth's memory
     * estimate, the final job the site's default */
    char mem[32];
    double mem_part_b, mem_merge_b; /* "auto": bytes a part and the merge need at most over the
                                       cases (their estimates, taken as the cases are planned) */
    char suite[4096];       /* a suite farm: the suite file (absolute; "" = a frames farm) */
    const char *const *sets; /* the command's overrides (--set, --size) for the final run --suite
                                (borrowed; n_sets of them) */
    int n_sets;
    char then[16];          /* "tune", "run" or "none" */
    char then_args[1024];
    char command[4096];     /* the farm command line, for the scripts' header */
    int n_cases;
    gr_farm_case *cases;    /* malloc'd */
} gr_farm_plan;

/* Fills plan->cases from the scene and plan's frames, fps and views: each case's key and
 * what the cache already holds (merged truth, parts). GR_E_USAGE for bad --frames/--view. */
gr_status gr_farm_plan_cases(gr_farm_plan *plan, const gr_scene *scene, gr_error *err);
/* Fills plan->cases with the cases of a view suite (suite/suite.h; loaded with the command's
 * overrides), each rendering its own scene copy cases/NAME/scene.json, and what the cache holds
 * of them. plan->frames and views must be empty. */
gr_status gr_farm_plan_suite(gr_farm_plan *plan, const gr_suite *suite, gr_error *err);
void gr_farm_plan_free(gr_farm_plan *plan); /* frees the cases; accepts NULL */

/* Path of part (tile i, batch group j) of case c in the cache. */
void gr_farm_part_path(const gr_farm_plan *plan, int c, int i, int j, char *buf, size_t n);

/* Array indices of the parts still to render ("0-3,8,10-11"; "" if none) into buf. */
void gr_farm_todo(const gr_farm_plan *plan, char *buf, size_t n);

/* GR_E_USAGE naming the option when a value that goes into the scripts cannot be written there
 * safely: a control character in any of them (a line break would start a command), or in
 * --frames and --view anything but what numbers are written with (they become unquoted words
 * of a case's arguments). Every value is quoted in the scripts: single quotes for bash, double
 * quotes on #SBATCH lines (which sbatch splits itself); --then-args is split at blanks into
 * words, each quoted. */
gr_status gr_farm_check(const gr_farm_plan *plan, gr_error *err);

/* Writes the farm folder (scene.json, parts.sh, merge.sh, final.sh, submit.sh, farm.json,
 * logs/), after gr_farm_check; each file atomically (common/outfile). GR_E_IO naming the file.
 * scene: a frames farm's scene (gr_farm_plan_cases); suite: a suite farm's (gr_farm_plan_suite),
 * whose cases' scenes go to cases/NAME/scene.json. Exactly one of them is not NULL. */
gr_status gr_farm_write(const gr_farm_plan *plan, const gr_scene *scene, const gr_suite *suite, gr_error *err);

/* The jobs load the scene copies gr_farm_write wrote: each must reload to its case's cache key
 * (GR_E_RUNTIME naming the file and both keys otherwise). */
gr_status gr_farm_verify_copies(const gr_farm_plan *plan, gr_error *err);

/* Reads farm.json of a farm folder back into plan (cases with keys and args; the cache
 * states are refreshed). GR_E_INPUT naming the file. */
gr_status gr_farm_load(const char *dir, gr_farm_plan *plan, gr_error *err);

#endif
