/* godrays merge PARTS... -o OUT.exr: the image a single `godrays reference` run writes, from
 * the part files of `reference --tile/--batch-part` (src/farm/parts.h), bit for bit. */
#include "cli/cli.h"
#include "cli/args.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "farm/parts.h"
#include "image/exr.h"
#include "image/png.h"
#include "reference/truth.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays merge PART... (-o OUT.exr | --cache) [options]\n"
            "\n"
            "Assembles the parts of a ground-truth render (godrays reference --tile I/N\n"
            "--batch-part J/M -o PART) into the image one run would have written: the same\n"
            "pixels, error channels and statistics, byte for byte; the metadata lists each part's\n"
            "provenance. A missing, duplicated, overlapping or mismatched part is an error (exit 2).\n"
            "\n"
            "options:\n"
            "  -o, --output FILE   EXR to write (a PNG preview beside it unless --no-preview)\n"
            "  --cache             also store it in the ground-truth cache ($GODRAYS_CACHE, else\n"
            "                      the user cache), where run, sweep, tune and pareto find it\n"
            "  --no-preview        no PNG preview\n"
            "  --quiet             no summary line\n");
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int merge_with(gr_args *args)
{
    const char *cmd = "merge", *out_path = NULL;
    int cache = 0, preview = 1, quiet = 0, rc = 0, n = 0;
    const char **parts = calloc((size_t)args->argc + 1, sizeof *parts);
    if (!parts) return 1;
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            free(parts);
            return 0;
        }
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) rc = gr_args_value(args, &out_path);
        else if (!strcmp(a, "--cache")) cache = 1;
        else if (!strcmp(a, "--no-preview")) preview = 0;
        else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) quiet = 1;
        else if (a[0] == '-' && a[1]) rc = gr_cli_usage_error(cmd, "unknown option %s", a);
        else parts[n++] = a;
    }
    if (!rc && !n) rc = gr_cli_usage_error(cmd, "no part files given");
    if (!rc && !out_path && !cache) rc = gr_cli_usage_error(cmd, "no output given (-o OUT.exr or --cache)");
    for (int k = 0; k < n && !rc; k++) rc = gr_args_add_input(args, "part", parts[k]); /* never replaced */
    /* an input named as the output first: the worse mistake */
    if (!rc && out_path) rc = gr_args_check_output_file(args, "-o", out_path);
    /* the merge is float pixels and error channels: an EXR, whatever the name said (-o x.png
     * wrote EXR bytes into x.png); the PNG preview goes beside it */
    const size_t ol = out_path ? strlen(out_path) : 0;
    if (!rc && out_path && (ol < 5 || strcasecmp(out_path + ol - 4, ".exr") != 0))
        rc = gr_cli_usage_error(cmd, "-o %s: the merged ground truth is an EXR file: name it OUT.exr (a PNG preview is "
                                "written beside it)", out_path);
    if (!rc && out_path && preview) rc = gr_args_note_preview(args, "-o", out_path);
    if (rc) {
        free(parts);
        return rc;
    }
    double t0 = now_s();
    gr_error err = {GR_OK, ""};
    gr_scene *scene = malloc(sizeof *scene);
    gr_ref_result res;
    memset(&res, 0, sizeof res);
    gr_status st = scene ? gr_parts_merge(parts, n, scene, &res, NULL, 0, &err)
                         : gr_fail(&err, GR_E_NOMEM, "out of memory");
    double merge_s = now_s() - t0;
    if (st == GR_OK) gr_meta_set_double(&res.meta, "godrays:merge_s", merge_s);
    if (st == GR_OK && out_path) st = gr_exr_write(out_path, res.image, &res.meta, &err);
    if (st == GR_OK && out_path && preview) {
        char pp[4096];
        gr_args_preview_path(out_path, pp, sizeof pp);
        const int rgb[3] = {0, 1, 2};
        st = gr_png_write_preview(pp, res.image, rgb, res.preview_exposure, &err);
    }
    gr_truth_info ti;
    memset(&ti, 0, sizeof ti);
    if (st == GR_OK && cache) st = gr_truth_store(scene, res.image, &res.meta, &ti, &err);
    if (st != GR_OK) rc = gr_cli_report(cmd, &err);
    else if (!quiet)
        fprintf(stderr,
                "godrays merge: %d parts -> %s%s%s (%dx%d, %d spp, parts' wall time %.4g s, merge %.2f s): rel. std. "
                "error of the mean %.3g%%, of the p95 pixel %.3g%%\n",
                n, out_path ? out_path : "", out_path && cache ? " and " : "", cache ? ti.path : "", res.image->width,
                res.image->height, res.spp, res.wall_s, merge_s, 100.0 * res.rel_se_mean, 100.0 * res.rel_se_p95);
    gr_ref_result_free(&res);
    free(scene);
    free(parts);
    return rc;
}

int cmd_merge(int argc, char **argv)
{
    return gr_args_main("merge", argc, argv, merge_with);
}
