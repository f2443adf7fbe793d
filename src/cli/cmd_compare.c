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

#include "compare/capture.h"
#include "compare/diffmap.h"
#include "compare/flip.h"
#include "compare/structure.h"
#include "report/profile.h"
#include "scene/scene.h"
#include "compare/metrics.h"
#include "image/exr.h"
#include "compare/metrics_io.h"
#include "compare/registry.h"
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
            "Then one line per metric of the metric registry (rmse, ssim, flip, structure, ...;\n"
            "in the JSON: \"registry\" in each set). Formulas and conventions: docs/metrics.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR     write DIR/metrics.json (every number), DIR/diff.png (|dY|,\n"
            "                       inferno) and DIR/diff_signed.png (dY, blue-red), with colorbars\n"
            "  --mask M             image of the same size; pixels whose first channel is 0 are\n"
            "                       not scored\n"
            "  --fit MODE           also report the metrics after a least-squares fit of TEST: scale\n"
            "                       (one factor a = <t, r> / <t, t> for R, G, B; a bare --fit and\n"
            "                       --fit-scale mean this), rgb (one factor per channel, a_c = <t_c, r_c> /\n"
            "                       <t_c, t_c>: a tint is fitted too; the three are reported) or none\n"
            "                       (default)\n"
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
            "  --technique-dir DIR  add the user technique in DIR (repeatable): a --scene may hold\n"
            "                       its section\n"
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
            "Warnings (stderr, and \"warnings\" in the JSON; the comparison goes on): TEST matches REF\n"
            "better flipped upside down or mirrored; an 8-bit input with more than 0.5 %% of its pixels\n"
            "at code 255; an 8- or 16-bit TEST whose values look linear although decoded as sRGB, or\n"
            "the reverse; a best scale fit outside [0.1, 10] (docs/metrics.md, \"Capture warnings\").\n"
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

/* Reads one input (and what the file says of its pixels, info: may be NULL); any failure is
 * bad input (exit 2) naming the role and the file, unless no image can be read at all (the
 * OpenImageIO module missing: exit 1). EXR files through the project's reader (image/exr.h),
 * as OpenImageIO reads them (float samples, canonical channel order, never decoded; its
 * colour space is "Linear" for every EXR file, whatever the file's attributes say),
 * without loading OpenImageIO (0.4 s of dynamic linking, docs/images.md); the rest through it. */
