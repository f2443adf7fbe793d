/* godrays farm SCENE ...: ground truths of frames and views (or farm --suite SUITE: of a view
 * suite's cases) as a Slurm job array of parts, merged into the shared ground-truth cache
 * (src/farm/farm.h, docs/farm.md);
 * godrays farm --status DIR: what is done. */
#define _DEFAULT_SOURCE
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "farm/farm.h"
#include "reference/cache.h"
#include "realtime/technique.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays farm SCENE.json [options]      write and submit the Slurm jobs\n"
            "       godrays farm --suite SUITE [options]    the ground truths of a view suite's cases\n"
            "       godrays farm --status DIR               what a farm has done\n"
            "\n"
            "Renders the ground truths of a sequence of frames and views on a Slurm cluster: a job\n"
            "array of parts (godrays reference --tile/--batch-part), a dependent merge job that puts\n"
            "each merged truth in the shared cache (bit for bit a single render's), and a final job\n"
            "(tune or run) that finds them there. Parts already in the cache are not submitted\n"
            "again. How a site sets it up: docs/farm.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR     farm folder: scripts, scene copies, logs (default farm-NAME,\n"
            "                       the scene's or the suite's name)\n"
            "  --cache DIR          shared ground-truth cache (default $GODRAYS_CACHE, else the\n"
            "                       user cache that run uses); every node must see it\n"
            "  --suite SUITE        every case of a view suite (docs/scene-format.md \"Suites\"; the\n"
            "                       --set/--size overrides apply to each): its scene copy in\n"
            "                       DIR/cases/NAME/; --then run (the default) is run --suite\n"
            "  --frames A:B:S       frames A, A+S, ..., B at water.time_s + frame/fps (as tune)\n"
            "  --fps F              frames per second (default 30)\n"
            "  --view YAW,PITCH     an extra camera view (repeatable, at most 8; as tune)\n"
            "  --tiles N            row tiles per image (default 4)\n"
            "  --batch-parts M      batch groups per image (default 1; at most reference.batches)\n"
            "  --partition P        Slurm partition (default: the cluster's)\n"
            "  --time T             time limit per job (sbatch --time)\n"
            "  --cpus N             cores per task (sbatch --cpus-per-task; the render's threads)\n"
            "  --mem SIZE|auto      memory per job (sbatch --mem, e.g. 1536M or 4G) on every job;\n"
            "                       auto: the parts and the merge from the ground truth's memory\n"
            "                       estimate, the final job the site's default (docs/farm.md)\n"
            "  --max-parallel K     at most K array tasks at once\n"
            "  --retries R          attempts per part before it is reported failed (default 3)\n"
            "  --then tune|run|none the final job on the merged truths (default tune;\n"
            "                       --suite: run)\n"
            "  --then-args \"ARGS\"   more arguments for it (tune: default --params with the first\n"
            "                       technique's first two tunable settings, unless ARGS name --params)\n"
            "  --binary PATH        the godrays the jobs run (default: this one)\n"
            "  --set KEY=VALUE, --size WxH   scene overrides (baked into the scene copy)\n"
            "  --dry-run            write the scripts, do not submit (submit later: DIR/submit.sh)\n");
}

static int make_dirs(const char *path)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(tmp, 0755) != 0 && errno != EEXIST) return -1;
            *p = '/';
        }
    return mkdir(tmp, 0755) != 0 && errno != EEXIST ? -1 : 0;
}

static int count_failed(const char *dir, int t, char *last, size_t n)
{
    char p[8400];
    snprintf(p, sizeof p, "%s/logs/part-%d.err", dir, t);
    FILE *f = fopen(p, "r");
    if (!f) return 0;
    char line[1024];
    int failed = 0;
    last[0] = '\0';
    while (fgets(line, sizeof line, f)) {
        if (strstr(line, "FAILED")) failed = 1;
        if (strstr(line, "attempt")) snprintf(last, n, "%s", line);
    }
    fclose(f);
    size_t l = strlen(last);
    if (l && last[l - 1] == '\n') last[l - 1] = '\0';
    return failed;
}

