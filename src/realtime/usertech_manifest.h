/* A user technique's manifest (docs/techniques.md): DIR/manifest.json parsed and validated,
 * every shader file it names read, its settings turned into a gr_param_table. No GL: the
 * renderer that runs a manifest is realtime/usertech.c.
 *
 * Every file of a manifest (the manifest itself and each shader) is opened by ONE function,
 * gr_ut_read_file, so checks on what a manifest may read belong there. Errors: GR_E_INPUT
 * with "DIR/manifest.json: JSON.PATH: reason" (one line). */
#ifndef GR_USERTECH_MANIFEST_H
#define GR_USERTECH_MANIFEST_H

#include <stddef.h>

#include "common/status.h"
#include "realtime/technique.h"
#include "scene/params.h"

#define GR_USERTECH_MANIFEST "manifest.json"

#define GR_UT_MAX_SETTINGS 64
#define GR_UT_MAX_TARGETS 8
#define GR_UT_MAX_PASSES 6   /* + the two harness inputs = GR_TECH_MAX_PASSES timed passes */
#define GR_UT_MAX_INPUTS 8
#define GR_UT_MAX_FACTORS 4
#define GR_UT_NAME_MAX 24
#define GR_UT_MAX_SIZE 16384
#define GR_UT_MAX_LADDER 16
#define GR_UT_MAX_FILE_BYTES (1 << 20) /* a manifest or a shader file: 1 MiB at most */
#define GR_UT_MAX_FILES 32               /* shader files, includes counted */
#define GR_UT_MAX_INCLUDE_DEPTH 16
#define GR_UT_LINE_BASE 10000000 /* > the lines of a 1 MiB file; 33 x it fits an int */

typedef enum { GR_UT_NUMBER, GR_UT_INT, GR_UT_BOOL, GR_UT_RGB } gr_ut_type;
extern const char *const gr_ut_type_names[];

typedef enum { GR_UT_FMT_RGBA8, GR_UT_FMT_RGBA16F, GR_UT_FMT_RGBA32F } gr_ut_format;
extern const char *const gr_ut_format_names[];

typedef enum { GR_UT_BLEND_NONE, GR_UT_BLEND_ADDITIVE, GR_UT_BLEND_ALPHA } gr_ut_blend;
extern const char *const gr_ut_blend_names[];

typedef enum { GR_UT_PRIM_TRIANGLES, GR_UT_PRIM_TRIANGLE_STRIP, GR_UT_PRIM_LINES, GR_UT_PRIM_POINTS } gr_ut_prim;
extern const char *const gr_ut_prim_names[];

/* Harness textures a pass may list among its inputs (bound as t_NAME; gr_ut_input_name). */
enum {
    GR_UT_IN_SHADOW_MAP = -1,
    GR_UT_IN_EYE_DEPTH = -2,
    GR_UT_IN_LIGHT = -3,
    GR_UT_IN_CAUSTICS = -4,
    GR_UT_IN_SCENE_COLOUR = -5,
    GR_UT_N_HARNESS_INPUTS = 5
};
#define GR_UT_HARNESS_INPUTS "\"shadow_map\", \"eye_depth\", \"sun_light\", \"caustics\" or \"scene_colour\""
/* The caustic stack's values of a "caustics" object: the volume techniques' caustic settings
 * (realtime/volsettings.h gr_vol_caustic_descriptors), in their order. */
#define GR_UT_CAUSTIC_VALUES 8

typedef struct gr_ut_setting {
    char key[GR_TECH_NAME_MAX];
    gr_ut_type type;
    size_t offset;
} gr_ut_setting;

/* A number given in the manifest or taken from a setting (setting >= 0). */
typedef struct gr_ut_value {
    double v;
    int setting;
} gr_ut_value;

/* A count: literal * product of int settings ("6*N*N"). */
typedef struct gr_ut_count {
    long long literal;
    int n_factors;
    int factor[GR_UT_MAX_FACTORS];
} gr_ut_count;

typedef struct gr_ut_target {
    char name[GR_UT_NAME_MAX];
    int absolute, width, height; /* "size": [w, h] */
    gr_ut_value scale;              /* "scale": relative to the frame, per axis */
    gr_ut_format format;
    int linear;
} gr_ut_target;