static gr_status read_input(const char *role, const char *path, int linearize, gr_image **img, gr_oiio_info *info,
                            int *dof, gr_error *err)
{
    *img = NULL;
    if (dof) *dof = 0;
    gr_status st;
    size_t n = strlen(path);
    if (n > 4 && !strcasecmp(path + n - 4, ".exr")) {
        int bits = 32;
        gr_metadata meta;
        gr_meta_init(&meta);
        st = gr_exr_read_bits(path, img, dof ? &meta : NULL, &bits, err);
        if (st == GR_OK && info) *info = (gr_oiio_info){.bits = bits, .colorspace = "Linear"};
        /* a ground truth's stderr comes from a few batches: its degrees of freedom (Student's
         * t), from godrays:stderr_dof when it is one of ours; 0 (unknown) otherwise */
        const gr_meta_item *it = st == GR_OK && dof ? gr_meta_get(&meta, "godrays:stderr_dof") : NULL;
        if (it && it->type != GR_META_STRING && it->num >= 1.0) *dof = (int)it->num;
        gr_meta_free(&meta);
    } else {
        st = gr_oiio_available(err);
        if (st != GR_OK) return st;
        st = gr_oiio_read_info(path, linearize, img, info, err);
    }
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

/* What the command line asked for. */
typedef struct compare_opts {
    const char *cmd;
    const char *paths[2], *outdir, *mask_path, *scene_path;
    const char *sets[32];
    int n_sets, npos, json, linearize, do_basic, do_flip;
    int do_struct;                /* -1: when a vanishing point is given */
    int have_vp;
    double vp[2];
    int flip_mode;                /* -1: from REF's file extension */
    gr_fit_mode fit;              /* --fit (opt.fit_scale follows it) */
    gr_metrics_options opt;
    gr_flip_options fopt;
} compare_opts;

/* What the comparison read, computed and owns (freed by state_free). */
typedef struct compare_state {
    gr_image *ref, *test, *mask, *diff[3];
    gr_image *scaled;             /* TEST as fitted, for FLIP (and the pictures, per channel) */
    gr_oiio_info info[2];         /* what REF's and TEST's files say of their pixels */
    int ref_dof;                  /* REF's stderr degrees of freedom (0: unknown; read_input) */
    gr_capture_report capture;    /* the capture checks (compare/capture.h) */
    unsigned char *scored;
    float *flipmap, *angles;
    gr_structure_options so;
    gr_metrics m;
    double scale;                 /* the test's factor for FLIP and the difference images */
    gr_flip_result fres;
    gr_structure_compare sres;
    double t_metrics, t_flip, t_struct;
    char flip_skipped[GR_ERROR_MSG_MAX];
    cJSON *root;
    char *text;
} compare_state;

static void state_free(compare_state *s)
{
    cJSON_free(s->text);
    cJSON_Delete(s->root);
    gr_image_destroy(s->ref);
    gr_image_destroy(s->test);
    gr_image_destroy(s->mask);
    for (int k = 0; k < 3; k++) gr_image_destroy(s->diff[k]);
    gr_image_destroy(s->scaled);
    free(s->scored);
    free(s->flipmap);
    free(s->angles);
}

/* --metric LIST: the groups to compute. */
static int parse_metric_list(compare_opts *o, const char *v)
{
    o->do_basic = o->do_flip = o->do_struct = 0;
    char buf[256];
    if (strlen(v) >= sizeof buf) return gr_cli_usage_error(o->cmd, "--metric '%s': too long", v);
    strcpy(buf, v);
    for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        if (!strcmp(t, "basic")) o->do_basic = 1;
        else if (!strcmp(t, "flip")) o->do_flip = 1;
        else if (!strcmp(t, "structure")) o->do_struct = 1;
        else if (!strcmp(t, "all")) o->do_basic = o->do_flip = 1, o->do_struct = -1;
        else return gr_cli_usage_error(o->cmd, "--metric '%s': unknown metric '%s' (basic, flip, structure, all)", v, t);
    }
    if (!o->do_basic && !o->do_flip && !o->do_struct) return gr_cli_usage_error(o->cmd, "--metric '%s': names no metric", v);
    return 0;
}

/* --flip-mode, --tone-mapper, --ppd, --exposures. */
static int parse_flip_option(compare_opts *o, const char *a, const char *v)
{
    if (!strcmp(a, "--flip-mode")) {
        if (!strcmp(v, "ldr")) o->flip_mode = GR_FLIP_LDR;
        else if (!strcmp(v, "hdr")) o->flip_mode = GR_FLIP_HDR;
        else return gr_cli_usage_error(o->cmd, "--flip-mode '%s': use ldr or hdr", v);
    } else if (!strcmp(a, "--tone-mapper")) {
        if (!strcmp(v, "aces")) o->fopt.tonemapper = GR_FLIP_TM_ACES;
        else if (!strcmp(v, "reinhard")) o->fopt.tonemapper = GR_FLIP_TM_REINHARD;
        else return gr_cli_usage_error(o->cmd, "--tone-mapper '%s': use aces or reinhard", v);
    } else if (!strcmp(a, "--ppd")) {
        char *end = NULL;
        errno = 0;
        const double d = strtod(v, &end);
        if (errno || end == v || *end || !isfinite(d) || d <= 0.0)
            return gr_cli_usage_error(o->cmd, "--ppd '%s' is not a number > 0", v);
        o->fopt.ppd = d;
    } else {
        double e0, e1;
        int k, used = 0;
        if (sscanf(v, "%lf:%lf:%d%n", &e0, &e1, &k, &used) != 3 || v[used] != '\0' || !isfinite(e0) ||
            !isfinite(e1) || e1 < e0 || k < 1)
            return gr_cli_usage_error(o->cmd, "--exposures '%s': need START:STOP:COUNT, START <= STOP, COUNT >= 1", v);
        o->fopt.exposures_given = 1, o->fopt.start_exposure = e0, o->fopt.stop_exposure = e1, o->fopt.n_exposures = k;
    }
    return 0;
}