static int status(const char *dir)
{
    gr_farm_plan plan;
    gr_error err = {GR_OK, ""};
    if (gr_farm_load(dir, &plan, &err) != GR_OK) return gr_cli_report("farm", &err);
    int per = plan.tiles * plan.batch_parts, merged = 0;
    printf("farm %s: %d cases x %d parts, cache %s%s%s\n", dir, plan.n_cases, per, plan.cache,
           plan.suite[0] ? ", suite " : "", plan.suite);
    for (int c = 0; c < plan.n_cases; c++) {
        const gr_farm_case *fc = &plan.cases[c];
        merged += fc->merged;
        printf("  case %d%s%s%s%s: %s", c, fc->name[0] ? " " : "", fc->name, fc->args[0] ? " " : "", fc->args,
               fc->merged ? "merged (in the cache)" : "");
        if (!fc->merged) printf("parts %d/%d", fc->parts_done, per);
        for (int r = 0; r < per && !fc->merged; r++) {
            int t = c * per + r;
            char last[1024], p[8400];
            if (count_failed(dir, t, last, sizeof last)) printf("; part %d FAILED (%s/logs/part-%d.err)", t, dir, t);
            snprintf(p, sizeof p, "%s/logs/part-%d.pid", dir, t);
            if (access(p, F_OK) == 0) printf("; part %d running%s%s", t, last[0] ? ": " : "", last);
        }
        printf("\n");
    }
    printf("%d of %d cases in the cache\n", merged, plan.n_cases);
    char jp[8400], line[256], ids[256] = "";
    snprintf(jp, sizeof jp, "%s/jobs.txt", dir);
    FILE *f = fopen(jp, "r");
    if (f) {
        while (fgets(line, sizeof line, f)) {
            char what[32], id[64];
            if (sscanf(line, "%31s %63s", what, id) == 2 && strcmp(id, "-") != 0) {
                size_t l = strlen(ids);
                snprintf(ids + l, sizeof ids - l, "%s%s", l ? "," : "", id);
                printf("job %s: %s\n", what, id);
            }
        }
        fclose(f);
    }
    fflush(stdout);
    if (ids[0]) { /* what Slurm still has of them (squeue is only on a cluster's nodes) */
        pid_t pid = fork();
        if (pid == 0) {
            FILE *nul = freopen("/dev/null", "w", stderr);
            (void)nul;
            execlp("squeue", "squeue", "-h", "-j", ids, "-o", "  slurm: %i %j %T %R", (char *)NULL);
            _exit(127);
        }
        if (pid > 0) waitpid(pid, NULL, 0);
    }
    gr_farm_plan_free(&plan);
    return 0;
}

/* The files the farm folder gets (farm.h) may not be inputs, such as the scene (common/paths);
 * out NULL: the default folder, named after the scene, which no input names before it exists. */
static int check_outputs(gr_args *args, const char *out)
{
    static const char *const names[] = {"scene.json", "farm.json", "parts.sh", "merge.sh", "final.sh", "submit.sh"};
    char p[4200];
    for (size_t k = 0; out && k < sizeof names / sizeof names[0]; k++) {
        snprintf(p, sizeof p, "%s/%s", out, names[k]);
        const int rc = gr_args_note_output(args, "-o", p);
        if (rc) return rc;
    }
    return 0;
}

/* The folder, the cache and the binary as absolute paths (the jobs run elsewhere); the folder
 * and the cache are created. Exit 2 with the message otherwise. */
