/* Command-line arguments the godrays commands share: the scene overrides that --set, --size
 * and per-setting flags such as --spp collect, option values, the one scene argument, the
 * scene itself, and the check that an output file or folder can be written before any slow
 * work. Parsing stays in each cmd_NAME.c (a loop over argv); these functions do the parts
 * that used to be written out in every command.
 *
 * Every function that reads or checks an argument returns a process exit code: 0 when all is
 * well, else the code of the one line it printed on stderr (2: bad usage or input, through
 * gr_cli_usage_error or "godrays CMD: message"; 1: out of memory). */
#ifndef GR_CLI_ARGS_H
#define GR_CLI_ARGS_H

#include "gl/glctx.h"
#include "realtime/technique.h"
#include "report/html.h"
#include "scene/scene.h"
#include "suite/suite.h"

#define GR_ARGS_MAX_OUTPUTS 16 /* files one command writes beside each other (export: 4) */

typedef struct gr_args {
    const char *cmd;            /* the subcommand, for messages ("run") */
    int argc;
    char **argv;                /* argv[0] is the subcommand's name */
    int i;                      /* the argument being read; taking a value advances it */
    char **sets;                /* scene overrides "KEY=VALUE" in command-line order (owned) */
    int n_sets, cap_sets;
    char **origins;             /* per override: the flag and value that made it ("--threads 4"),
                                   NULL for --set; messages name what the user typed (owned) */
    int have_size;              /* --size was given */
    const char *size_example;   /* in the --size message; NULL: "640x360" */
    const char *scene_path;     /* the positional SCENE argument (NULL: none yet) */
    const char *tech_dirs[GR_TECH_MAX]; /* --technique-dir values, in order */
    int n_tech_dirs;
    char *out_roles[GR_ARGS_MAX_OUTPUTS]; /* the outputs checked so far: "--gltf" (owned) */
    char *out_paths[GR_ARGS_MAX_OUTPUTS]; /* and their paths (owned) */
    int n_outs;
    const char *preset_path;    /* --preset FILE (NULL: none) */
    int preset_pos;             /* where its overrides go among the others */
    char preset_technique[GR_TECH_NAME_MAX]; /* its technique, once applied ("" before) */
} gr_args;

/* Empty overrides, reading argv from argument 1. */
void gr_args_create(gr_args *a, const char *cmd, int argc, char **argv);
void gr_args_free(gr_args *a); /* frees the overrides; accepts NULL */
/* create, fn, free: the whole of cmd_NAME for a command written as NAME_with(gr_args *);
 * returns fn's exit code. */
int gr_args_main(const char *cmd, int argc, char **argv, int (*fn)(gr_args *a));

/* The overrides as gr_scene_load_file takes them. */
const char *const *gr_args_sets(const gr_args *a);

/* The value of the flag argv[i]: *value = argv[i + 1] and i advances; "FLAG needs a value". */
int gr_args_value(gr_args *a, const char **value);
/* As gr_args_value for a folder name, which must not be empty ("FLAG: empty directory name"). */
int gr_args_dir(gr_args *a, const char **dir);

/* --set KEY=VALUE: appends the override ("--set V: expected KEY=VALUE"). */
int gr_args_take_set(gr_args *a);
/* --size WxH: appends camera.width=W and camera.height=H ("--size V: expected WxH, e.g. ..."). */
int gr_args_take_size(gr_args *a);
/* FLAG V for a flag that stands for one scene setting (--spp V): appends "key=V". */
int gr_args_take_setting(gr_args *a, const char *key);
/* --gl-platform auto|surfaceless|device. */
int gr_args_take_gl_platform(gr_args *a, gr_gl_platform *platform);
/* argv[i] as one of the options of the commands that write a folder from a scene (run,
 * sweep, tune, pareto): -o/--output DIR (into *dir, see gr_args_dir), --set, --size,
 * --technique-dir, --max-memory, --time-limit, --preset, and --gl-platform when platform is not NULL.
 * *taken = 0 (and 0 returned) when it is none. */