/* An option with a value other than the FLIP ones and --metric. */
static int parse_value_option(compare_opts *o, const char *a, const char *v)
{
    if (!strcmp(a, "--mask")) {
        o->mask_path = v;
    } else if (!strcmp(a, "--stderr-bound")) {
        char *end = NULL;
        errno = 0;
        double b = strtod(v, &end);
        if (errno || end == v || *end || isnan(b) || b <= 0.0)
            return gr_cli_usage_error(o->cmd, "--stderr-bound '%s' is not a number > 0 (or inf)", v);
        o->opt.stderr_bound = b;
    } else if (!strcmp(a, "--set")) {
        if (o->n_sets >= (int)(sizeof o->sets / sizeof o->sets[0]))
            return gr_cli_usage_error(o->cmd, "--set: at most %d overrides", (int)(sizeof o->sets / sizeof o->sets[0]));
        o->sets[o->n_sets++] = v;
    } else if (!strcmp(a, "--scene")) {
        o->scene_path = v;
    } else if (!strcmp(a, "--vp")) {
        int used = 0;
        if (sscanf(v, "%lf,%lf%n", &o->vp[0], &o->vp[1], &used) != 2 || v[used] != '\0' || !isfinite(o->vp[0]) ||
            !isfinite(o->vp[1]))
            return gr_cli_usage_error(o->cmd, "--vp '%s': need X,Y (two numbers)", v);
        o->have_vp = 1;
    } else if (!strcmp(a, "--max-memory")) {
        gr_error merr;
        double bytes;
        if (gr_memlimit_parse("--max-memory", v, &bytes, &merr) != GR_OK) return gr_cli_usage_error(o->cmd, "%s", merr.msg);
        gr_memlimit_set(bytes);
    } else if (!strcmp(a, "--metric")) {
        return parse_metric_list(o, v);
    } else {
        return parse_flip_option(o, a, v);
    }
    return 0;
}

/* The argument at args->i; -1 to go on, else the exit code (0 after --help). */
static int parse_arg(gr_args *args, compare_opts *o)
{
    static const char *const with_value[] = {"--mask", "--stderr-bound", "--vp", "--scene", "--set", "--metric",
                                             "--flip-mode", "--ppd", "--tone-mapper", "--exposures", "--max-memory"};
    const char *a = args->argv[args->i], *v = NULL;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        const int rc = gr_args_value(args, &o->outdir);
        return rc ? rc : -1;
    }
    if (!strcmp(a, "--technique-dir")) { /* a --scene holding a user technique's section */
        const int rc = gr_args_take_technique_dir(args);
        return rc ? rc : -1;
    }
    for (size_t k = 0; k < sizeof with_value / sizeof with_value[0]; k++) {
        if (strcmp(a, with_value[k])) continue;
        int rc = gr_args_value(args, &v);
        if (!rc) rc = parse_value_option(o, a, v);
        return rc ? rc : -1;
    }
    gr_error ferr;
    const int fr = gr_fit_mode_option(args->argc, args->argv, &args->i, &o->fit, &ferr);
    if (fr < 0) return gr_cli_usage_error(o->cmd, "%s", ferr.msg);
    if (fr > 0) o->opt.fit_scale = (int)o->fit;
    else if (!strcmp(a, "--json")) o->json = 1;
    else if (!strcmp(a, "--no-linearize")) o->linearize = 0;
    else if (a[0] == '-' && a[1] != '\0') return gr_cli_usage_error(o->cmd, "unknown option '%s'", a);
    else if (o->npos >= 2) return gr_cli_usage_error(o->cmd, "unexpected argument '%s': give REF and TEST only", a);
    else o->paths[o->npos++] = a;
    return -1;
}

/* The whole command line into o; -1 to go on, else the exit code. */
static int parse_args(gr_args *args, compare_opts *o)
{
    for (; args->i < args->argc; args->i++) {
        const int rc = parse_arg(args, o);
        if (rc >= 0) return rc;
    }
    if (o->npos != 2) return gr_cli_usage_error(o->cmd, "need two images, REF and TEST");
    const int trc = gr_args_add_technique_dirs(args);
    if (trc) return trc;
    if (o->have_vp && o->scene_path) return gr_cli_usage_error(o->cmd, "give --vp or --scene, not both");
    if (o->n_sets && !o->scene_path) return gr_cli_usage_error(o->cmd, "--set needs --scene");
    if (o->do_struct == 1 && !o->have_vp && !o->scene_path)
        return gr_cli_usage_error(o->cmd, "--metric structure needs the vanishing point: --vp X,Y or --scene FILE");
    if (o->do_struct == -1) o->do_struct = o->have_vp || o->scene_path;
    /* no file written into -o DIR may replace an input (common/paths) */
    if (gr_args_add_input(args, "REF", o->paths[0]) || gr_args_add_input(args, "TEST", o->paths[1]) ||
        (o->scene_path && gr_args_add_input(args, "--scene", o->scene_path)))
        return 1;
    if (o->outdir) {
        const int rc = gr_args_check_output_dir(args, "-o", o->outdir);
        if (rc) return rc;
    }
    return -1;
}

