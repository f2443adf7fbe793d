/* godrays compare: error metrics between any two images OpenImageIO reads (the ground truth
 * and a real-time frame, possibly captured from another engine), optional mask, reference
 * standard errors, best scale fit; with -o DIR also metrics.json and false-color differences. */
#include "cli/cli.h"
#include "common/memlimit.h"
#include "common/outfile.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "compare/diffmap.h"
#include "compare/flip.h"
#include "compare/structure.h"
#include "report/profile.h"
#include "scene/scene.h"
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
            "R, G, B by name, else the first three; one channel (+ alpha) is grey (a lone R, G or\n"
            "B is refused: docs/images.md). If REF has\n"
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
            "  --metric LIST        which metric groups to compute, comma-separated: basic (the\n"
            "                       table above), flip, structure, or all (default: all; structure\n"
            "                       only with --vp or --scene)\n"
            "  --vp X,Y             the beams' vanishing point in image coordinates (pixel centres\n"
            "                       at +0.5; may lie outside) for the structure metrics\n"
            "  --scene FILE         take the vanishing point from FILE's camera and refracted sun\n"
            "                       (and de-glow by the angle to that sun, not the distance to the\n"
            "                       point)\n"
            "  --set KEY=VALUE      override a value of that scene, e.g. camera.yaw_deg=120\n"
            "                       (repeatable)\n"
            "  --flip-mode M        ldr or hdr (default: hdr when REF is .exr, .hdr or .pfm, else\n"
            "                       ldr); FLIP is computed on a * TEST with the fitted a if any\n"
            "  --ppd P              FLIP's observer: pixels per degree (default 67.02: 0.7 m from\n"
            "                       a 0.7 m wide 3840-pixel display)\n"
            "  --tone-mapper T      HDR-FLIP's tone mapper: aces (default) or reinhard\n"
            "  --exposures A:B:N    HDR-FLIP's exposures (log2): N from A to B (default: from REF)\n"
            "                       with -o, DIR/flip.png is the per-pixel FLIP map (magma, 0 black\n"
            "                       .. 1 white-yellow)\n"
            "  --json               print the JSON instead of the table\n"
            "  --max-memory SIZE    refuse (exit 2) images estimated to need more (e.g. 2G; default\n"
            "                       $GODRAYS_MAX_MEMORY, else 80 %% of the memory)\n"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage, unreadable input or size mismatch.\n",
            GR_METRICS_STDERR_BOUND);
}

