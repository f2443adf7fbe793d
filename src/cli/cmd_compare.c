/* godrays compare: error metrics between any two images OpenImageIO reads (the ground truth
 * and a real-time frame, possibly captured from another engine), optional mask, reference
 * standard errors, best scale fit; with -o DIR also metrics.json and false-color differences. */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "compare/diffmap.h"
#include "compare/metrics.h"
#include "image/exr.h"
#include "compare/metrics_io.h"
#include "image/oiio.h"
#include "report/report.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays compare REF TEST [-o DIR] [options]\n"
            "\n"
            "Compares TEST against the reference REF: per RGB channel, pooled RGB (as idiff) and\n"
            "Rec. 709 luminance: bias, MAE, RMSE, relative MSE, PSNR (reference-peak and idiff\n"
            "conventions), max error and where, SSIM on luminance, RMSE after Gaussian blur at\n"
            "sigma 1, 4, 16 px. Any format OpenImageIO reads (EXR, PNG, TIFF, HDR, ...); channels\n"
            "R, G, B by name, else the first three, a 1-channel image is gray. If REF has\n"
            "stderr.R/G/B channels, differences within 2 standard errors are reported as not\n"
            "significant and pixels whose reference is too noisy are not scored (counted).\n"
            "Formulas and conventions: docs/metrics.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR     write DIR/metrics.json (every number), DIR/diff.png (|dY|,\n"
            "                       inferno) and DIR/diff_signed.png (dY, blue-red), with colorbars\n"
            "  --mask M             image of the same size; pixels whose first channel is 0 are\n"
            "                       not scored\n"
            "  --fit-scale          also fit a = <t, r> / <t, t> and report the metrics of a * TEST\n"
            "  --stderr-bound B     do not score pixels whose reference luminance relative stderr\n"
            "                       exceeds B (default %g; inf: score all)\n"
            "  --no-linearize       read 8-bit files as code / 255 (default: sRGB-decode them)\n"
            "  --json               print the JSON instead of the table\n"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage, unreadable input or size mismatch.\n",
            GR_METRICS_STDERR_BOUND);
}