/* Reads REF, TEST and the mask; checks sizes, layouts, the memory estimate and a black
 * reference. */
static gr_status read_inputs(const compare_opts *o, compare_state *s, gr_error *err)
{
    gr_status st = read_input("reference", o->paths[0], o->linearize, &s->ref, &s->info[0], &s->ref_dof, err);
    if (st == GR_OK) st = read_input("test", o->paths[1], o->linearize, &s->test, &s->info[1], NULL, err);
    if (st == GR_OK && o->mask_path) st = read_input("mask", o->mask_path, 0, &s->mask, NULL, NULL, err);
    if (st != GR_OK) return st;
    const gr_image *ref = s->ref, *test = s->test, *mask = s->mask;
    if (ref->width != test->width || ref->height != test->height)
        return gr_fail(err, GR_E_INPUT, "size mismatch: reference %s is %d x %d, test %s is %d x %d", o->paths[0],
                       ref->width, ref->height, o->paths[1], test->width, test->height);
    if (mask && (mask->width != ref->width || mask->height != ref->height))
        return gr_fail(err, GR_E_INPUT, "size mismatch: mask %s is %d x %d, images are %d x %d", o->mask_path,
                       mask->width, mask->height, ref->width, ref->height);
    for (int k = 0; k < 2; k++)
        if ((st = check_grey(k ? "test" : "reference", o->paths[k], k ? test : ref, err)) != GR_OK) return st;
    /* the metrics, blurs and difference images: about 170 bytes per pixel, measured
     * (2.8 GB for 4096 x 4096; docs/reliability.md); FLIP's working set on top, counted
     * from its buffers (an upper bound: they are allocated after the metrics' are freed):
     * 22 double planes, 2 x 3 double colours, 2 float maps, 1 double for the quantiles */
    const double per_px = 170.0 + (o->do_flip ? 22.0 * 8 + 6.0 * 8 + 2.0 * 4 + 8.0 : 0.0);
    char detail[96];
    snprintf(detail, sizeof detail, "%d x %d pixels at about %.0f bytes each", ref->width, ref->height, per_px);
    st = gr_memlimit_check("the comparison", per_px * ref->width * (double)ref->height, detail, err);
    if (st == GR_OK && all_zero(ref))
        st = gr_fail(err, GR_E_INPUT, "reference %s is zero everywhere: no metric can say anything about the test "
                     "image (camera inside an occluder, a medium without scattering, no light reaching the view?)",
                     o->paths[0]);
    return st;
}

/* The structure metrics' geometry: the vanishing point (--vp, or --scene's refracted sun) and,
 * with --scene, the angle to that sun per pixel for the de-glow. */
static gr_status structure_setup(compare_opts *o, compare_state *s, gr_error *err)
{
    const gr_image *ref = s->ref;
    if (o->scene_path) {
        gr_scene sc;
        gr_status st = gr_scene_load_file(o->scene_path, o->sets, o->n_sets, &sc, err);
        if (st == GR_OK) st = gr_structure_scene_vp(&sc, ref->width, ref->height, &o->vp[0], &o->vp[1], err);
        if (st != GR_OK) {
            if (st != GR_E_NOMEM) err->status = GR_E_INPUT;
            gr_error_prefix(err, "--scene %s", o->scene_path);
            return err->status;
        }
        /* de-glow by the angle to the refracted sun, rings one pixel wide */
        sc.camera.width = ref->width, sc.camera.height = ref->height;
        s->angles = malloc((size_t)ref->width * (size_t)ref->height * sizeof(float));
        if (!s->angles) return gr_fail(err, GR_E_NOMEM, "out of memory for the structure metrics");
        double dir[3];
        gr_profile_sun_view_dir(&sc, dir);
        gr_profile_angles(&sc.camera, dir, s->angles);
        s->so.radial = s->angles, s->so.radial_bin = sc.camera.fov_deg / ref->height;
    }
    s->so.vp_x = o->vp[0], s->so.vp_y = o->vp[1];
    o->opt.structure = &s->so;
    return GR_OK;
}