/* Writes text and a newline to path atomically (common/outfile). */
static gr_status write_text(const char *path, const char *text, gr_error *err)
{
    size_t n = strlen(text);
    char *t = malloc(n + 2);
    if (!t) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    memcpy(t, text, n);
    t[n] = '\n';
    t[n + 1] = '\0';
    gr_status st = gr_outfile_write(path, t, (long long)n + 1, err);
    free(t);
    return st;
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

/* Images of one or two channels (docs/images.md, "Grey images"): one channel, or grey + alpha
 * A, is grey and compared as such (the channel in R, G and B), which is stated on stderr; a
 * lone colour channel (R, G or B) or any other pair such as (R, G) is part of an RGB image
 * with no defined luminance, refused rather than compared as grey (issue 15 finding 10 refused
 * (R, G), issue 31 found R alone copied into G and B). */
static gr_status check_grey(const char *role, const char *path, const gr_image *im, gr_error *err)
{
    if (im->nchannels > 2) return GR_OK;
    const char *c0 = im->names[0];
    const int colour = !strcmp(c0, "R") || !strcmp(c0, "G") || !strcmp(c0, "B");
    if (colour || (im->nchannels == 2 && strcmp(im->names[1], "A")))
        return gr_fail(err, GR_E_INPUT, "%s %s: %d channel%s (%s%s%s): neither grey (one channel, + alpha A) nor RGB; "
                       "convert it first, e.g. oiiotool IN --ch R,G,B=0 -o OUT.exr", role, path, im->nchannels,
                       im->nchannels == 2 ? "s" : "", c0, im->nchannels == 2 ? ", " : "",
                       im->nchannels == 2 ? im->names[1] : "");
    fprintf(stderr, "godrays compare: %s %s: grey (channel %s%s), compared in R, G and B alike\n", role, path, c0,
            im->nchannels == 2 ? " + alpha A" : "");
    return GR_OK;
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

/* Every sample of img's channels other than stderr.* is 0: the metrics would give a "perfect"
 * fit (a = 0, RMSE 0, PSNR inf, SSIM 1) that means nothing. */
static int all_zero(const gr_image *img)
{
    const size_t n = (size_t)img->width * (size_t)img->height, nc = (size_t)img->nchannels;
    for (size_t c = 0; c < nc; c++) {
        if (!strncmp(img->names[c], "stderr.", 7)) continue;
        for (size_t p = 0; p < n; p++)
            if (img->pixels[p * nc + c] != 0.0f) return 0;
    }
    return 1;
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
    int npos = 0, json = 0, linearize = 1, do_basic = 1, do_flip = 1;
    int do_struct = -1; /* -1: when a vanishing point is given */
    int have_vp = 0;
    double vp[2] = {0.0, 0.0};
    const char *scene_path = NULL, *sets[32];
    int n_sets = 0;
    int flip_mode = -1; /* -1: from REF's file extension */
    char flip_skipped[GR_ERROR_MSG_MAX] = "";
    gr_metrics_options opt = {0};
    gr_flip_options fopt = {0};
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
        } else if (!strcmp(a, "--vp") || !strcmp(a, "--scene") || !strcmp(a, "--set")) {
            const int rc = gr_args_value(&args, &v);
            if (rc) return rc;
            if (!strcmp(a, "--set")) {
                if (n_sets >= (int)(sizeof sets / sizeof sets[0]))
                    return gr_cli_usage_error(cmd, "--set: at most %d overrides", (int)(sizeof sets / sizeof sets[0]));
                sets[n_sets++] = v;
            } else if (!strcmp(a, "--scene")) {
                scene_path = v;
            } else {
                int used = 0;
                if (sscanf(v, "%lf,%lf%n", &vp[0], &vp[1], &used) != 2 || v[used] != '\0' || !isfinite(vp[0]) ||
                    !isfinite(vp[1]))
                    return gr_cli_usage_error(cmd, "--vp '%s': need X,Y (two numbers)", v);
                have_vp = 1;
            }
        } else if (!strcmp(a, "--metric") || !strcmp(a, "--flip-mode") || !strcmp(a, "--ppd") ||
                   !strcmp(a, "--tone-mapper") || !strcmp(a, "--exposures")) {
            const int rc = gr_args_value(&args, &v);
            if (rc) return rc;
            if (!strcmp(a, "--metric")) {
                do_basic = do_flip = do_struct = 0;
                char buf[256];
                if (strlen(v) >= sizeof buf) return gr_cli_usage_error(cmd, "--metric '%s': too long", v);
                strcpy(buf, v);
                for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
                    if (!strcmp(t, "basic")) do_basic = 1;
                    else if (!strcmp(t, "flip")) do_flip = 1;
                    else if (!strcmp(t, "structure")) do_struct = 1;
                    else if (!strcmp(t, "all")) do_basic = do_flip = 1, do_struct = -1;
                    else
                        return gr_cli_usage_error(cmd, "--metric '%s': unknown metric '%s' (basic, flip, structure, all)",
                                                  v, t);
                }
                if (!do_basic && !do_flip && !do_struct) return gr_cli_usage_error(cmd, "--metric '%s': names no metric", v);
            } else if (!strcmp(a, "--flip-mode")) {
                if (!strcmp(v, "ldr")) flip_mode = GR_FLIP_LDR;
                else if (!strcmp(v, "hdr")) flip_mode = GR_FLIP_HDR;
                else return gr_cli_usage_error(cmd, "--flip-mode '%s': use ldr or hdr", v);
            } else if (!strcmp(a, "--tone-mapper")) {
                if (!strcmp(v, "aces")) fopt.tonemapper = GR_FLIP_TM_ACES;
                else if (!strcmp(v, "reinhard")) fopt.tonemapper = GR_FLIP_TM_REINHARD;
                else return gr_cli_usage_error(cmd, "--tone-mapper '%s': use aces or reinhard", v);
            } else if (!strcmp(a, "--ppd")) {
                char *end = NULL;
                errno = 0;
                const double d = strtod(v, &end);
                if (errno || end == v || *end || !isfinite(d) || d <= 0.0)
                    return gr_cli_usage_error(cmd, "--ppd '%s' is not a number > 0", v);
                fopt.ppd = d;
            } else {
                double e0, e1;
                int k, used = 0;
                if (sscanf(v, "%lf:%lf:%d%n", &e0, &e1, &k, &used) != 3 || v[used] != '\0' || !isfinite(e0) ||
                    !isfinite(e1) || e1 < e0 || k < 1)
                    return gr_cli_usage_error(cmd, "--exposures '%s': need START:STOP:COUNT, START <= STOP, COUNT >= 1", v);
                fopt.exposures_given = 1, fopt.start_exposure = e0, fopt.stop_exposure = e1, fopt.n_exposures = k;
            }
        } else if (!strcmp(a, "--max-memory")) {
            const int vrc = gr_args_value(&args, &v);
            if (vrc) return vrc;
            gr_error merr;
            double bytes;
            if (gr_memlimit_parse("--max-memory", v, &bytes, &merr) != GR_OK) return gr_cli_usage_error(cmd, "%s", merr.msg);
            gr_memlimit_set(bytes);
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
    if (have_vp && scene_path) return gr_cli_usage_error(cmd, "give --vp or --scene, not both");
    if (n_sets && !scene_path) return gr_cli_usage_error(cmd, "--set needs --scene");
    if (do_struct == 1 && !have_vp && !scene_path)
        return gr_cli_usage_error(cmd, "--metric structure needs the vanishing point: --vp X,Y or --scene FILE");
    if (do_struct == -1) do_struct = have_vp || scene_path;
    if (outdir) {
        const int rc = gr_args_check_output_dir(&args, "-o", outdir);
        if (rc) return rc;
    }

    gr_error err = {0};
    gr_image *ref = NULL, *test = NULL, *mask = NULL, *diff[3] = {NULL, NULL, NULL}, *scaled = NULL;
    unsigned char *scored = NULL;
    float *flipmap = NULL, *angles = NULL;
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
    for (int k = 0; st == GR_OK && k < 2; k++) st = check_grey(k ? "test" : "reference", paths[k], k ? test : ref, &err);
    if (st == GR_OK) {
        /* the metrics, blurs and difference images: about 170 bytes per pixel, measured
         * (2.8 GB for 4096 x 4096; docs/reliability.md); FLIP's working set on top, counted
         * from its buffers (an upper bound: they are allocated after the metrics' are freed):
         * 22 double planes, 2 x 3 double colours, 2 float maps, 1 double for the quantiles */
        const double per_px = 170.0 + (do_flip ? 22.0 * 8 + 6.0 * 8 + 2.0 * 4 + 8.0 : 0.0);
        char detail[96];
        snprintf(detail, sizeof detail, "%d x %d pixels at about %.0f bytes each", ref->width, ref->height, per_px);
        st = gr_memlimit_check("the comparison", per_px * ref->width * (double)ref->height, detail, &err);
    }
    if (st == GR_OK && all_zero(ref))
        st = gr_fail(&err, GR_E_INPUT, "reference %s is zero everywhere: no metric can say anything about the test "
                     "image (camera inside an occluder, a medium without scattering, no light reaching the view?)",
                     paths[0]);
    if (st != GR_OK) goto fail;

    /* The structure metrics' geometry first: the metric sets carry their summary (as in
     * `godrays run`), the "structure" object the details. */
    gr_structure_options so = {0};
    if (do_struct) {
        if (scene_path) {
            gr_scene sc;
            st = gr_scene_load_file(scene_path, sets, n_sets, &sc, &err);
            if (st == GR_OK) st = gr_structure_scene_vp(&sc, ref->width, ref->height, &vp[0], &vp[1], &err);
            if (st != GR_OK) {
                if (st != GR_E_NOMEM) err.status = GR_E_INPUT;
                gr_error_prefix(&err, "--scene %s", scene_path);
                goto fail;
            }
            /* de-glow by the angle to the refracted sun, rings one pixel wide */
            sc.camera.width = ref->width, sc.camera.height = ref->height;
            angles = malloc((size_t)ref->width * (size_t)ref->height * sizeof(float));
            if (!angles) {
                st = gr_fail(&err, GR_E_NOMEM, "out of memory for the structure metrics");
                goto fail;
            }
            double dir[3];
            gr_profile_sun_view_dir(&sc, dir);
            gr_profile_angles(&sc.camera, dir, angles);
            so.radial = angles, so.radial_bin = sc.camera.fov_deg / ref->height;
        }
        so.vp_x = vp[0], so.vp_y = vp[1];
        opt.structure = &so;
    }
    opt.mask = mask;
    if (!do_basic) opt.skip_ssim = opt.skip_blur = 1;
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

    /* FLIP on a * TEST (a = the fitted scale when asked for, else 1), pooled over the pixels
     * the other metrics score; the mode follows REF's format unless given. */
    const double scale = m.have_fit && m.fit_defined ? m.fit.scale : 1.0;
    gr_flip_result fres;
    double t_flip = 0.0;
    if (do_flip) {
        if (flip_mode < 0) {
            const char *dot = strrchr(paths[0], '.');
            flip_mode = dot && (!strcasecmp(dot, ".exr") || !strcasecmp(dot, ".hdr") || !strcasecmp(dot, ".pfm"))
                            ? GR_FLIP_HDR : GR_FLIP_LDR;
        }
        fopt.mode = (gr_flip_mode)flip_mode;
        const size_t n = (size_t)ref->width * (size_t)ref->height;
        scored = malloc(n);
        flipmap = malloc(n * sizeof(float));
        if (!scored || !flipmap) {
            st = gr_fail(&err, GR_E_NOMEM, "out of memory for FLIP");
            goto fail;
        }
        st = gr_metrics_scored_pixels(ref, mask, opt.stderr_bound, scored, NULL, NULL, &err);
        if (st != GR_OK) goto fail;
        fopt.scored = scored;
        const gr_image *ft = test;
        if (scale != 1.0) {
            scaled = gr_image_create(test->width, test->height, test->nchannels, NULL);
            if (!scaled) {
                st = gr_fail(&err, GR_E_NOMEM, "out of memory for FLIP");
                goto fail;
            }
            memcpy(scaled->names, test->names, sizeof test->names);
            for (size_t i = 0; i < n * (size_t)test->nchannels; i++) scaled->pixels[i] = (float)(scale * test->pixels[i]);
            ft = scaled;
        }
        const double t1 = now_s();
        gr_error ferr = {GR_OK, ""};
        double e0, e1;
        int ne;
        if (fopt.mode == GR_FLIP_HDR && !fopt.exposures_given &&
            gr_flip_exposures(ref, fopt.tonemapper, &e0, &e1, &ne, &ferr) != GR_OK) {
            /* a black reference (all-zero, or a zero median) gives HDR-FLIP no exposure range:
             * FLIP is left out, said so, instead of failing the whole comparison */
            snprintf(flip_skipped, sizeof flip_skipped, "%s", ferr.msg);
            do_flip = 0;
        } else {
            st = gr_flip_compute(ref, ft, &fopt, flipmap, &fres, &err);
        }
        t_flip = now_s() - t1;
        if (st != GR_OK) goto fail;
    }

    gr_structure_compare sres;
    double t_struct = 0.0;
    if (do_struct) {
        if (!scored) {
            scored = malloc((size_t)ref->width * (size_t)ref->height);
            if (!scored) {
                st = gr_fail(&err, GR_E_NOMEM, "out of memory for the structure metrics");
                goto fail;
            }
            st = gr_metrics_scored_pixels(ref, mask, opt.stderr_bound, scored, NULL, NULL, &err);
            if (st != GR_OK) goto fail;
        }
        so.scored = scored;
        const double t2 = now_s();
        st = gr_structure_compare_images(ref, test, &so, &sres, &err);
        t_struct = now_s() - t2;
        if (st != GR_OK) goto fail;
    }

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
    cJSON *sj = do_struct ? gr_structure_to_json(&sres, vp[0], vp[1]) : NULL;
    if (do_struct && (!sj || !cJSON_AddNumberToObject(sj, "time_s", t_struct) ||
                      !cJSON_AddItemToObject(root, "structure", sj))) {
        cJSON_Delete(sj);
        st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
        goto fail;
    }
    if (flip_skipped[0] && !cJSON_AddStringToObject(root, "flip_skipped", flip_skipped)) {
        st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
        goto fail;
    }
    cJSON *fj = do_flip ? gr_flip_to_json(&fres, scale) : NULL;
    if (do_flip && (!fj || !cJSON_AddNumberToObject(fj, "time_s", t_flip) || !cJSON_AddItemToObject(root, "flip", fj))) {
        cJSON_Delete(fj);
        st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
        goto fail;
    }

    if (outdir) {
        /* Everything is computed before the first file is written; each file goes through a
         * temporary name, so an error leaves no half-written file behind. */
        static const char *const names[3] = {"diff.png", "diff_signed.png", "flip.png"};
        cJSON *dj = cJSON_AddObjectToObject(root, "difference_images");
        if (!dj) {
            st = gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
            goto fail;
        }
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
        if (do_flip) {
            st = gr_flip_heatmap(flipmap, ref->width, ref->height, &diff[2], &err);
            if (st != GR_OK) goto fail;
            cJSON *one = cJSON_AddObjectToObject(dj, names[2]);
            if (!one || !cJSON_AddStringToObject(one, "quantity", "FLIP per pixel (of scale * test)") ||
                !cJSON_AddNumberToObject(one, "scale", scale) || !cJSON_AddStringToObject(one, "color_map", "magma") ||
                !cJSON_AddNumberToObject(one, "min", 0.0) || !cJSON_AddNumberToObject(one, "max", 1.0)) {
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
        for (int k = 0; st == GR_OK && k < 3; k++) {
            if (!diff[k]) continue;
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
        if (do_basic) gr_metrics_print_table(stdout, &m);
        if (do_flip) gr_flip_print(stdout, "FLIP", &fres, scale);
        if (flip_skipped[0]) printf("  FLIP not computed: %s\n", flip_skipped);
        if (do_struct) gr_structure_print(stdout, &sres, vp[0], vp[1]);
        if (outdir)
            printf("wrote %s/metrics.json, %s/diff.png, %s/diff_signed.png%s%s%s\n", outdir, outdir, outdir,
                   do_flip ? ", " : "", do_flip ? outdir : "", do_flip ? "/flip.png" : "");
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
    gr_image_destroy(diff[2]);
    gr_image_destroy(scaled);
    free(scored);
    free(flipmap);
    free(angles);
    return rc;
}
