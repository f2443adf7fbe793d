/* godrays reference SCENE -o OUT.exr: the ground-truth god-ray layer (reference/), with a
 * PNG preview beside it. Quality flags become "reference.*" overrides of the scene, so they
 * are range-checked by the same tables as the file. */
#include "cli/cli.h"
#include "cli/args.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "farm/parts.h"
#include "image/exr.h"
#include "image/png.h"
#include "reference/bench.h"
#include "reference/integrator.h"
#include "reference/truth.h"
#include "scene/scene.h"
#include "tune/objective.h"
#include "tune/session.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays reference SCENE.json -o OUT.exr [options]\n"
            "\n"
            "Renders the ground-truth god-ray layer (sunlight refracted by the waves and scattered\n"
            "once toward the camera) with per-pixel standard errors, and a PNG preview beside it.\n"
            "\n"
            "options (defaults: the scene's \"reference\" section):\n"
            "  -o, --output FILE      EXR to write (required); the PNG preview beside it\n"
            "  --spp N                camera samples per pixel in each batch\n"
            "  --steps N              stratified march steps per camera ray (with adaptive steps,\n"
            "                         the default: the most a pixel takes)\n"
            "  --step-error E         adaptive steps: each pixel's step noise at most E times\n"
            "                         max(pixel, image mean) (reference.step_error)\n"
            "  --fixed-steps          --steps in every pixel (reference.adaptive_steps = false)\n"
            "  --surface-res N        surface tessellation (N x N cells over the lit patch)\n"
            "  --sun-samples N        directions sampled inside the sun's disc\n"
            "  --batches N            independent batches for the error bars\n"
            "  --seed N               RNG seed (same seed, same bytes, any thread count)\n"
            "  --threads N            worker threads (0 = all cores)\n"
            "  --target-error E       refine until the relative standard error of the image mean\n"
            "                         and of its 95th-percentile pixel are below E (at most 64\n"
            "                         rounds of passes; a warning says when that cap stopped it)\n"
            "  --cutoff T             stop camera rays where their transmittance falls below T\n"
            "  --size WxH             override the image size\n"
            "  --set KEY=VALUE        any scene override, e.g. --set medium.g=0.9 (repeatable)\n"
            "  --technique-dir DIR    add the user technique in DIR (for a scene with its section)\n"
            "  --aov                  add transmittance and ray_length channels\n"
            "  --no-preview           do not write the PNG preview\n"
            "  --max-memory SIZE      refuse (exit 2) a render estimated to need more (e.g. 8G;\n"
            "                         default $GODRAYS_MAX_MEMORY, else 80 %% of the memory)\n"
            "  --quiet                no progress bar\n"
            "  --phases               print where the time went: per phase (beam builds, lookup grid,\n"
            "                         pilot, march, bias probe, statistics) wall, CPU and serial\n"
            "                         seconds, the serial fraction and Amdahl's speed-up to 16 threads\n"
            "  --bench                benchmark instead of writing files: hot-loop lookups per second\n"
            "                         with 1 and 2 threads, Embree's raw occlusion-ray throughput\n"
            "\n"
            "frames, views and parts of the work (godrays farm, docs/farm.md):\n"
            "  --frame F              frame F of the animated waves: water.time_s + F / fps (as tune)\n"
            "  --fps F                frames per second for --frame (default 30)\n"
            "  --view YAW,PITCH       the camera turned to this view (degrees, as tune's --view)\n"
            "  --tile I/N             rows of tile I of N (0 <= I < N): writes a part file (-o), not\n"
            "                         an EXR; `godrays merge` assembles the parts bit for bit\n"
            "  --batch-part J/M       batches of group J of M (0 <= J < M <= batches): a part file\n"
            "                         (parts take the fixed passes: no --target-error, no --aov)\n"
            "\n"
            "Ctrl-C stops the render and writes what is done, marked godrays:partial = 1 (exit 1).\n");
}

/* --target-error stops refining at the round cap (gr_ref_result.max_rounds) whether or not the
 * target was met: say so, even with --quiet, since the image is less accurate than asked. */
static void warn_target(const gr_scene *scene, int passes_per_round, const gr_ref_result *res)
{
    const double target = scene->reference.target_error;
    if (!(target > 0.0) || res->target_met) return;
    const int rounds = res->max_rounds;
    fprintf(stderr,
            "godrays reference: warning: target error %g not reached after %d passes (the cap: %d rounds of %d): "
            "relative standard error of the image mean %.3g, of the 95th-percentile pixel %.3g; raise "
            "--sun-samples or --spp (more samples per round), or ask for a larger --target-error\n",
            target, res->passes, rounds, passes_per_round, res->rel_se_mean, res->rel_se_p95);
}