/* The scored pixels (as the metrics score them), once, for FLIP and the structure details. */
static gr_status need_scored(const compare_opts *o, compare_state *s, gr_error *err)
{
    if (s->scored) return GR_OK;
    s->scored = malloc((size_t)s->ref->width * (size_t)s->ref->height);
    if (!s->scored) return gr_fail(err, GR_E_NOMEM, "out of memory for the scored pixels");
    return gr_metrics_scored_pixels(s->ref, s->mask, o->opt.stderr_bound, s->scored, NULL, NULL, err);
}

/* FLIP on a * TEST (a = the fitted scale when asked for, else 1), pooled over the pixels the
 * other metrics score; the mode follows REF's format unless given. With its own options and
 * map it is reported in its own block ("flip"), not in the metric sets: those stay what
 * `godrays run` writes for the same pair (tests/cli/test_run.sh), where the registry's "flip"
 * is not computed. */
static gr_status compute_flip(compare_opts *o, compare_state *s, gr_error *err)
{
    const gr_image *ref = s->ref, *test = s->test;
    if (o->flip_mode < 0) {
        const char *dot = strrchr(o->paths[0], '.');
        o->flip_mode = dot && (!strcasecmp(dot, ".exr") || !strcasecmp(dot, ".hdr") || !strcasecmp(dot, ".pfm"))
                           ? GR_FLIP_HDR : GR_FLIP_LDR;
    }
    o->fopt.mode = (gr_flip_mode)o->flip_mode;
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    s->flipmap = malloc(n * sizeof(float));
    if (!s->flipmap) return gr_fail(err, GR_E_NOMEM, "out of memory for FLIP");
    gr_status st = need_scored(o, s, err);
    if (st != GR_OK) return st;
    o->fopt.scored = s->scored;
    if (!s->scaled && s->scale != 1.0) {
        s->scaled = gr_image_create(test->width, test->height, test->nchannels, NULL);
        if (!s->scaled) return gr_fail(err, GR_E_NOMEM, "out of memory for FLIP");
        memcpy(s->scaled->names, test->names, sizeof test->names);
        for (size_t i = 0; i < n * (size_t)test->nchannels; i++) s->scaled->pixels[i] = (float)(s->scale * test->pixels[i]);
    }
    const gr_image *ft = s->scaled ? s->scaled : test;
    const double t1 = now_s();
    /* a black reference (all-zero, or a zero median) gives HDR-FLIP no exposure range: FLIP
     * is left out, said so, instead of failing the whole comparison */
    int undefined = 0;
    st = gr_flip_compute_defined(ref, ft, &o->fopt, s->flipmap, &s->fres, &undefined, s->flip_skipped,
                                 sizeof s->flip_skipped, err);
    if (undefined) o->do_flip = 0;
    s->t_flip = now_s() - t1;
    return st;
}

/* The per-channel fit: TEST's R, G, B times a_R, a_G, a_B into s->scaled (what FLIP and the
 * difference pictures compare then, with factor 1). */
static gr_status rgb_fitted(compare_state *s, gr_error *err)
{
    static const char *const rgb[3] = {"R", "G", "B"};
    const gr_image *t = s->test;
    const size_t n = (size_t)t->width * (size_t)t->height;
    if (!(s->scaled = gr_image_create(t->width, t->height, 3, rgb))) return gr_fail(err, GR_E_NOMEM, "out of memory");
    for (size_t p = 0; p < n; p++)
        for (int c = 0; c < 3; c++)
            s->scaled->pixels[3 * p + (size_t)c] =
                (float)(s->m.fit.scale_rgb[c] * t->pixels[p * (size_t)t->nchannels + (size_t)s->m.test_rgb[c]]);
    return GR_OK;
}

/* The capture checks (compare/capture.h): their warnings go into the JSON, and on stderr once
 * everything has succeeded (print_warnings: a refused command says only why). */