/* Writes text to path through a temporary file renamed into place. */
static gr_status write_text(const char *path, const char *text, gr_error *err)
{
    char tmp[4300];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp)
        return gr_fail(err, GR_E_USAGE, "%s: path too long", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return gr_fail(err, GR_E_IO, "%s: cannot create: %s", tmp, strerror(errno));
    int ok = fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        return gr_fail(err, GR_E_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    return GR_OK;
}

/* Reads one input; any failure is bad input (exit 2) naming the role and the file. */
static gr_status read_input(const char *role, const char *path, int linearize, gr_image **img, gr_error *err)
{
    gr_status st = gr_oiio_read(path, linearize, img, err);
    if (st == GR_OK) return GR_OK;
    if (st != GR_E_NOMEM) err->status = GR_E_INPUT;
    gr_error_prefix(err, "%s", role);
    return err->status;
}

static cJSON *image_json(const char *path, const gr_image *img, const int rgb[3])
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON *ch = cJSON_AddArrayToObject(o, "channels_compared");
    int ok = cJSON_AddStringToObject(o, "path", path) && cJSON_AddNumberToObject(o, "channels", img->nchannels) && ch;
    for (int c = 0; ok && c < 3; c++) {
        cJSON *s = cJSON_CreateString(img->names[rgb[c]]);
        ok = s && cJSON_AddItemToArray(ch, s);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cmd_compare(int argc, char **argv)
{
    const char *cmd = "compare";
    const char *paths[2] = {NULL, NULL}, *outdir = NULL, *mask_path = NULL;
    int npos = 0, json = 0, linearize = 1;
    gr_metrics_options opt = {0};
    gr_args args; /* no overrides: nothing to free */
    gr_args_create(&args, cmd, argc, argv);
    for (; args.i < argc; args.i++) {
        const char *a = argv[args.i], *v = NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--mask") ||
                   !strcmp(a, "--stderr-bound")) {
            const int rc = gr_args_value(&args, &v);
            if (rc) return rc;
            if (!strcmp(a, "--mask")) {
                mask_path = v;
            } else if (!strcmp(a, "--stderr-bound")) {
                char *end = NULL;
                errno = 0;
                double b = strtod(v, &end);
                if (errno || end == v || *end || isnan(b) || b <= 0.0)
                    return gr_cli_usage_error(cmd, "--stderr-bound '%s' is not a number > 0 (or inf)", v);
                opt.stderr_bound = b;
            } else {
                outdir = v;
            }
        } else if (!strcmp(a, "--fit-scale")) {
            opt.fit_scale = 1;
        } else if (!strcmp(a, "--json")) {
            json = 1;
        } else if (!strcmp(a, "--no-linearize")) {
            linearize = 0;
        } else if (a[0] == '-' && a[1] != '\0') {
            return gr_cli_usage_error(cmd, "unknown option '%s'", a);
        } else {
            if (npos >= 2) return gr_cli_usage_error(cmd, "unexpected argument '%s': give REF and TEST only", a);
            paths[npos++] = a;
        }
    }
    if (npos != 2) return gr_cli_usage_error(cmd, "need two images, REF and TEST");
    if (outdir) {
        const int rc = gr_args_check_output_dir(&args, "-o", outdir);
        if (rc) return rc;
    }

    gr_error err = {0};
    gr_image *ref = NULL, *test = NULL, *mask = NULL, *diff[2] = {NULL, NULL};
    cJSON *root = NULL;
    char *text = NULL;
    int rc = 0;
    gr_status st = read_input("reference", paths[0], linearize, &ref, &err);
    if (st == GR_OK) st = read_input("test", paths[1], linearize, &test, &err);
    if (st == GR_OK && mask_path) st = read_input("mask", mask_path, 0, &mask, &err);
    if (st == GR_OK && (ref->width != test->width || ref->height != test->height))
        st = gr_fail(&err, GR_E_INPUT, "size mismatch: reference %s is %d x %d, test %s is %d x %d", paths[0],
                     ref->width, ref->height, paths[1], test->width, test->height);
    if (st == GR_OK && mask && (mask->width != ref->width || mask->height != ref->height))
        st = gr_fail(&err, GR_E_INPUT, "size mismatch: mask %s is %d x %d, images are %d x %d", mask_path, mask->width,
                     mask->height, ref->width, ref->height);
    if (st != GR_OK) goto fail;

    opt.mask = mask;
    /* a ground truth's stderr comes from a few batches: its degrees of freedom, for Student's t */
    {
        gr_metadata meta;
        gr_meta_init(&meta);
        gr_image *tmp = NULL;
        gr_error e2 = {0};
        size_t n = strlen(paths[0]);
        if (n > 4 && !strcmp(paths[0] + n - 4, ".exr") && gr_exr_read(paths[0], &tmp, &meta, &e2) == GR_OK) {
            const gr_meta_item *it = gr_meta_get(&meta, "godrays:stderr_dof");
            if (it && it->type != GR_META_STRING && it->num >= 1.0) opt.stderr_dof = (int)it->num;
        }
        gr_image_destroy(tmp);
        gr_meta_free(&meta);
    }
    gr_metrics m;
    const double t0 = now_s();
    st = gr_metrics_compute(ref, test, &opt, &m, &err);
    const double t_metrics = now_s() - t0;
    if (st != GR_OK) goto fail;

    root = gr_metrics_to_json(&m);
    cJSON *rj = root ? image_json(paths[0], ref, m.ref_rgb) : NULL;
    cJSON *tj = root ? image_json(paths[1], test, m.test_rgb) : NULL;
    if (!root || !rj || !tj || !cJSON_AddItemToObject(root, "reference", rj) ||
        !cJSON_AddItemToObject(root, "test", tj) || !cJSON_AddBoolToObject(root, "linearized_8bit", linearize) ||
        !cJSON_AddNumberToObject(root, "metrics_time_s", t_metrics) ||
        (mask_path && !cJSON_AddStringToObject(root, "mask", mask_path))) {
        st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
        goto fail;
    }

    if (outdir) {
        /* Everything is computed before the first file is written; each file goes through a
         * temporary name, so an error leaves no half-written file behind. */
        static const char *const names[2] = {"diff.png", "diff_signed.png"};
        cJSON *dj = cJSON_AddObjectToObject(root, "difference_images");
        if (!dj) {
            st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
            goto fail;
        }
        const double scale = m.have_fit && m.fit_defined ? m.fit.scale : 1.0;
        for (int k = 0; k < 2; k++) {
            gr_diffmap_options dopt = {.kind = k ? GR_DIFFMAP_SIGNED : GR_DIFFMAP_ABS, .scale = scale,
                                       .mask = mask, .stderr_bound = opt.stderr_bound};
            gr_diffmap_info info;
            st = gr_diffmap_create(ref, test, &dopt, &diff[k], &info, &err);
            if (st != GR_OK) goto fail;
            cJSON *one = cJSON_AddObjectToObject(dj, names[k]);
            if (!one || !cJSON_AddStringToObject(one, "quantity", k ? "scale * Y(test) - Y(ref)" : "|scale * Y(test) - Y(ref)|") ||
                !cJSON_AddNumberToObject(one, "scale", scale) || !cJSON_AddStringToObject(one, "color_map", info.map) ||
                !cJSON_AddNumberToObject(one, "min", info.vmin) || !cJSON_AddNumberToObject(one, "max", info.vmax) ||
                !cJSON_AddBoolToObject(one, "colorbar_labelled", info.labelled) ||
                !cJSON_AddStringToObject(one, "unscored_pixels", "mid gray")) {
                st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
                goto fail;
            }
        }
        text = cJSON_Print(root);
        if (!text) {
            st = gr_fail(&err, GR_E_NOMEM, "out of memory printing the JSON");
            goto fail;
        }
        st = gr_report_make_dir(outdir, &err);
        char path[4200];
        for (int k = 0; st == GR_OK && k < 2; k++) {
            if (snprintf(path, sizeof path, "%s/%s", outdir, names[k]) >= (int)sizeof path)
                st = gr_fail(&err, GR_E_USAGE, "%s: output directory name too long", outdir);
            else
                st = gr_oiio_write(path, diff[k], &err);
        }
        if (st == GR_OK) {
            snprintf(path, sizeof path, "%s/metrics.json", outdir); /* fits: diff_signed.png is longer */
            st = write_text(path, text, &err);
        }
        if (st != GR_OK) goto fail;
    } else {
        text = cJSON_Print(root);
        if (!text) {
            st = gr_fail(&err, GR_E_NOMEM, "out of memory printing the JSON");
            goto fail;
        }
    }

    if (json) {
        printf("%s\n", text);
    } else {
        printf("reference %s, test %s\n", paths[0], paths[1]);
        gr_metrics_print_table(stdout, &m);
        if (outdir) printf("wrote %s/metrics.json, %s/diff.png, %s/diff_signed.png\n", outdir, outdir, outdir);
    }
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    cJSON_free(text);
    cJSON_Delete(root);
    gr_image_destroy(ref);
    gr_image_destroy(test);
    gr_image_destroy(mask);
    gr_image_destroy(diff[0]);
    gr_image_destroy(diff[1]);
    return rc;
}