static int absolute_paths(gr_farm_plan *plan, const char *scene_name, const char *out, const char *cache,
                          const char *binary)
{
    char name[256], buf[PATH_MAX];
    snprintf(name, sizeof name, "farm-%s", scene_name[0] ? scene_name : "scene");
    if (!out) out = name;
    if (make_dirs(out) != 0 || !realpath(out, buf)) {
        fprintf(stderr, "godrays farm: -o %s: cannot create: %s\n", out, strerror(errno));
        return 2;
    }
    snprintf(plan->dir, sizeof plan->dir, "%s", buf);
    if (make_dirs(cache) != 0 || !realpath(cache, buf)) {
        fprintf(stderr, "godrays farm: cache %s: cannot create: %s\n", cache, strerror(errno));
        return 2;
    }
    snprintf(plan->cache, sizeof plan->cache, "%s", buf);
    ssize_t bl = binary ? (realpath(binary, buf) ? (ssize_t)strlen(buf) : -1) : readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (bl < 0) {
        fprintf(stderr, "godrays farm: --binary %s: %s\n", binary ? binary : "(this one)", strerror(errno));
        return 2;
    }
    buf[bl] = '\0';
    snprintf(plan->binary, sizeof plan->binary, "%s", buf);
    return 0;
}

/* tune needs its parameters: without --params in --then-args, the first technique's first
 * tunable settings (`godrays techniques`) are appended. */
static int default_tune_params(gr_farm_plan *plan)
{
    if (!strcmp(plan->then, "tune") && !strstr(plan->then_args, "--params")) {
        /* the first technique's first tunable settings (`godrays techniques`) */
        const gr_technique_class *tc = gr_technique_at(0);
        const gr_param *ex[2];
        const int nex = gr_technique_tune_example(tc, ex, 2);
        if (nex == 0) return gr_cli_usage_error("farm", "--then tune: give --then-args \"--params TECHNIQUE.KEY\"");
        size_t tl = strlen(plan->then_args);
        snprintf(plan->then_args + tl, sizeof plan->then_args - tl, "%s--params %s.%s%s%s%s", tl ? " " : "", tc->name,
                 ex[0]->name, nex > 1 ? "," : "", nex > 1 ? tc->name : "", nex > 1 ? "." : "");
        tl = strlen(plan->then_args);
        if (nex > 1) snprintf(plan->then_args + tl, sizeof plan->then_args - tl, "%s", ex[1]->name);
    }
    return 0;
}

/* A case's scene can be split into parts: no --target-error, the tiles and batch groups within
 * its rows and batches. case_name: a suite case's (NULL: the scene). Exit 2 with the message. */
static int check_scene(const gr_farm_plan *plan, const gr_scene *scene, const char *case_name)
{
    char where[96] = "";
    if (case_name) snprintf(where, sizeof where, "case %s: ", case_name);
    if (scene->reference.target_error > 0.0)
        return gr_cli_usage_error("farm", "%sreference.target_error = %g: parts take the fixed passes of one round; set "
                                  "it to 0 and raise reference.sun_samples or spp instead (docs/farm.md)",
                                  where, scene->reference.target_error);
    if (plan->tiles > scene->camera.height || plan->batch_parts > scene->reference.batches)
        return gr_cli_usage_error("farm", "%s--tiles %d / --batch-parts %d: at most the %d rows / %d batches", where,
                                  plan->tiles, plan->batch_parts, scene->camera.height, scene->reference.batches);
    return 0;
}