static gr_status capture_checks(const compare_opts *o, compare_state *s, gr_error *err)
{
    gr_status st = need_scored(o, s, err);
    if (st != GR_OK) return st;
    gr_capture_input in = {.ref = s->ref, .test = s->test, .ref_rgb = s->m.ref_rgb, .test_rgb = s->m.test_rgb,
                           .scored = s->scored};
    gr_capture_file *f[2] = {&in.ref_file, &in.test_file};
    for (int k = 0; k < 2; k++)
        *f[k] = (gr_capture_file){.bits = s->info[k].bits, .integer = s->info[k].integer,
                                  .decoded = s->info[k].decoded, .n_top_code = s->info[k].n_top_code};
    if (s->m.have_fit && s->m.fit_defined && s->m.fit_mode == GR_FIT_RGB) in.fit_rgb = s->m.fit.scale_rgb;
    return gr_capture_check(&in, &s->capture, err);
}

static void print_warnings(const compare_opts *o, const compare_state *s)
{
    for (int k = 0; k < s->capture.n; k++) {
        const int ref = !strcmp(s->capture.w[k].code, "clipped_reference");
        fprintf(stderr, "godrays compare: warning: %s %s: %s\n", ref ? "reference" : "test", o->paths[ref ? 0 : 1],
                s->capture.w[k].message);
    }
}

/* Every number computed: the metrics (with the registry's), FLIP and the structure details. */
static gr_status compute_all(compare_opts *o, compare_state *s, gr_error *err)
{
    gr_status st = GR_OK;
    if (o->do_struct && (st = structure_setup(o, s, err)) != GR_OK) return st;
    o->opt.mask = s->mask;
    if (!o->do_basic) o->opt.skip_ssim = o->opt.skip_blur = o->opt.skip_extra = 1;
    o->opt.stderr_dof = s->ref_dof;
    const double t0 = now_s();
    st = gr_metrics_compute(s->ref, s->test, &o->opt, &s->m, err);
    s->t_metrics = now_s() - t0;
    if (st != GR_OK) return st;
    s->scale = s->m.have_fit && s->m.fit_defined ? s->m.fit.scale : 1.0;
    if (s->m.have_fit && s->m.fit_defined && s->m.fit_mode == GR_FIT_RGB && (st = rgb_fitted(s, err)) != GR_OK)
        return st;
    if ((st = capture_checks(o, s, err)) != GR_OK) return st;
    if (o->do_flip && (st = compute_flip(o, s, err)) != GR_OK) return st;
    if (o->do_struct) {
        if ((st = need_scored(o, s, err)) != GR_OK) return st;
        s->so.scored = s->scored;
        const double t2 = now_s();
        st = gr_structure_compare_images(s->ref, s->test, &s->so, &s->sres, err);
        s->t_struct = now_s() - t2;
    }
    return st;
}

/* A number, or null when not finite (not checked). */
static int add_num_or_null(cJSON *o, const char *k, double v)
{
    return (isfinite(v) ? cJSON_AddNumberToObject(o, k, v) : cJSON_AddNullToObject(o, k)) != NULL;
}

/* "warnings" (each: code, the file it is about, message) and "capture_checks" (the numbers
 * behind them) of the capture checks. */
static int add_capture_json(const compare_opts *o, const compare_state *s, cJSON *root)
{
    const gr_capture_report *c = &s->capture;
    cJSON *ws = cJSON_AddArrayToObject(root, "warnings");
    int ok = ws != NULL;
    for (int k = 0; ok && k < c->n; k++) {
        cJSON *w = cJSON_CreateObject();
        ok = w && cJSON_AddItemToArray(ws, w);
        const int ref = !strcmp(c->w[k].code, "clipped_reference");
        ok = ok && cJSON_AddStringToObject(w, "code", c->w[k].code) &&
             cJSON_AddStringToObject(w, "file", o->paths[ref ? 0 : 1]) &&
             cJSON_AddStringToObject(w, "message", c->w[k].message);
    }
    cJSON *cj = ok ? cJSON_AddObjectToObject(root, "capture_checks") : NULL;
    return cj && add_num_or_null(cj, "rel_rmse_y_fit_as_given", c->err_given) &&
           add_num_or_null(cj, "rel_rmse_y_fit_flipped_vertically", c->err_vflip) &&
           add_num_or_null(cj, "rel_rmse_y_fit_flipped_horizontally", c->err_hflip) &&
           add_num_or_null(cj, "scale", c->scale) && add_num_or_null(cj, "reference_top_code_fraction", c->top_fraction[0]) &&
           add_num_or_null(cj, "test_top_code_fraction", c->top_fraction[1]) &&
           add_num_or_null(cj, "test_log_slope_as_read", c->slope_given) &&
           add_num_or_null(cj, "test_log_slope_read_other_way", c->slope_other) &&
           add_num_or_null(cj, "test_rel_rmse_y_fit_as_read", c->err_as_read) &&
           add_num_or_null(cj, "test_rel_rmse_y_fit_read_other_way", c->err_other) &&
           cJSON_AddBoolToObject(cj, "test_decoded_from_srgb", s->info[1].decoded) &&
           cJSON_AddStringToObject(cj, "test_declared_colorspace", s->info[1].colorspace) &&
           add_num_or_null(cj, "test_bits", s->info[1].bits);
}