/* Adaptive steps held back by the cap (reference.steps) in at least 1 % of the pixels: those
 * miss the step target, and the figures above say how much; the remedy is the cap. */
static void warn_steps_cap(const gr_scene *scene, const gr_ref_result *res)
{
    if (!(res->steps_capped_frac >= 0.01)) return;
    fprintf(stderr,
            "godrays reference: warning: in %.1f%% of the pixels the step target (reference.step_error %g) needs "
            "more than the cap of %d march steps (reference.steps): they were held to the cap where the pilot asked for "
            "%.0f on average, so their step noise is above the target; raise --steps (or accept a larger "
            "--step-error)\n",
            100.0 * res->steps_capped_frac, scene->reference.step_error, scene->reference.steps, res->steps_wanted_capped);
}

/* The surface tessellation's estimated bias above 1 % of the image mean (issue 30's quality
 * line): the cells are 1/surface_res of the lit region, so views with a wide lit region (a deep
 * camera, a low sun) get coarse cells. Bias ~ h^p with the order p measured by the probe
 * (docs/reference.md 4, "Views with a wide lit region"), so each doubling of surface_res divides
 * it by 2^p. Not under --quiet (the summary line gives the figure, this the remedy), nor where
 * twice the cells would pass the setting's maximum (16384). */
static void warn_bias(const gr_scene *scene, const gr_ref_result *res, int quiet)
{
    const double est = res->bias_surface_rel;
    if (quiet || !(est > GR_TRUTH_COARSE_BIAS) || !isfinite(est) || scene->reference.surface_res > 8192) return;
    const gr_meta_item *mo = gr_meta_get(&res->meta, "godrays:bias_surface_rel_measured_order");
    const gr_meta_item *po = gr_meta_get(&res->meta, "godrays:bias_surface_order");
    const double p = po && po->num >= 1.0 && po->num <= 2.0 ? po->num : 1.0;
    char with[96] = "";
    if (mo && mo->num > est) snprintf(with, sizeof with, ", %.2g%% with the measured order %.2g", 100.0 * mo->num, p);
    /* with the cells near the camera refined (docs/reference.md 2.2, "Near the camera"): where
     * they reach their target the probe measures their error with them 2x finer; where the cap
     * kept them short of it, its coarser levels alias the shortest wave and it leans high */
    const gr_meta_item *held = gr_meta_get(&res->meta, "godrays:bias_probe_near_held");
    const char *near = !gr_meta_get(&res->meta, "godrays:surface_refine_near") ? ""
                       : held && held->num == 1.0
                           ? "; it includes the error of the cells near the camera, refined (godrays:surface_refine_near) "
                             "and measured with them 2x finer (godrays:bias_probe_near_held)"
                           : "; the cells near the camera are refined already (godrays:surface_refine_near), but short of "
                             "their target, and on such views this estimate leans high (docs/reference.md 2.2, \"Near the camera\")";
    fprintf(stderr,
            "godrays reference: warning: the surface tessellation's bias is about %.2g%% of the image mean in the worst channel%s "
            "(godrays:bias_surface_rel_est): the surface cells, 1/%d of the lit region (godrays:lit_region), are coarse "
            "for this view; --surface-res %d should divide it by %.2g to 4 (the beam builds' time and memory grow 4x)%s\n",
            100.0 * est, with, scene->reference.surface_res, 2 * scene->reference.surface_res, pow(2.0, p), near);
}

/* "I/N" with 0 <= I < N: 0, else the exit code of the usage error. */
static int parse_part(const char *flag, const char *v, int *i, int *n)
{
    char extra;
    if (sscanf(v, "%d/%d%c", i, n, &extra) != 2 || *n < 1 || *i < 0 || *i >= *n)
        return gr_cli_usage_error("reference", "%s %s: expected I/N with 0 <= I < N", flag, v);
    return 0;
}

/* --bench: the figures of reference/bench.h; an exit code. */
static int print_bench(const gr_scene *scene)
{
    gr_error err = {GR_OK, ""};
    gr_ref_bench_result b;
    if (gr_ref_bench(scene, &b, &err) != GR_OK) return gr_cli_report("reference", &err);
    printf("Embree raw rtcOccluded1 (1 thread, random rays): %.3g rays/s vs occluders, %.3g rays/s vs the "
           "surface mesh (%lld triangles)\n", b.occluded_occluders_per_s, b.occluded_surface_per_s, b.surface_triangles);
    printf("beam lookups alone (grid cell + box and containment tests, 1 thread, %lld primitives): %.3g /s\n", b.beam_prims,
           b.point_queries_per_s);
    printf("hot loop (lookups incl. shadow rays and shading): 1 thread %.3g /s (%.2f s), 2 threads %.3g /s (%.2f s)\n",
           b.qps[0], b.wall_s[0], b.qps[1], b.wall_s[1]);
    printf("speed-up 1 -> 2 threads: %.2fx; identical bytes: %s; pixels within 1%%: %.1f%%\n", b.speedup,
           b.identical ? "yes" : "NO", 100.0 * b.frac_se_1pct);
    return 0;
}

