#include "farm/farm.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "common/outfile.h"
#include "reference/cache.h"
#include "reference/truth.h"
#include "tune/objective.h"
#include "tune/session.h"

static int exists(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0;
}

void gr_farm_part_path(const gr_farm_plan *plan, int c, int i, int j, char *buf, size_t n)
{
    snprintf(buf, n, "%s/parts/%s/tile-%d-of-%d.batches-%d-of-%d.part", plan->cache, plan->cases[c].key, i, plan->tiles, j,
             plan->batch_parts);
}

/* What the cache holds for each case: the merged truth, its parts. */
static void refresh(gr_farm_plan *plan)
{
    char p[8400];
    for (int c = 0; c < plan->n_cases; c++) {
        gr_farm_case *fc = &plan->cases[c];
        gr_cache_path(plan->cache, fc->key, p, sizeof p, NULL);
        fc->merged = exists(p);
        fc->parts_done = 0;
        for (int i = 0; i < plan->tiles; i++)
            for (int j = 0; j < plan->batch_parts; j++) {
                gr_farm_part_path(plan, c, i, j, p, sizeof p);
                fc->parts_done += exists(p);
            }
    }
}

/* With plan->mem "auto": case scene cs's memory estimate into the plan's maxima (a part: the
 * whole render's, as it allocates the image's sums and touches its rows'; the merge: every
 * part's sums read, the merged sums, the image: docs/farm.md "Memory"). Else nothing. */
static gr_status case_memory(gr_farm_plan *plan, const gr_scene *cs, gr_error *err)
{
    if (strcmp(plan->mem, "auto") != 0) return GR_OK;
    double fixed = 0.0, pixels = 0.0, sets = 0.0;
    gr_status st = gr_truth_memory(cs, &fixed, &pixels, &sets, err);
    plan->mem_part_b = fmax(plan->mem_part_b, fixed + pixels + sets);
    plan->mem_merge_b = fmax(plan->mem_merge_b, fixed + 2.0 * pixels);
    return st;
}

gr_status gr_farm_plan_cases(gr_farm_plan *plan, const gr_scene *scene, gr_error *err)
{
    double times[GR_FARM_MAX_CASES];
    long frames[GR_FARM_MAX_CASES];
    int nt = 0;
    if (plan->frames[0]) {
        gr_status st = gr_tune_parse_frames("--frames", plan->frames, plan->fps, times, GR_FARM_MAX_CASES, &nt, err);
        if (st != GR_OK) return st;
        long a = 0, b = 0, s = 1;
        sscanf(plan->frames, "%ld:%ld:%ld", &a, &b, &s);
        for (int k = 0; k < nt; k++) frames[k] = a + k * s;
    }
    int nv = 1 + plan->n_views, n = (nt ? nt : 1) * nv;
    if (n > GR_FARM_MAX_CASES) return gr_fail(err, GR_E_USAGE, "--frames x --view: %d cases, at most %d", n, GR_FARM_MAX_CASES);
    plan->cases = calloc((size_t)n, sizeof *plan->cases);
    if (!plan->cases) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    plan->n_cases = n;
    gr_scene *cs = malloc(sizeof *cs);
    if (!cs) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    gr_status st = GR_OK;
    for (int c = 0; c < n && st == GR_OK; c++) {
        gr_farm_case *fc = &plan->cases[c];
        int t = c / nv, v = c % nv;
        fc->has_frame = nt > 0;
        fc->frame = nt ? frames[t] : 0;
        fc->view = v;
        snprintf(fc->scene, sizeof fc->scene, "scene.json");
        /* the case as tune makes it (water.time_s + frame / fps), so the keys are tune's */
        fc->time_s = nt ? times[t] + scene->water.time_s : scene->water.time_s;
        gr_tune_view view = {0.0, 0.0};
        size_t l = 0;
        fc->args[0] = '\0';
        if (nt) l += (size_t)snprintf(fc->args + l, sizeof fc->args - l, "--frame %ld --fps %.17g", fc->frame, plan->fps);
        if (v) {
            st = gr_tune_parse_view("--view", plan->views[v - 1], &view, err);
            if (st != GR_OK) break;
            snprintf(fc->args + l, sizeof fc->args - l, "%s--view %s", l ? " " : "", plan->views[v - 1]);
        }
        st = gr_tune_make_case(scene, fc->time_s, v ? &view : NULL, cs, err);
        if (st == GR_OK) st = gr_cache_key(cs, fc->key, err);
        if (st == GR_OK) st = case_memory(plan, cs, err);
    }
    free(cs);
    if (st == GR_OK) refresh(plan);
    return st;
}