/* The farm written: what is left to do, then submit.sh (unless dry). Returns the exit code. */
static int submit(const gr_farm_plan *plan, int dry)
{
    int per = plan->tiles * plan->batch_parts, merged = 0, parts = 0;
    for (int c = 0; c < plan->n_cases; c++) {
        merged += plan->cases[c].merged;
        parts += plan->cases[c].merged ? per : plan->cases[c].parts_done;
    }
    char todo[8192];
    gr_farm_todo(plan, todo, sizeof todo);
    printf("farm %s: %d cases x %d parts (%d tiles x %d batch groups); in the cache: %d cases merged, %d of %d parts\n",
           plan->dir, plan->n_cases, per, plan->tiles, plan->batch_parts, merged, parts, plan->n_cases * per);
    printf("  array tasks to run: %s\n", todo[0] ? todo : "none");
    if (dry) {
        printf("dry run: scripts in %s (parts.sh, merge.sh, final.sh); submit with %s/submit.sh\n", plan->dir, plan->dir);
        return 0;
    }
    fflush(stdout);
    char sub[8400];
    snprintf(sub, sizeof sub, "%s/submit.sh", plan->dir);
    pid_t pid = fork();
    if (pid == 0) {
        execl("/bin/bash", "bash", sub, (char *)NULL);
        _exit(127);
    }
    int wst = 0;
    if (pid < 0 || waitpid(pid, &wst, 0) < 0 || !WIFEXITED(wst) || WEXITSTATUS(wst) != 0) {
        fprintf(stderr, "godrays farm: %s failed (is sbatch on PATH and the cluster up?); the scripts are in %s\n", sub,
                plan->dir);
        return 1;
    }
    printf("status: godrays farm --status %s\n", plan->dir);
    return 0;
}

static int farm_with(gr_args *args)
{
    const char *cmd = "farm", *out = NULL, *v = NULL, *status_dir = NULL, *cache = NULL, *binary = NULL, *suite = NULL;
    gr_farm_plan plan;
    memset(&plan, 0, sizeof plan);
    plan.fps = 30.0;
    plan.tiles = 4;
    plan.batch_parts = 1;
    plan.retries = 3;
    int dry = 0, rc = 0;
    char extra;
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        }
#define INT_OPT(flag, field, lo)                                                                              \
    else if (!strcmp(a, flag)) {                                                                              \
        if (!(rc = gr_args_value(args, &v)) && (sscanf(v, "%d%c", &plan.field, &extra) != 1 || plan.field < (lo))) \
            rc = gr_cli_usage_error(cmd, "%s %s: expected an integer >= %d", flag, v, lo);                    \
    }