/* A part file (--tile, --batch-part: src/farm/parts.h); an exit code. */
static int write_part(const gr_args *args, const gr_scene *scene, const gr_ref_options *opt, const gr_ref_result *res,
                      const char *out_path, int quiet)
{
    if (res->partial) {
        fprintf(stderr, "godrays reference: interrupted; no part written (%s)\n", out_path);
        return 1;
    }
    char command[2048] = "godrays";
    for (int k = 0; k < args->argc; k++) {
        size_t l = strlen(command);
        snprintf(command + l, sizeof command - l, " %s", args->argv[k]);
    }
    gr_error err = {GR_OK, ""};
    if (gr_part_write(out_path, scene, opt, res, command, &err) != GR_OK) return gr_cli_report("reference", &err);
    if (!quiet)
        fprintf(stderr, "godrays reference: wrote part %s (rows [%d, %d) of %d, batches [%d, %d) of %d, %d passes, %.1f s)\n",
                out_path, opt->row0, opt->row1, scene->camera.height, opt->batch0, opt->batch1, scene->reference.batches,
                res->passes, res->wall_s);
    return 0;
}

/* --phases: the render's phase table on stdout (docs/reference.md 2.8; the same figures as the
 * metadata's godrays:phase.NAME.*), the serial fraction s of the wall time and what Amdahl's law
 * predicts from this render's n threads to 16: (s + p) / (s + p n / 16), p = 1 - s. */
static void print_phases(const gr_ref_result *res)
{
    if (!res->phases) {
        printf("phases: not measured\n");
        return;
    }
    double w = 0.0, c = 0.0, se = 0.0;
    printf("%-8s %10s %10s %10s\n", "phase", "wall s", "CPU s", "serial s");
    for (int i = 0; i < GR_REF_PHASES; i++) {
        printf("%-8s %10.3f %10.3f %10.3f\n", gr_ref_phase_names[i], res->phase_wall_s[i], res->phase_cpu_s[i],
               res->phase_serial_s[i]);
        w += res->phase_wall_s[i];
        c += res->phase_cpu_s[i];
        se += res->phase_serial_s[i];
    }
    printf("%-8s %10.3f %10.3f %10.3f\n", "all", w, c, se);
    const gr_meta_item *t = gr_meta_get(&res->meta, "godrays:threads");
    const int n = t && t->num >= 1.0 ? (int)t->num : 0;
    const double sf = res->serial_frac, p = 1.0 - sf;
    printf("serial fraction %.2f %% of the wall time on %d threads", 100.0 * sf, n);
    if (n > 0 && n < 16 && sf >= 0.0 && sf <= 1.0) printf("; Amdahl from %d to 16 threads: %.2fx", n, 1.0 / (sf + p * n / 16.0));
    printf("\n");
}