gr_status gr_farm_plan_suite(gr_farm_plan *plan, const gr_suite *suite, gr_error *err)
{
    if (plan->frames[0] || plan->n_views > 0) return gr_fail(err, GR_E_USAGE, "--suite: takes no --frames or --view");
    if (suite->n_cases > GR_FARM_MAX_CASES)
        return gr_fail(err, GR_E_USAGE, "%s: %d cases, at most %d", suite->path, suite->n_cases, GR_FARM_MAX_CASES);
    plan->cases = calloc((size_t)suite->n_cases, sizeof *plan->cases);
    if (!plan->cases) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    plan->n_cases = suite->n_cases;
    gr_status st = GR_OK;
    for (int c = 0; c < suite->n_cases && st == GR_OK; c++) {
        const gr_suite_case *sc = &suite->cases[c];
        gr_farm_case *fc = &plan->cases[c];
        /* the case's scene is the one run --suite and pareto --suite ask the provider for:
         * its key is theirs */
        snprintf(fc->name, sizeof fc->name, "%s", sc->name);
        snprintf(fc->scene, sizeof fc->scene, "cases/%s/scene.json", sc->name);
        fc->time_s = sc->scene.water.time_s;
        st = gr_cache_key(&sc->scene, fc->key, err);
        if (st == GR_OK) st = case_memory(plan, &sc->scene, err);
    }
    if (st == GR_OK) refresh(plan);
    return st;
}

/* The #SBATCH --mem line of a job: auto's figure in MiB (rounded up), or the size given */
static void mem_line(FILE *f, const gr_farm_plan *plan, double auto_b)
{
    if (!strcmp(plan->mem, "auto")) {
        if (auto_b > 0.0) fprintf(f, "#SBATCH --mem=%.0fM\n", ceil(auto_b / 1048576.0));
    } else if (plan->mem[0]) {
        fprintf(f, "#SBATCH --mem=%s\n", plan->mem);
    }
}

void gr_farm_plan_free(gr_farm_plan *plan)
{
    if (!plan) return;
    free(plan->cases);
    plan->cases = NULL;
    plan->n_cases = 0;
}

void gr_farm_todo(const gr_farm_plan *plan, char *buf, size_t n)
{
    int per = plan->tiles * plan->batch_parts, total = plan->n_cases * per, start = -1;
    size_t l = 0;
    buf[0] = '\0';
    char p[8400];
    for (int t = 0; t <= total; t++) {
        int todo = 0;
        if (t < total) {
            int c = t / per, r = t % per;
            gr_farm_part_path(plan, c, r / plan->batch_parts, r % plan->batch_parts, p, sizeof p);
            todo = !plan->cases[c].merged && !exists(p);
        }
        if (todo && start < 0) start = t;
        if (!todo && start >= 0) {
            if (l < n)
                l += (size_t)snprintf(buf + l, n - l, "%s%d", l ? "," : "", start);
            if (t - 1 > start && l < n) l += (size_t)snprintf(buf + l, n - l, "-%d", t - 1);
            start = -1;
        }
    }
}

/* ---- writing ---- */

/* s single-quoted for the shell */
static void sq(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'') fputs("'\\''", f);
        else fputc(*s, f);
    }
    fputc('\'', f);
}

/* " FLAG 'v'": an option and its value, quoted */
static void sq_flag(FILE *f, const char *flag, const char *v)
{
    fprintf(f, " %s ", flag);
    sq(f, v);
}

/* s double-quoted for a #SBATCH line, which sbatch splits into words itself (no shell): inside
 * quotes a space or '#' is part of the value, and '"' and '\\' are escaped with a backslash */