/* The JSON document (without the difference images' entries). */
static gr_status build_json(const compare_opts *o, compare_state *s, gr_error *err)
{
    cJSON *root = s->root = gr_metrics_to_json(&s->m);
    cJSON *rj = root ? image_json(o->paths[0], s->ref, s->m.ref_rgb) : NULL;
    if (rj && !cJSON_AddItemToObject(root, "reference", rj)) cJSON_Delete(rj), rj = NULL;
    cJSON *tj = rj ? image_json(o->paths[1], s->test, s->m.test_rgb) : NULL;
    if (tj && !cJSON_AddItemToObject(root, "test", tj)) cJSON_Delete(tj), tj = NULL;
    if (!tj || !add_capture_json(o, s, root) || !cJSON_AddBoolToObject(root, "linearized_8bit", o->linearize) ||
        !cJSON_AddNumberToObject(root, "metrics_time_s", s->t_metrics) ||
        (o->mask_path && !cJSON_AddStringToObject(root, "mask", o->mask_path)))
        return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    cJSON *sj = o->do_struct ? gr_structure_to_json(&s->sres, o->vp[0], o->vp[1]) : NULL;
    if (o->do_struct && (!sj || !cJSON_AddNumberToObject(sj, "time_s", s->t_struct) ||
                         !cJSON_AddItemToObject(root, "structure", sj))) {
        cJSON_Delete(sj);
        return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    }
    if (s->flip_skipped[0] && !cJSON_AddStringToObject(root, "flip_skipped", s->flip_skipped))
        return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    cJSON *fj = o->do_flip ? gr_flip_to_json(&s->fres, s->scale) : NULL;
    if (o->do_flip && (!fj || !cJSON_AddNumberToObject(fj, "time_s", s->t_flip) || !cJSON_AddItemToObject(root, "flip", fj))) {
        cJSON_Delete(fj);
        return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    }
    return GR_OK;
}

static const char *const diff_names[3] = {"diff.png", "diff_signed.png", "flip.png"};

/* The difference images (and the FLIP map) and their entries in the JSON. */
static gr_status make_diff_images(const compare_opts *o, compare_state *s, gr_error *err)
{
    cJSON *dj = cJSON_AddObjectToObject(s->root, "difference_images");
    if (!dj) return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    for (int k = 0; k < 2; k++) {
        const int per_channel = s->m.have_fit && s->m.fit_defined && s->m.fit_mode == GR_FIT_RGB;
        gr_diffmap_options dopt = {.kind = k ? GR_DIFFMAP_SIGNED : GR_DIFFMAP_ABS, .scale = per_channel ? 1.0 : s->scale,
                                   .mask = s->mask, .stderr_bound = o->opt.stderr_bound};
        gr_diffmap_info info;
        gr_status st = gr_diffmap_create(s->ref, per_channel ? s->scaled : s->test, &dopt, &s->diff[k], &info, err);
        if (st != GR_OK) return st;
        cJSON *one = cJSON_AddObjectToObject(dj, diff_names[k]);
        if (!one || !cJSON_AddStringToObject(one, "quantity", k ? "scale * Y(test) - Y(ref)" : "|scale * Y(test) - Y(ref)|") ||
            !cJSON_AddNumberToObject(one, "scale", s->scale) || !cJSON_AddStringToObject(one, "color_map", info.map) ||
            !cJSON_AddNumberToObject(one, "min", info.vmin) || !cJSON_AddNumberToObject(one, "max", info.vmax) ||
            !cJSON_AddBoolToObject(one, "colorbar_labelled", info.labelled) ||
            !cJSON_AddStringToObject(one, "unscored_pixels", "mid gray"))
            return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    }
    if (!o->do_flip) return GR_OK;
    gr_status st = gr_flip_heatmap(s->flipmap, s->ref->width, s->ref->height, &s->diff[2], err);
    if (st != GR_OK) return st;
    cJSON *one = cJSON_AddObjectToObject(dj, diff_names[2]);
    if (!one || !cJSON_AddStringToObject(one, "quantity", "FLIP per pixel (of scale * test)") ||
        !cJSON_AddNumberToObject(one, "scale", s->scale) || !cJSON_AddStringToObject(one, "color_map", "magma") ||
        !cJSON_AddNumberToObject(one, "min", 0.0) || !cJSON_AddNumberToObject(one, "max", 1.0))
        return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    return GR_OK;
}