#define STR_OPT(flag, field)                                                                                   \
    else if (!strcmp(a, flag)) {                                                                               \
        if (!(rc = gr_args_value(args, &v)) && snprintf(plan.field, sizeof plan.field, "%s", v) >= (int)sizeof plan.field) \
            rc = gr_cli_usage_error(cmd, "%s: too long", flag);                                                \
    }
        if (!strcmp(a, "--dry-run")) dry = 1;
        else if (!strcmp(a, "--status")) rc = gr_args_dir(args, &status_dir);
        else if (!strcmp(a, "-o") || !strcmp(a, "--output")) rc = gr_args_dir(args, &out);
        else if (!strcmp(a, "--cache")) rc = gr_args_dir(args, &cache);
        else if (!strcmp(a, "--binary")) rc = gr_args_value(args, &binary);
        else if (!strcmp(a, "--suite")) rc = gr_args_value(args, &suite);
        else if (!strcmp(a, "--set")) rc = gr_args_take_set(args);
        else if (!strcmp(a, "--size")) rc = gr_args_take_size(args);
        else if (!strcmp(a, "--fps")) {
            if (!(rc = gr_args_value(args, &v)) && (sscanf(v, "%lf%c", &plan.fps, &extra) != 1 || !(plan.fps > 0.0)))
                rc = gr_cli_usage_error(cmd, "--fps %s: expected frames per second > 0", v);
        } else if (!strcmp(a, "--view")) {
            if (plan.n_views >= 8) rc = gr_cli_usage_error(cmd, "--view: at most 8 extra views");
            else if (!(rc = gr_args_value(args, &v))) snprintf(plan.views[plan.n_views++], sizeof plan.views[0], "%s", v);
        }
        INT_OPT("--tiles", tiles, 1)
        INT_OPT("--batch-parts", batch_parts, 1)
        INT_OPT("--cpus", cpus, 1)
        INT_OPT("--retries", retries, 1)
        INT_OPT("--max-parallel", max_parallel, 1)
        STR_OPT("--frames", frames)
        STR_OPT("--partition", partition)
        STR_OPT("--time", time_limit)
        STR_OPT("--mem", mem)
        STR_OPT("--then", then)
        STR_OPT("--then-args", then_args)
        else rc = gr_args_take_scene(args);
    }
    if (rc) return rc;
    if (status_dir)
        return args->scene_path || suite ? gr_cli_usage_error(cmd, "--status DIR takes no scene or suite") : status(status_dir);
    if (suite && args->scene_path) return gr_cli_usage_error(cmd, "--suite %s and the scene %s: give one of them", suite, args->scene_path);
    if (!suite && (rc = gr_args_need_scene(args)) != 0) return rc;
    if (!plan.then[0]) snprintf(plan.then, sizeof plan.then, "%s", suite ? "run" : "tune");
    if (suite && !strcmp(plan.then, "tune"))
        return gr_cli_usage_error(cmd, "--suite with --then tune: tune takes one scene; --then run (run --suite) or none");
    if (suite && (plan.frames[0] || plan.n_views))
        return gr_cli_usage_error(cmd, "--suite with --frames/--view: a suite's cases are its views and times");
    size_t l = (size_t)snprintf(plan.command, sizeof plan.command, "godrays");
    for (int k = 0; k < args->argc && l < sizeof plan.command; k++)
        l += (size_t)snprintf(plan.command + l, sizeof plan.command - l, " %s", args->argv[k]);
    plan.sets = gr_args_sets(args);
    plan.n_sets = args->n_sets;
    gr_error err = {GR_OK, ""};
    if (gr_farm_check(&plan, &err) != GR_OK) return gr_cli_report(cmd, &err); /* before any folder is made */
    if ((rc = check_outputs(args, out)) != 0) return rc;
    if (strcmp(plan.then, "tune") && strcmp(plan.then, "run") && strcmp(plan.then, "none"))
        return gr_cli_usage_error(cmd, "--then %s: expected tune, run or none", plan.then);
    if ((rc = default_tune_params(&plan)) != 0) return rc;
    if (!cache) cache = getenv("GODRAYS_CACHE");
    char user_cache[4096];
    if (!cache || !cache[0]) { /* the cache run and tune use here; the nodes must see it too */
        gr_error cerr = {GR_OK, ""};
        if (gr_cache_dir(user_cache, sizeof user_cache, &cerr) != GR_OK) return gr_cli_report(cmd, &cerr);
        cache = user_cache;
        fprintf(stderr, "godrays farm: note: GODRAYS_CACHE is not set: the jobs use %s, which every node must see at "
                        "that path (docs/farm.md)\n", cache);
    }
    gr_scene *scene = NULL;
    gr_suite *s = NULL;
    if (suite) rc = gr_args_load_suite(args, suite, &s);
    else rc = gr_args_load_scene(args, &scene);
    for (int c = 0; !rc && c < (s ? s->n_cases : 1); c++)
        rc = check_scene(&plan, s ? &s->cases[c].scene : scene, s ? s->cases[c].name : NULL);
    if (!rc) rc = absolute_paths(&plan, s ? s->name : scene->name, out, cache, binary);
    if (!rc && suite && !realpath(suite, plan.suite)) rc = gr_cli_usage_error(cmd, "--suite %s: %s", suite, strerror(errno));
    if (!rc) {
        gr_status st = s ? gr_farm_plan_suite(&plan, s, &err) : gr_farm_plan_cases(&plan, scene, &err);
        if (st == GR_OK) st = gr_farm_write(&plan, scene, s, &err);
        if (st == GR_OK) st = gr_farm_verify_copies(&plan, &err); /* the jobs load the copies: the same keys */
        rc = st != GR_OK ? gr_cli_report(cmd, &err) : submit(&plan, dry);
    }
    gr_farm_plan_free(&plan);
    gr_suite_destroy(s);
    free(scene);
    return rc;
}

int cmd_farm(int argc, char **argv)
{
    return gr_args_main("farm", argc, argv, farm_with);
}