static void dq(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') fputc('\\', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* The words of s (split at spaces and tabs), each single-quoted: --then-args "A B" becomes the
 * arguments 'A' 'B', and nothing in them ($(...), `...`, ;, globs) reaches the shell as code. */
static void sq_words(FILE *f, const char *s)
{
    char w[1024];
    while (*s) {
        size_t n = strcspn(s, " \t");
        if (n > 0 && n < sizeof w) {
            memcpy(w, s, n);
            w[n] = '\0';
            fputc(' ', f);
            sq(f, w);
        }
        s += n;
        s += strspn(s, " \t");
    }
}

/* A value that goes into a script: a control character (a line break ends a #SBATCH line or a
 * comment and starts a command) is refused. */
static gr_status no_control(const char *what, const char *v, gr_error *err)
{
    for (const unsigned char *c = (const unsigned char *)v; *c; c++)
        if (*c < 0x20 || *c == 0x7f)
            return gr_fail(err, GR_E_USAGE, "%s '%s': control character 0x%02x: refusing to write it into a job script",
                           what, v, *c);
    return GR_OK;
}

/* A value that goes into a case's arguments, which the scripts split into words unquoted:
 * only what numbers are written with. */
static gr_status plain_word(const char *what, const char *v, gr_error *err)
{
    for (const char *c = v; *c; c++)
        if (!strchr("0123456789+-.,:eEinfatyINFATY", *c))
            return gr_fail(err, GR_E_USAGE, "%s '%s': unexpected character '%c' (numbers only)", what, v, *c);
    return GR_OK;
}

/* "", "auto" or a size as sbatch --mem takes it (digits, then K, M, G, T or nothing for M) */
static gr_status check_mem(const char *mem, gr_error *err)
{
    if (!mem[0] || !strcmp(mem, "auto")) return GR_OK;
    size_t n = strspn(mem, "0123456789");
    int ok = n > 0 && n <= 12 && (mem[n] == '\0' || (strchr("KMGT", mem[n]) && mem[n + 1] == '\0'));
    if (ok) {
        ok = 0;
        for (size_t k = 0; k < n; k++) ok |= mem[k] != '0';
    }
    if (!ok)
        return gr_fail(err, GR_E_USAGE, "--mem %s: expected auto or a size as sbatch --mem takes it (a number > 0, then K, M, "
                                        "G or T; no unit: M), e.g. 1536M or 4G", mem);
    return GR_OK;
}

gr_status gr_farm_check(const gr_farm_plan *plan, gr_error *err)
{
    const struct { const char *what, *v; } vals[] = {
        {"-o", plan->dir},           {"--cache", plan->cache},    {"--binary", plan->binary},
        {"--partition", plan->partition}, {"--time", plan->time_limit}, {"--frames", plan->frames},
        {"--then", plan->then},      {"--then-args", plan->then_args}, {"the command line", plan->command},
        {"--suite", plan->suite},
    };
    gr_status st = GR_OK;
    for (size_t k = 0; st == GR_OK && k < sizeof vals / sizeof vals[0]; k++) st = no_control(vals[k].what, vals[k].v, err);
    if (st == GR_OK) st = plain_word("--frames", plan->frames, err);
    for (int v = 0; st == GR_OK && v < plan->n_views; v++) st = plain_word("--view", plan->views[v], err);
    for (int k = 0; st == GR_OK && k < plan->n_sets; k++) st = no_control("--set", plan->sets[k], err);
    if (st == GR_OK) st = check_mem(plan->mem, err);
    return st;
}

typedef struct wfile { gr_outfile o; FILE *f; } wfile;

static gr_status wopen(wfile *w, const gr_farm_plan *plan, const char *name, gr_error *err)
{
    char path[8400];
    snprintf(path, sizeof path, "%s/%s", plan->dir, name);
    gr_status st = gr_outfile_open(&w->o, path, err); /* atomic, never over an input: common/outfile */
    w->f = w->o.f;
    return st;
}

static gr_status wclose(wfile *w, int exec, gr_error *err)
{
    if (exec && chmod(w->o.tmp, 0755) != 0) {
        const int e = errno;
        gr_status st = gr_fail(err, GR_E_IO, "%s: cannot make it executable: %s", w->o.path, strerror(e));
        gr_outfile_abort(&w->o);
        return st;
    }
    return gr_outfile_commit(&w->o, 0, err);
}

static void header(FILE *f, const gr_farm_plan *plan, const char *what)
{
    char date[64];
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(date, sizeof date, "%Y-%m-%d %H:%M:%SZ", &tm);
    fprintf(f, "#!/bin/bash\n# godrays farm: %s\n# Written by `%s` on %s (docs/farm.md).\n", what, plan->command, date);
}

static void sbatch_common(FILE *f, const gr_farm_plan *plan, const char *name, const char *log)
{
    char p[8400];
    fprintf(f, "#SBATCH --job-name=%s\n#SBATCH --output=", name);
    snprintf(p, sizeof p, "%s/logs/%s.out", plan->dir, log);
    dq(f, p);
    fputs("\n#SBATCH --error=", f);
    snprintf(p, sizeof p, "%s/logs/%s.err", plan->dir, log);
    dq(f, p);
    fputc('\n', f);
    if (plan->partition[0]) {
        fputs("#SBATCH --partition=", f);
        dq(f, plan->partition);
        fputc('\n', f);
    }
    if (plan->time_limit[0]) {
        fputs("#SBATCH --time=", f);
        dq(f, plan->time_limit);
        fputc('\n', f);
    }
}

static void vars(FILE *f, const gr_farm_plan *plan)
{
    fputs("set -u\n# everything the job needs: the binary, the scene copy, the shared cache\nGODRAYS=", f);
    sq(f, plan->binary);
    fputs("\nFARM=", f);
    sq(f, plan->dir);
    fputs("\nexport GODRAYS_CACHE=", f);
    sq(f, plan->cache);
    fprintf(f, "\nTILES=%d\nBATCH_PARTS=%d\n", plan->tiles, plan->batch_parts);
    fputs("# case C: its scene copy (in $FARM), its reference arguments and its ground truth's cache key\nCASE_SCENES=(", f);
    for (int c = 0; c < plan->n_cases; c++) {
        fputs(c ? (c % 3 ? " " : "\n             ") : "", f);
        sq(f, plan->cases[c].scene);
    }
    fputs(")\nCASE_ARGS=(", f);
    for (int c = 0; c < plan->n_cases; c++) {
        fputs(c ? "\n           " : "", f);
        sq(f, plan->cases[c].args);
    }
    fputs(")\nCASE_KEYS=(", f);
    for (int c = 0; c < plan->n_cases; c++) fprintf(f, "%s%s", c ? (c % 3 ? " " : "\n           ") : "", plan->cases[c].key);
    fputs(")\n", f);
}

/* The scene copy rel (relative to the farm folder, its folder made) of one case's scene. */
static gr_status write_scene(const gr_farm_plan *plan, const char *rel, const gr_scene *scene, gr_error *err)
{
    char p[8400];
    const char *slash = strrchr(rel, '/');
    if (slash) { /* cases/NAME/: both levels */
        for (const char *q = strchr(rel, '/'); q && q <= slash; q = strchr(q + 1, '/')) {
            snprintf(p, sizeof p, "%s/%.*s", plan->dir, (int)(q - rel), rel);
            if (mkdir(p, 0755) != 0 && errno != EEXIST) return gr_fail(err, GR_E_IO, "%s: cannot create: %s", p, strerror(errno));
        }
    }
    char *js = gr_scene_to_json(scene);
    if (!js) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    wfile w;
    gr_status st = wopen(&w, plan, rel, err);
    if (st == GR_OK) {
        fputs(js, w.f);
        fputc('\n', w.f);
        st = wclose(&w, 0, err);
    }
    free(js);
    return st;
}

/* final.sh: the job after a successful merge; its truths come from the cache. */
static gr_status write_final(const gr_farm_plan *plan, gr_error *err)
{
    wfile w;
    gr_status st = wopen(&w, plan, "final.sh", err);
    if (st != GR_OK) return st;
    FILE *f = w.f;
    header(f, plan, "the final job on the merged ground truths (found in the cache)");
    sbatch_common(f, plan, "godrays-final", "final");
    if (plan->cpus > 0) fprintf(f, "#SBATCH --cpus-per-task=%d\n", plan->cpus);
    mem_line(f, plan, 0.0); /* auto: the site's default (tune and run are not estimated) */
    fputs("set -u\nGODRAYS=", f);
    sq(f, plan->binary);
    fputs("\nFARM=", f);
    sq(f, plan->dir);
    if (!plan->suite[0]) fputs("\nSCENE=\"$FARM/scene.json\"", f);
    fputs("\nexport GODRAYS_CACHE=", f);
    sq(f, plan->cache);
    fputc('\n', f);
    if (plan->suite[0] && !strcmp(plan->then, "run")) {
        /* the suite itself (its cases' scene files must be visible here), with the farm's
         * overrides: the cases' keys are the parts' */
        fputs("\"$GODRAYS\" run", f);
        sq_flag(f, "--suite", plan->suite);
        for (int k = 0; k < plan->n_sets; k++) sq_flag(f, "--set", plan->sets[k]);
        fputs(" -o \"$FARM/run\"", f);
        sq_words(f, plan->then_args);
        fputc('\n', f);
    } else if (!strcmp(plan->then, "tune")) {
        fputs("\"$GODRAYS\" tune \"$SCENE\"", f);
        if (plan->frames[0]) {
            sq_flag(f, "--frames", plan->frames);
            fprintf(f, " --fps %.17g", plan->fps);
        }
        for (int v = 0; v < plan->n_views; v++) sq_flag(f, "--view", plan->views[v]);
        fputs(" --quiet -o \"$FARM/tune\"", f);
        sq_words(f, plan->then_args);
        fputc('\n', f);
    } else if (!strcmp(plan->then, "run")) {
        fputs("# run takes the scene's own view; each frame's water time as tune computes it\nfail=0\n", f);
        for (int c = 0; c < plan->n_cases; c++)
            if (plan->cases[c].view == 0) {
                fprintf(f, "\"$GODRAYS\" run \"$SCENE\" --set water.time_s=%.17g --quiet -o \"$FARM/run/case-%d\"",
                        plan->cases[c].time_s, c);
                sq_words(f, plan->then_args);
                fputs(" || fail=1\n", f);
            }
        fputs("exit $fail\n", f);
    } else {
        fputs("echo \"nothing to do (farm --then none)\"\n", f);
    }
    return wclose(&w, 1, err);
}

gr_status gr_farm_verify_copies(const gr_farm_plan *plan, gr_error *err)
{
    gr_scene *copy = malloc(sizeof *copy);
    if (!copy) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    gr_farm_plan check = *plan; /* a frames farm: the cases planned again from the one copy */
    check.cases = NULL;
    check.n_cases = 0;
    check.mem[0] = '\0'; /* their keys only: no memory estimates */
    char p[8400], key[48];
    gr_status st = GR_OK;
    for (int c = 0; st == GR_OK && c < plan->n_cases; c++) {
        const gr_farm_case *fc = &plan->cases[c];
        snprintf(p, sizeof p, "%s/%s", plan->dir, fc->scene);
        if (plan->suite[0] || c == 0) st = gr_scene_load_file(p, NULL, 0, copy, err);
        if (st == GR_OK && plan->suite[0]) st = gr_cache_key(copy, key, err);
        else if (st == GR_OK && c == 0) st = gr_farm_plan_cases(&check, copy, err);
        if (st == GR_OK && !plan->suite[0]) snprintf(key, sizeof key, "%s", check.cases[c].key);
        if (st == GR_OK && strcmp(key, fc->key) != 0)
            st = gr_fail(err, GR_E_RUNTIME, "%s: case %d reloads with cache key %s, not %s", p, c, key, fc->key);
    }
    gr_farm_plan_free(&check);
    free(copy);
    return st;
}

gr_status gr_farm_write(const gr_farm_plan *plan, const gr_scene *scene, const gr_suite *suite, gr_error *err)
{
    gr_status cst = gr_farm_check(plan, err);
    if (cst != GR_OK) return cst;
    if (!scene == !suite) return gr_fail(err, GR_E_USAGE, "farm: a scene or a suite (one of them)");
    char p[8400];
    snprintf(p, sizeof p, "%s/logs", plan->dir);
    if (mkdir(plan->dir, 0755) != 0 && errno != EEXIST)
        return gr_fail(err, GR_E_IO, "%s: cannot create: %s", plan->dir, strerror(errno));
    if (mkdir(p, 0755) != 0 && errno != EEXIST) return gr_fail(err, GR_E_IO, "%s: cannot create: %s", p, strerror(errno));
    wfile w;
    gr_status st = GR_OK;
    if (scene) st = write_scene(plan, "scene.json", scene, err);
    for (int c = 0; suite && c < plan->n_cases && st == GR_OK; c++)
        st = write_scene(plan, plan->cases[c].scene, &suite->cases[c].scene, err);
    if (st != GR_OK) return st;
    int per = plan->tiles * plan->batch_parts;

    /* parts.sh */
    if ((st = wopen(&w, plan, "parts.sh", err)) != GR_OK) return st;
    FILE *f = w.f;
    header(f, plan, "the ground-truth parts, one per array task");
    fprintf(f,
            "# Task T renders case T / %d, tile (T %% %d) / %d, batch group T %% %d into\n"
            "# $GODRAYS_CACHE/parts/KEY/ (skipped when that part or the case's merged truth is there).\n"
            "# A failed attempt (killed, crashed) is retried up to RETRIES times; bad input (exit 2) is not.\n"
            "# By hand: sbatch --array=0-%d parts.sh, or bash parts.sh T to run task T here.\n",
            per, per, plan->batch_parts, plan->batch_parts, plan->n_cases * per - 1);
    sbatch_common(f, plan, "godrays-parts", "part-%a");
    if (plan->cpus > 0) fprintf(f, "#SBATCH --cpus-per-task=%d\n", plan->cpus);
    mem_line(f, plan, plan->mem_part_b);
    fputs("#SBATCH --requeue\n", f);
    vars(f, plan);
    fprintf(f, "RETRIES=%d\n", plan->retries);
    fputs("T=${1:-${SLURM_ARRAY_TASK_ID:?not an array task: give the task number as the argument}}\n"
          "C=$((T / (TILES * BATCH_PARTS))); R=$((T % (TILES * BATCH_PARTS)))\n"
          "I=$((R / BATCH_PARTS)); J=$((R % BATCH_PARTS)); KEY=${CASE_KEYS[$C]}\n"
          "PART=\"$GODRAYS_CACHE/parts/$KEY/tile-$I-of-$TILES.batches-$J-of-$BATCH_PARTS.part\"\n"
          "if [ -e \"$GODRAYS_CACHE/reference-$KEY.exr\" ] || [ -e \"$PART\" ]; then\n"
          "  echo \"part $T: already in the cache\"; exit 0\n"
          "fi\n"
          "mkdir -p \"$GODRAYS_CACHE/parts/$KEY\"\n"
          "attempt=1\n"
          "while :; do\n"
          "  echo \"part $T (case $C: ${CASE_SCENES[$C]} ${CASE_ARGS[$C]}; tile $I/$TILES; batches $J/$BATCH_PARTS): attempt $attempt on $(hostname) at $(date -u +%FT%TZ)\"\n"
          "  start=$(date +%s.%N)\n"
          "  # shellcheck disable=SC2086 (the case's arguments are words)\n"
          "  \"$GODRAYS\" reference \"$FARM/${CASE_SCENES[$C]}\" ${CASE_ARGS[$C]} --tile \"$I/$TILES\" --batch-part \"$J/$BATCH_PARTS\" \\\n"
          "      --threads \"${SLURM_CPUS_PER_TASK:-0}\" --quiet -o \"$PART\" &\n"
          "  pid=$!\n"
          "  echo $pid > \"$FARM/logs/part-$T.pid\"\n"
          "  wait $pid; rc=$?\n"
          "  rm -f \"$FARM/logs/part-$T.pid\"\n"
          "  if [ $rc -eq 0 ]; then\n"
          "    echo \"part $T: done in $(awk \"BEGIN { print $(date +%s.%N) - $start }\") s\"; exit 0\n"
          "  fi\n"
          "  echo \"part $T: attempt $attempt failed (exit $rc)\" >&2\n"
          "  if [ $rc -eq 2 ]; then echo \"part $T: FAILED (bad input, not retried)\" >&2; exit 2; fi\n"
          "  if [ $attempt -ge $RETRIES ]; then echo \"part $T: FAILED after $attempt attempts\" >&2; exit 1; fi\n"
          "  attempt=$((attempt + 1))\n"
          "done\n",
          f);
    if ((st = wclose(&w, 1, err)) != GR_OK) return st;

    /* merge.sh */
    if ((st = wopen(&w, plan, "merge.sh", err)) != GR_OK) return st;
    f = w.f;
    header(f, plan, "merge each case's parts into the ground-truth cache");
    fputs("# An array after the parts (whatever their outcome): task C merges case C (bash merge.sh:\n"
          "# every case, here). A case whose truth is cached is skipped; a case with missing parts is\n"
          "# reported with the tail of their logs (exit 1).\n",
          f);
    sbatch_common(f, plan, "godrays-merge", "merge-%a");
    mem_line(f, plan, plan->mem_merge_b);
    vars(f, plan);
    fputs("mkdir -p \"$FARM/truth\"\n"
          "fail=0\n"
          "CASES=(\"${!CASE_KEYS[@]}\")\n"
          "if [ -n \"${SLURM_ARRAY_TASK_ID:-}\" ]; then CASES=(\"$SLURM_ARRAY_TASK_ID\"); fi\n"
          "for C in \"${CASES[@]}\"; do\n"
          "  KEY=${CASE_KEYS[$C]}\n"
          "  if [ -e \"$GODRAYS_CACHE/reference-$KEY.exr\" ]; then echo \"case $C: in the cache\"; continue; fi\n"
          "  parts=(); missing=0\n"
          "  for ((I = 0; I < TILES; I++)); do for ((J = 0; J < BATCH_PARTS; J++)); do\n"
          "    P=\"$GODRAYS_CACHE/parts/$KEY/tile-$I-of-$TILES.batches-$J-of-$BATCH_PARTS.part\"\n"
          "    T=$((C * TILES * BATCH_PARTS + I * BATCH_PARTS + J))\n"
          "    if [ -e \"$P\" ]; then parts+=(\"$P\"); continue; fi\n"
          "    missing=1\n"
          "    echo \"case $C (${CASE_SCENES[$C]} ${CASE_ARGS[$C]}): part $T missing (tile $I, batches $J); its log $FARM/logs/part-$T.err:\" >&2\n"
          "    tail -n 5 \"$FARM/logs/part-$T.err\" 2>/dev/null | sed 's/^/    /' >&2\n"
          "  done; done\n"
          "  if [ $missing -ne 0 ]; then fail=1; continue; fi\n"
          "  start=$(date +%s.%N)\n"
          "  if \"$GODRAYS\" merge \"${parts[@]}\" --cache --no-preview -o \"$FARM/truth/case-$C.exr\"; then\n"
          "    echo \"case $C: merged ${#parts[@]} parts in $(awk \"BEGIN { print $(date +%s.%N) - $start }\") s\"\n"
          "  else fail=1; fi\n"
          "done\n"
          "exit $fail\n",
          f);
    if ((st = wclose(&w, 1, err)) != GR_OK) return st;

    if ((st = write_final(plan, err)) != GR_OK) return st;

    /* submit.sh */
    char todo[8192];
    gr_farm_todo(plan, todo, sizeof todo);
    int unmerged = 0;
    for (int c = 0; c < plan->n_cases; c++) unmerged += !plan->cases[c].merged;
    if ((st = wopen(&w, plan, "submit.sh", err)) != GR_OK) return st;
    f = w.f;
    header(f, plan, "submit the parts, the merge and the final job");
    fputs("# The array lists the parts not yet in the cache when this was written (a resubmission\n"
          "# skips the rest; each task checks again when it starts). Job ids go to jobs.txt.\n"
          "set -eu\nFARM=",
          f);
    sq(f, plan->dir);
    fprintf(f, "\ncd \"$FARM\"\nARRAY=\"%s\"   # of 0-%d\n", todo, plan->n_cases * per - 1);
    if (plan->max_parallel > 0) fprintf(f, "MAX_PARALLEL=\"%%%d\"   # at most this many tasks at once\n", plan->max_parallel);
    else fputs("MAX_PARALLEL=\"\"   # \"%K\": at most K tasks at once (farm --max-parallel K)\n", f);
    char mtodo[8192] = "";
    for (int c = 0, start = -1; c <= plan->n_cases; c++) { /* the cases still to merge */
        int todo_c = c < plan->n_cases && !plan->cases[c].merged;
        size_t l = strlen(mtodo);
        if (todo_c && start < 0) start = c;
        if (!todo_c && start >= 0) {
            if (c - 1 > start) snprintf(mtodo + l, sizeof mtodo - l, "%s%d-%d", l ? "," : "", start, c - 1);
            else snprintf(mtodo + l, sizeof mtodo - l, "%s%d", l ? "," : "", start);
            start = -1;
        }
    }
    fprintf(f, "MERGE_ARRAY=\"%s\"   # cases whose truth is not in the cache yet (%d)\n", mtodo, unmerged);
    fputs("P=\"\"; M=\"\"; F=\"\"\n"
          "if [ -n \"$ARRAY\" ]; then P=$(sbatch --parsable --array=\"$ARRAY$MAX_PARALLEL\" parts.sh); P=${P%%;*}; fi\n"
          "if [ -n \"$MERGE_ARRAY\" ]; then\n"
          "  M=$(sbatch --parsable --array=\"$MERGE_ARRAY\" ${P:+--dependency=afterany:$P} merge.sh); M=${M%%;*}\n"
          "fi\n",
          f);
    if (strcmp(plan->then, "none") != 0)
        fputs("F=$(sbatch --parsable ${M:+--dependency=afterok:$M} final.sh); F=${F%%;*}\n", f);
    fputs("printf 'parts %s\\nmerge %s\\nfinal %s\\n' \"${P:--}\" \"${M:--}\" \"${F:--}\" > jobs.txt\n"
          "echo \"submitted: parts ${P:--} (tasks ${ARRAY:-none}), merge ${M:--}, final ${F:--}\"\n",
          f);
    if ((st = wclose(&w, 1, err)) != GR_OK) return st;

    /* farm.json */
    cJSON *j = cJSON_CreateObject();
    if (!j) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    cJSON_AddStringToObject(j, "format", "godrays-farm-1");
    cJSON_AddStringToObject(j, "command", plan->command);
    cJSON_AddStringToObject(j, "binary", plan->binary);
    cJSON_AddStringToObject(j, "cache", plan->cache);
    cJSON_AddNumberToObject(j, "tiles", plan->tiles);
    cJSON_AddNumberToObject(j, "batch_parts", plan->batch_parts);
    cJSON_AddStringToObject(j, "then", plan->then);
    if (plan->suite[0]) cJSON_AddStringToObject(j, "suite", plan->suite);
    cJSON *arr = cJSON_AddArrayToObject(j, "cases");
    for (int c = 0; arr && c < plan->n_cases; c++) {
        cJSON *o = cJSON_CreateObject();
        if (!o) break;
        cJSON_AddStringToObject(o, "args", plan->cases[c].args);
        cJSON_AddStringToObject(o, "scene", plan->cases[c].scene);
        if (plan->cases[c].name[0]) cJSON_AddStringToObject(o, "name", plan->cases[c].name);
        cJSON_AddStringToObject(o, "key", plan->cases[c].key);
        cJSON_AddNumberToObject(o, "view", plan->cases[c].view);
        cJSON_AddNumberToObject(o, "time_s", plan->cases[c].time_s);
        cJSON_AddItemToArray(arr, o);
    }
    char *txt = cJSON_Print(j);
    cJSON_Delete(j);
    if (!txt) return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    st = wopen(&w, plan, "farm.json", err);
    if (st == GR_OK) {
        fputs(txt, w.f);
        fputc('\n', w.f);
        st = wclose(&w, 0, err);
    }
    cJSON_free(txt);
    return st;
}

gr_status gr_farm_load(const char *dir, gr_farm_plan *plan, gr_error *err)
{
    memset(plan, 0, sizeof *plan);
    char p[8400];
    snprintf(p, sizeof p, "%s/farm.json", dir);
    FILE *f = fopen(p, "rb");
    if (!f) return gr_fail(err, GR_E_INPUT, "%s: cannot open: %s (not a farm folder?)", p, strerror(errno));
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n > 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = buf ? fread(buf, 1, (size_t)n, f) : 0;
    fclose(f);
    if (!buf || got != (size_t)n) {
        free(buf);
        return gr_fail(err, GR_E_INPUT, "%s: cannot read", p);
    }
    buf[n] = '\0';
    cJSON *j = cJSON_Parse(buf);
    free(buf);
    const cJSON *cases = j ? cJSON_GetObjectItemCaseSensitive(j, "cases") : NULL;
    const cJSON *cache = j ? cJSON_GetObjectItemCaseSensitive(j, "cache") : NULL;
    const cJSON *tiles = j ? cJSON_GetObjectItemCaseSensitive(j, "tiles") : NULL;
    const cJSON *bp = j ? cJSON_GetObjectItemCaseSensitive(j, "batch_parts") : NULL;
    if (!cJSON_IsArray(cases) || !cJSON_IsString(cache) || !cJSON_IsNumber(tiles) || !cJSON_IsNumber(bp) ||
        tiles->valueint < 1 || bp->valueint < 1) {
        cJSON_Delete(j);
        return gr_fail(err, GR_E_INPUT, "%s: not a godrays farm plan (cases, cache, tiles, batch_parts)", p);
    }
    snprintf(plan->dir, sizeof plan->dir, "%s", dir);
    snprintf(plan->cache, sizeof plan->cache, "%s", cache->valuestring);
    const cJSON *suite = cJSON_GetObjectItemCaseSensitive(j, "suite");
    if (cJSON_IsString(suite)) snprintf(plan->suite, sizeof plan->suite, "%s", suite->valuestring);
    plan->tiles = tiles->valueint;
    plan->batch_parts = bp->valueint;
    int nc = cJSON_GetArraySize(cases);
    plan->cases = calloc(nc > 0 ? (size_t)nc : 1, sizeof *plan->cases);
    if (!plan->cases) {
        cJSON_Delete(j);
        return gr_fail(err, GR_E_NOMEM, "farm: out of memory");
    }
    const cJSON *o;
    cJSON_ArrayForEach(o, cases)
    {
        const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, "args"), *k = cJSON_GetObjectItemCaseSensitive(o, "key");
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(o, "scene"), *nm = cJSON_GetObjectItemCaseSensitive(o, "name");
        gr_farm_case *fc = &plan->cases[plan->n_cases++];
        snprintf(fc->args, sizeof fc->args, "%s", cJSON_IsString(a) ? a->valuestring : "");
        snprintf(fc->scene, sizeof fc->scene, "%s", cJSON_IsString(sc) ? sc->valuestring : "scene.json");
        snprintf(fc->name, sizeof fc->name, "%s", cJSON_IsString(nm) ? nm->valuestring : "");
        snprintf(fc->key, sizeof fc->key, "%s", cJSON_IsString(k) ? k->valuestring : "");
    }
    cJSON_Delete(j);
    refresh(plan);
    return GR_OK;
}