/* The EXR, its preview and the summary line; an exit code (1 for a partial render). */
static int write_image(const gr_scene *scene, const gr_ref_result *res, const char *out_path, int preview, int quiet,
                       int per_round)
{
    gr_error err = {GR_OK, ""};
    gr_status st = gr_exr_write(out_path, res->image, &res->meta, &err);
    if (st == GR_OK && preview) {
        char pp[4096];
        gr_args_preview_path(out_path, pp, sizeof pp);
        const int rgb[3] = {0, 1, 2};
        st = gr_png_write_preview(pp, res->image, rgb, res->preview_exposure, &err);
    }
    if (st != GR_OK) return gr_cli_report("reference", &err);
    char bias[224];
    /* the measured-order figure beside the order-2 estimate: where the coarser levels are not
     * yet asymptotic (the camera cone, docs/reference.md 2.2) it is the one a finer render confirms */
    const gr_meta_item *mo = gr_meta_get(&res->meta, "godrays:bias_surface_rel_measured_order");
    if (res->bias_surface_rel >= 0.0 && res->bias_block_p95 >= 0.0 && mo && mo->num >= 0.0)
        snprintf(bias, sizeof bias,
                 "~%.2g%% of the mean (%.2g%% with the measured order), 95th-percentile 10x10 block %.2g%% "
                 "(godrays:bias_surface_rel_est, _measured_order, bias_block_p95_rel)",
                 100.0 * res->bias_surface_rel, 100.0 * mo->num, 100.0 * res->bias_block_p95);
    else if (res->bias_surface_rel >= 0.0 && res->bias_block_p95 >= 0.0)
        snprintf(bias, sizeof bias, "~%.2g%% of the mean, 95th-percentile 10x10 block %.2g%% (godrays:bias_surface_rel_est, bias_block_p95_rel)",
                 100.0 * res->bias_surface_rel, 100.0 * res->bias_block_p95);
    else if (res->bias_surface_rel >= 0.0)
        snprintf(bias, sizeof bias, "~%.2g%% of the mean (godrays:bias_surface_rel_est)", 100.0 * res->bias_surface_rel);
    else
        snprintf(bias, sizeof bias, "not estimated");
    if (!quiet)
        fprintf(stderr,
                "godrays reference: wrote %s (%dx%d, %d spp, %.1f march steps per ray on average, %.1f s%s): rel. std. "
                "error of the mean %.3g%%, "
                "of the p95 pixel %.3g%%, %.1f%% of pixels within 1%%; surface bias %s\n",
                out_path, res->image->width, res->image->height, res->spp, res->steps_mean > 0.0 ? res->steps_mean : 0.0,
                res->wall_s, res->partial ? ", PARTIAL" : "",
                100.0 * res->rel_se_mean, 100.0 * res->rel_se_p95, 100.0 * res->frac_se_1pct, bias);
    if (res->partial) {
        fprintf(stderr, "godrays reference: interrupted; %s holds the partial result (godrays:partial = 1)\n", out_path);
        return 1;
    }
    warn_target(scene, per_round, res);
    warn_steps_cap(scene, res);
    warn_bias(scene, res, quiet);
    return 0;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int reference_with(gr_args *args)
{
    const int argc = args->argc;
    char **argv = args->argv;
    static const struct { const char *flag, *key; } qflags[] = {
        {"--spp", "reference.spp"}, {"--steps", "reference.steps"}, {"--surface-res", "reference.surface_res"},
        {"--sun-samples", "reference.sun_samples"}, {"--batches", "reference.batches"}, {"--seed", "reference.seed"},
        {"--threads", "reference.threads"}, {"--target-error", "reference.target_error"},
        {"--cutoff", "reference.transmittance_cutoff"}, {"--step-error", "reference.step_error"}};
    const char *cmd = "reference", *out_path = NULL;
    gr_scene *scene = NULL;
    int quiet = 0, aov = 0, preview = 1, bench = 0, phases = 0, rc = 0;
    int tile_i = 0, tile_n = 0, bp_j = 0, bp_m = 0, have_view = 0;
    const char *frame_s = NULL, *fps_s = NULL, *v = NULL;
    gr_tune_view view = {0.0, 0.0};
    for (; args->i < argc && !rc; args->i++) {
        const char *a = argv[args->i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) { quiet = 1; continue; }
        if (!strcmp(a, "--aov")) { aov = 1; continue; }
        if (!strcmp(a, "--bench")) { bench = 1; continue; }
        if (!strcmp(a, "--phases")) { phases = 1; continue; }
        if (!strcmp(a, "--no-preview")) { preview = 0; continue; }
        if (!strcmp(a, "--fixed-steps")) {
            if ((rc = gr_args_add_set(args, "reference.adaptive_steps=false")) != 0) return rc;
            continue;
        }
        size_t k = 0;
        while (k < sizeof qflags / sizeof qflags[0] && strcmp(a, qflags[k].flag)) k++;
        if (k < sizeof qflags / sizeof qflags[0]) rc = gr_args_take_setting(args, qflags[k].key);
        else if (!strcmp(a, "-o") || !strcmp(a, "--output")) rc = gr_args_value(args, &out_path);
        else if (!strcmp(a, "--set")) rc = gr_args_take_set(args);
        else if (!strcmp(a, "--size")) rc = gr_args_take_size(args);
        else if (!strcmp(a, "--tile")) rc = gr_args_value(args, &v) ? 2 : parse_part(a, v, &tile_i, &tile_n);
        else if (!strcmp(a, "--batch-part")) rc = gr_args_value(args, &v) ? 2 : parse_part(a, v, &bp_j, &bp_m);
        else if (!strcmp(a, "--frame")) rc = gr_args_value(args, &frame_s);
        else if (!strcmp(a, "--fps")) rc = gr_args_value(args, &fps_s);
        else if (!strcmp(a, "--view")) {
            gr_error verr = {GR_OK, ""};
            rc = gr_args_value(args, &v);
            if (!rc && gr_tune_parse_view(a, v, &view, &verr) != GR_OK) rc = gr_cli_report(cmd, &verr);
            have_view = 1;
        } else if (!strcmp(a, "--technique-dir")) rc = gr_args_take_technique_dir(args);
        else if (!strcmp(a, "--max-memory")) rc = gr_args_take_max_memory(args);
        else rc = gr_args_take_scene(args);
    }
    if (rc || (rc = gr_args_need_scene(args)) != 0) return rc;
    if (!out_path && !bench) return gr_cli_usage_error(cmd, "no output given (-o OUT.exr)");
    const int part = tile_n > 0 || bp_m > 0;
    if (part && bench) return gr_cli_usage_error(cmd, "--tile/--batch-part and --bench: give one of them");
    if (phases && bench) return gr_cli_usage_error(cmd, "--phases and --bench: give one of them (--bench renders nothing)");
    if (part && aov) return gr_cli_usage_error(cmd, "--aov with --tile/--batch-part: parts carry no AOVs (docs/farm.md)");
    long frame = 0;
    double fps = 30.0;
    char extra;
    if (frame_s && (sscanf(frame_s, "%ld%c", &frame, &extra) != 1 || frame < 0))
        return gr_cli_usage_error(cmd, "--frame %s: expected a frame number >= 0", frame_s);
    if (fps_s && (sscanf(fps_s, "%lf%c", &fps, &extra) != 1 || !(fps > 0.0) || fps > 1e6))
        return gr_cli_usage_error(cmd, "--fps %s: expected frames per second > 0", fps_s);
    /* a scene with a user technique's section loads once that technique is known */
    if ((rc = gr_args_add_technique_dirs(args)) != 0) goto done;
    if ((rc = gr_args_load_scene(args, &scene)) != 0) goto done;
    if (frame_s || have_view) {
        /* the same scene as tune's case (frame f: water.time_s + f / fps), so the ground truth
         * lands under the key tune and run look up */
        gr_error cerr = {GR_OK, ""};
        double t = frame_s ? (double)frame / fps + scene->water.time_s : scene->water.time_s;
        if (gr_tune_make_case(scene, t, have_view ? &view : NULL, scene, &cerr) != GR_OK) {
            rc = gr_cli_report(cmd, &cerr);
            goto done;
        }
    }
    if (bp_m > scene->reference.batches) {
        rc = gr_cli_usage_error(cmd, "--batch-part %d/%d: more groups than the %d batches", bp_j, bp_m, scene->reference.batches);
        goto done;
    }
    /* A render takes minutes: an output that cannot be written is refused before it. */
    if (!bench && (rc = gr_args_check_output_file(args, "-o", out_path)) != 0) goto done;
    if (!bench && preview && (rc = gr_args_note_preview(args, "-o", out_path)) != 0) goto done;

    gr_error err = {GR_OK, ""};
    if (bench) {
        rc = print_bench(scene);
        goto done;
    }
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.use_cache = 0;     /* the user asked for this render: written, not looked up */
    to.keep_partial = 1;  /* Ctrl-C writes what is done (godrays:partial = 1) */
    gr_ref_options *opt = &to.ref;
    opt->progress = !quiet;
    opt->aovs = aov;
    if (part) {
        opt->keep_sums = 1;
        if (tile_n > scene->camera.height) {
            rc = gr_cli_usage_error(cmd, "--tile %d/%d: more tiles than the %d rows", tile_i, tile_n, scene->camera.height);
            goto done;
        }
        gr_part_rows(tile_n ? tile_i : 0, tile_n ? tile_n : 1, scene->camera.height, &opt->row0, &opt->row1);
        gr_part_rows(bp_m ? bp_j : 0, bp_m ? bp_m : 1, scene->reference.batches, &opt->batch0, &opt->batch1);
    }
    gr_ref_result res;
    gr_truth_info ti;
    if (gr_truth_get(scene, &to, &res, &ti, &err) != GR_OK) {
        rc = gr_cli_report(cmd, &err);
        goto done;
    }
    if (part) rc = write_part(args, scene, opt, &res, out_path, quiet);
    else rc = write_image(scene, &res, out_path, preview, quiet, ti.passes_per_round);
    if (phases && (rc == 0 || res.partial)) print_phases(&res);
    gr_ref_result_free(&res);
done:
    free(scene);
    return rc;
}

int cmd_reference(int argc, char **argv)
{
    return gr_args_main("reference", argc, argv, reference_with);
}
