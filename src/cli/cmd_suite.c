/* godrays suite validate|list SUITE: check a view suite (src/suite/suite.h,
 * docs/scene-format.md "Suites") and show its cases. */
#include "cli/cli.h"
#include "cli/args.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "suite/suite.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays suite validate SUITE.json [options]\n"
            "       godrays suite list SUITE.json [options]\n"
            "\n"
            "A view suite is a list of cases, each a scene plus camera, sun and time overrides, with a\n"
            "name and a split (train or test): the views over which `godrays run --suite` ranks the\n"
            "techniques (docs/scene-format.md \"Suites\"; shipped suites: data/suites/).\n"
            "  validate  loads the suite and every case's scene with its overrides, checks them and\n"
            "            prints one line: the suite's name and its cases per split\n"
            "  list      one line per case: name, split, scene file, size, camera (position, yaw,\n"
            "            pitch, field of view), sun (elevation, azimuth), water time, extinction\n"
            "            (green, 1/m), occluders, seabed depth\n"
            "\n"
            "options:\n"
            "  --set KEY=VALUE      override a scene value in every case (after the case's own)\n"
            "  --size WxH           image size of every case (instead of the suite's \"size\")\n"
            "  --technique-dir DIR  add the user technique in DIR first (its section is then known)\n"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 valid; 2 bad usage or a bad suite (one line naming the suite file and the\n"
            "JSON path, or the case's scene file and its path); 1 the suite cannot be read.\n");
}

static void list_cases(const gr_suite *s)
{
    printf("%-22s %-5s %-28s %9s %-22s %6s %6s %5s %6s %6s %7s %8s %4s %7s\n", "case", "split", "scene", "size",
           "camera position (m)", "yaw", "pitch", "fov", "sun el", "sun az", "time s", "ext g/m", "occ", "seabed");
    for (int i = 0; i < s->n_cases; i++) {
        const gr_suite_case *c = &s->cases[i];
        const gr_scene *sc = &c->scene;
        const gr_camera *cam = &sc->camera;
        const char *file = strrchr(c->scene_path, '/');
        char size[32], pos[64], bed[16];
        snprintf(size, sizeof size, "%dx%d", cam->width, cam->height);
        snprintf(pos, sizeof pos, "%g,%g,%g", cam->position_m[0], cam->position_m[1], cam->position_m[2]);
        if (sc->has_seabed) snprintf(bed, sizeof bed, "%g", sc->seabed_depth_m);
        else snprintf(bed, sizeof bed, "none");
        printf("%-22s %-5s %-28s %9s %-22s %6.1f %6.1f %5.1f %6.1f %6.1f %7.3g %8.3g %4d %7s\n", c->name,
               gr_split_name(c->split), file ? file + 1 : c->scene_path, size, pos, cam->yaw_deg, cam->pitch_deg,
               cam->fov_deg, sc->sun.elevation_deg, sc->sun.azimuth_deg, sc->water.time_s, sc->medium.extinction[1],
               sc->n_occluders, bed);
    }
}

typedef struct suite_cli {
    int list;             /* 1: list, 0: validate */
    const char *path;
} suite_cli;

static int suite_parse(gr_args *a, suite_cli *o, int *help)
{
    for (; a->i < a->argc; a->i++) {
        const char *v = a->argv[a->i];
        int rc = 0;
        if (!strcmp(v, "-h") || !strcmp(v, "--help")) {
            usage(stdout);
            *help = 1;
            return 0;
        }
        if (!strcmp(v, "--set")) rc = gr_args_take_set(a);
        else if (!strcmp(v, "--size")) rc = gr_args_take_size(a);
        else if (!strcmp(v, "--technique-dir")) rc = gr_args_take_technique_dir(a);
        else if (v[0] == '-' && v[1] != '\0') rc = gr_cli_usage_error(a->cmd, "unknown option %s", v);
        else if (o->path) rc = gr_cli_usage_error(a->cmd, "more than one suite given (%s, %s)", o->path, v);
        else o->path = v;
        if (rc) return rc;
    }
    return o->path ? 0 : gr_cli_usage_error(a->cmd, "no suite file given");
}

static int suite_with(gr_args *a, int list)
{
    suite_cli o = {list, NULL};
    int help = 0, rc = suite_parse(a, &o, &help);
    if (rc || help) return rc;
    if ((rc = gr_args_add_technique_dirs(a)) != 0) return rc; /* their sections before the scenes */
    gr_suite *s = NULL;
    if ((rc = gr_args_load_suite(a, o.path, &s)) != 0) return rc;
    printf("%s: suite '%s', %d cases (%d train, %d test)", o.path, s->name, s->n_cases,
           gr_suite_count(s, GR_SPLIT_TRAIN), gr_suite_count(s, GR_SPLIT_TEST));
    if (s->width > 0) printf(", size %dx%d", s->width, s->height);
    printf(o.list ? "\n" : ": valid\n");
    if (o.list) {
        if (s->description[0]) printf("%s\n", s->description);
        list_cases(s);
    }
    gr_suite_destroy(s);
    if (fflush(stdout) != 0) {
        gr_error err;
        gr_fail(&err, GR_E_IO, "cannot write to stdout");
        return gr_cli_report(a->cmd, &err);
    }
    return 0;
}

static int validate_with(gr_args *a)
{
    return suite_with(a, 0);
}

static int list_with(gr_args *a)
{
    return suite_with(a, 1);
}

int cmd_suite(int argc, char **argv)
{
    const char *sub = argc > 1 ? argv[1] : NULL;
    if (!sub) return gr_cli_usage_error("suite", "expected a subcommand: validate or list");
    if (!strcmp(sub, "-h") || !strcmp(sub, "--help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(sub, "validate")) return gr_args_main("suite validate", argc - 1, argv + 1, validate_with);
    if (!strcmp(sub, "list")) return gr_args_main("suite list", argc - 1, argv + 1, list_with);
    return gr_cli_usage_error("suite", "unknown subcommand '%s' (expected validate or list)", sub);
}