typedef struct gr_ut_pass {
    char name[GR_UT_NAME_MAX];
    char *vertex_file, *fragment_file; /* as written in the manifest; vertex NULL = built-in */
    char *vertex_src, *fragment_src;
    int fullscreen;
    gr_ut_prim prim;
    gr_ut_count vertices, instances;
    int target;
    gr_ut_blend blend;
    int has_clear;
    float clear[4];
    int n_inputs;
    int inputs[GR_UT_MAX_INPUTS]; /* target index, or GR_UT_IN_* */
    char *defines;                /* "#define NAME VALUE\n" lines of its "defines" (NULL: none) */
} gr_ut_pass;

typedef struct gr_ut_manifest {
    char name[GR_TECH_NAME_MAX];
    char *description;
    char *dir, *path; /* folder, and folder/manifest.json */
    int n_settings;
    gr_ut_setting settings[GR_UT_MAX_SETTINGS];
    gr_param params[GR_UT_MAX_SETTINGS];
    char *param_strings[GR_UT_MAX_SETTINGS][2]; /* unit, doc (owned) */
    gr_param_table table;
    size_t settings_size;
    int n_targets;
    gr_ut_target targets[GR_UT_MAX_TARGETS];
    int n_passes;
    gr_ut_pass passes[GR_UT_MAX_PASSES];
    int output;
    int allow_black;
    int uses_shadow_map, uses_eye_depth, uses_light, uses_caustics, uses_scene_colour;
    gr_ut_value shadow_size, shadow_half_extent;
    /* "sun_light": the harness's light texture (realtime/toolkit.h gr_light_pass) */
    gr_ut_value light_scale, light_radius_deg, light_threshold;
    gr_ut_format light_format;
    int light_occluders;
    /* "caustics": value i is descriptor i of gr_vol_caustic_descriptors (texture_size, grid,
     * patch_m, caustic_depths, caustic_first_m, caustic_last_m, sun_disc), defaults theirs */
    int n_caustic_values;
    gr_ut_value caustic[GR_UT_CAUSTIC_VALUES];
    /* "scene_colour" (realtime/scenecolour.h): size, format, the light pass's kernel radius and
     * the albedo (a number or [r, g, b]; or a number or rgb setting: albedo_setting >= 0) */
    gr_ut_value scol_scale, scol_radius_deg;
    gr_ut_format scol_format;
    double scol_albedo[3];
    int scol_albedo_setting;
    /* every shader file read, includes too, relative to dir: line L of files[K] is numbered
     * GR_UT_LINE_BASE * (K + 1) + L in the sources ("#line"; Mesa ignores #line's source
     * string number), so a driver's line maps back to the file and its own line */
    int n_files;
    char *files[GR_UT_MAX_FILES];
    char source_hash[17]; /* FNV-1a 64 of the manifest and every shader file, hex */
    int n_ladder;
    gr_technique_level ladder[GR_UT_MAX_LADDER];
    char *ladder_text[GR_UT_MAX_LADDER];
    gr_technique_class cls; /* the class made from it (usertech.c fills it): lives as long as m */
} gr_ut_manifest;

/* t_NAME's NAME of input `in` of a pass (a target's index or GR_UT_IN_*; m may be NULL for
 * GR_UT_IN_*). */
const char *gr_ut_input_name(const gr_ut_manifest *m, int in);
/* GR_UT_IN_* of a harness texture's name ("sun_light", ...); 0 for any other name. */
int gr_ut_harness_input(const char *name);

/* A growable string (zero-initialize; free .s): gr_ut_sb_add appends printf-style; on no
 * memory it sets failed and keeps what it had. Ladder texts here, GLSL preludes in usertech.c. */
typedef struct gr_ut_strbuf {
    char *s;
    size_t len, cap;
    int failed;
} gr_ut_strbuf;
void gr_ut_sb_add(gr_ut_strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Parses and validates DIR/manifest.json and reads its shader files into a new manifest
 * (source_hash, table set; cls left zero); *out is the caller's: gr_ut_manifest_free. */
gr_status gr_ut_manifest_load(const char *dir, gr_ut_manifest **out, gr_error *err);
void gr_ut_manifest_free(gr_ut_manifest *m); /* accepts NULL */

/* Reads the whole text file at path into *out (malloc'd, NUL-terminated): the one place a
 * manifest's files are opened. The file must lie inside the folder dir once links and ".."
 * are resolved (realpath), be a regular file (checked on a non-blocking descriptor, so a
 * FIFO never blocks) of at most GR_UT_MAX_FILE_BYTES, and hold no NUL byte. GR_E_IO (why:
 * strerror, outside the folder, not a regular file, over the cap, a NUL byte, a read error;
 * never the file's contents) or GR_E_NOMEM, with the reason in why. */
gr_status gr_ut_read_file(const char *dir, const char *path, char **out, char *why, size_t why_n);

#endif