/* -o DIR: everything is computed before the first file is written; each file goes through a
 * temporary name, so an error leaves no half-written file behind. */
static gr_status write_outputs(const compare_opts *o, compare_state *s, gr_error *err)
{
    gr_status st = gr_report_make_dir(o->outdir, err);
    char path[4200];
    for (int k = 0; st == GR_OK && k < 3; k++) {
        if (!s->diff[k]) continue;
        if (snprintf(path, sizeof path, "%s/%s", o->outdir, diff_names[k]) >= (int)sizeof path)
            st = gr_fail(err, GR_E_USAGE, "%s: output directory name too long", o->outdir);
        else
            st = gr_oiio_write(path, s->diff[k], err);
    }
    if (st == GR_OK) {
        snprintf(path, sizeof path, "%s/metrics.json", o->outdir); /* fits: diff_signed.png is longer */
        st = write_text(path, s->text, err);
    }
    return st;
}

/* The tables for people: the groups asked for, then the registry's metrics of those groups. */
static void print_text(const compare_opts *o, const compare_state *s)
{
    const gr_metrics *m = &s->m;
    printf("reference %s, test %s\n", o->paths[0], o->paths[1]);
    if (o->do_basic) gr_metrics_print_table(stdout, m);
    if (o->do_flip) gr_flip_print(stdout, "FLIP", &s->fres, s->scale);
    if (s->flip_skipped[0]) printf("  FLIP not computed: %s\n", s->flip_skipped);
    if (o->do_struct) gr_structure_print(stdout, &s->sres, o->vp[0], o->vp[1]);
    unsigned costs = 0;
    if (o->do_basic)
        costs |= 1u << GR_METRIC_COST_PASS | 1u << GR_METRIC_COST_SSIM | 1u << GR_METRIC_COST_BLUR |
                 1u << GR_METRIC_COST_OWN;
    if (o->do_flip) costs |= 1u << GR_METRIC_COST_FLIP;
    if (o->do_struct) costs |= 1u << GR_METRIC_COST_STRUCTURE;
    gr_metrics_print_summary(stdout, m, costs);
    if (o->outdir)
        printf("wrote %s/metrics.json, %s/diff.png, %s/diff_signed.png%s%s%s\n", o->outdir, o->outdir, o->outdir,
               o->do_flip ? ", " : "", o->do_flip ? o->outdir : "", o->do_flip ? "/flip.png" : "");
}

int cmd_compare(int argc, char **argv)
{
    compare_opts o = {.cmd = "compare", .linearize = 1, .do_basic = 1, .do_flip = 1, .do_struct = -1, .flip_mode = -1};
    gr_args args; /* no overrides: nothing to free */
    gr_args_create(&args, o.cmd, argc, argv);
    int rc = parse_args(&args, &o);
    if (rc >= 0) return rc;

    gr_error err = {0};
    compare_state *s = calloc(1, sizeof *s);
    if (!s) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        return gr_cli_report(o.cmd, &err);
    }
    gr_status st = read_inputs(&o, s, &err);
    if (st == GR_OK) st = compute_all(&o, s, &err);
    if (st == GR_OK) st = build_json(&o, s, &err);
    if (st == GR_OK && o.outdir) st = make_diff_images(&o, s, &err);
    if (st == GR_OK && !(s->text = cJSON_Print(s->root))) st = gr_fail(&err, GR_E_NOMEM, "out of memory printing the JSON");
    if (st == GR_OK && o.outdir) st = write_outputs(&o, s, &err);
    rc = 0;
    if (st != GR_OK) {
        rc = gr_cli_report(o.cmd, &err);
    } else {
        print_warnings(&o, s);
        if (o.json) printf("%s\n", s->text);
        else print_text(&o, s);
    }
    state_free(s);
    free(s);
    return rc;
}