int gr_args_take_common(gr_args *a, const char **dir, gr_gl_platform *platform, int *taken);
/* --max-memory SIZE: the limit of every memory estimate of the command (common/memlimit). */
int gr_args_take_max_memory(gr_args *a);
/* --technique-dir DIR: remembers DIR (repeatable; added by gr_args_add_technique_dirs). */
int gr_args_take_technique_dir(gr_args *a);
/* --time-limit SECONDS: every technique render's time limit (gr_technique_set_time_limit). */
int gr_args_take_time_limit(gr_args *a);
/* Registers the user technique of every --technique-dir (gr_technique_add_dir), in order,
 * then applies --preset (its technique may be a user one); call it once, after the argument
 * loop and BEFORE loading the scene (a user technique's section is unknown to the loader until
 * then). A bad folder, manifest or preset: its message. */
int gr_args_add_technique_dirs(gr_args *a);
/* --preset FILE (tune/preset.h): remembered; its settings become overrides at this place
 * among the --set ones when gr_args_add_technique_dirs applies it (taken by
 * gr_args_take_common too). A second --preset is a usage error. */
int gr_args_take_preset(gr_args *a);
/* The technique called name (for the argument `what`, e.g. "--technique"); a usage error
 * listing the known ones otherwise. */
int gr_args_find_technique(const gr_args *a, const char *what, const char *name, const gr_technique_class **cls);

/* An override the command adds itself (printf format, e.g. "camera.width=%d"). */
int gr_args_add_set(gr_args *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* argv[i] is neither a flag nor a value: "unknown option X" if it starts with '-' (a lone "-"
 * is a name), "more than one scene given (A, B)" if a scene was given, else it is the scene. */
int gr_args_take_scene(gr_args *a);
/* After the loop: "no scene file given" when there is none. */
int gr_args_need_scene(const gr_args *a);
/* Loads the scene with the overrides into a new *scene (free() it); the loader's message and
 * exit code otherwise (2 for a bad scene, 1 for an unreadable file). */
int gr_args_load_scene(const gr_args *a, gr_scene **scene);
/* Loads the suite at path (registered as the input "the suite") with the overrides, which
 * apply to every case after its own (suite/suite.h), into a new *suite (gr_suite_destroy it);
 * the loader's one line and exit code otherwise (2 for a bad suite, 1 for an unreadable file). */
int gr_args_load_suite(gr_args *a, const char *path, gr_suite **suite);
/* Appends the scene and the options that change it (--set, --size) as typed, shell-quoted
 * and separated by spaces: the scene words of commands that an output suggests running next. */
void gr_args_scene_words(const gr_args *a, gr_strbuf *b);

/* The PNG preview beside an EXR: a trailing ".exr" (any case) becomes ".png", any other
 * name gets ".png" appended (so frame files OUT.0007 keep distinct previews). */
void gr_args_preview_path(const char *exr, char *buf, size_t n);

/* Registers an input the command reads (common/paths: no output may replace it), described
 * as `role path` in messages ("part a.part"); role and path must outlive the command. The
 * scene argument is registered by gr_args_take_scene ("the scene"). Exit 1: out of memory. */
int gr_args_add_input(gr_args *a, const char *role, const char *path);
/* An output the command writes beside the others, e.g. the .bin of a .gltf or an EXR's PNG
 * preview (role: "--gltf x.gltf's buffer"): refused (exit 2, one line naming both) when it is
 * the same file as an input or as an output checked before; else remembered. */
int gr_args_note_output(gr_args *a, const char *role, const char *path);
/* gr_args_note_output for the PNG preview of the EXR that flag names (gr_args_preview_path). */
int gr_args_note_preview(gr_args *a, const char *flag, const char *exr);

/* Fails early (exit 2, nothing created) unless a file can be written at path: its folder
 * exists, is a folder and is writable, path is not a folder, and it is neither the same file
 * as an input nor as an output checked before (gr_args_note_output). The message names flag
 * (e.g. "-o", or "default output" when the path was not given), the path and the reason. */
int gr_args_check_output_file(gr_args *a, const char *flag, const char *path);
/* The same for a folder the command creates with its missing parents: path is a writable
 * folder, or its nearest existing ancestor is, and it is no input. (A file the command
 * writes into it that is an input is refused when it is written: common/outfile.) */
int gr_args_check_output_dir(const gr_args *a, const char *flag, const char *path);

/* The output folder: given (the -o value) or, when NULL, the default out/SCENE_NAME[/sub]
 * (gr_tune_default_dir, into buf), checked with gr_args_check_output_dir. scene NULL: the
 * scene is loaded for its name (messages as gr_args_load_scene). */
int gr_args_output_dir(const gr_args *a, const gr_scene *scene, const char *given, const char *sub, char *buf,
                       size_t n, const char **dir);

#endif
