/* The scene: everything both renderers need, nothing more (docs/scene-format.md).
 * Conventions: y is up, the water rests at y = water.rest_height_m, lengths in metres,
 * angles in degrees in the file, radians in derived fields. Directions in the xz-plane
 * are given by an azimuth measured from +z toward +x: (sin a, cos a). */
#ifndef GR_SCENE_H
#define GR_SCENE_H

#include <stdint.h>
#include "common/status.h"
#include "scene/sections.h"
#include "scene/settings.h"

#define GR_MAX_WAVES 64
#define GR_MAX_OCCLUDERS 256
#define GR_GRAVITY 9.81 /* m/s^2, deep-water dispersion w^2 = g k */

typedef struct gr_wave {
    double amplitude_m;       /* a_i in seed eq. 5.5.7 */
    double wavelength_m;      /* lambda; wavenumber k = 2 pi / lambda */
    double direction_deg;     /* travel direction, azimuth from +z toward +x */
    double phase_rad;         /* phi_i^0 */
    double omega_rad_s;       /* w_i; from w^2 = g k unless given (NaN: re-derive in refresh) */
    /* derived */
    double k;                 /* 2 pi / lambda (1/m) */
    double dir[2];            /* unit (x, z) direction: (sin a, cos a) */
} gr_wave;

typedef struct gr_water {
    double rest_height_m;     /* h0 */
    double time_s;            /* t in eq. 5.5.7 */
    int n_waves;
    gr_wave waves[GR_MAX_WAVES];
} gr_water;

typedef struct gr_sun {
    double elevation_deg;     /* (0, 90] */
    double azimuth_deg;       /* toward the sun, from +z toward +x */
    double irradiance[3];     /* E_sun on a plane perpendicular to the rays (W/m^2, per RGB) */
    double angular_diameter_deg; /* default 0.53 */
    /* derived */
    double to_sun[3];         /* unit vector toward the sun */
    double dir[3];            /* I: unit direction in which sunlight travels (= -to_sun) */
} gr_sun;

typedef struct gr_medium {
    double absorption[3];     /* sigma_a (1/m) */
    double scattering[3];     /* sigma_s (1/m) */
    double g;                 /* Henyey-Greenstein asymmetry, (-1, 1) */
    double ior;               /* water IOR, default 1.333 */
    char preset[64];          /* name of the preset used, "" if none */
    /* derived */
    double extinction[3];     /* sigma_t = sigma_a + sigma_s */
} gr_medium;

typedef struct gr_camera {
    double position_m[3];
    int has_look_at;          /* 1: look_at_m given; 0: yaw/pitch given */
    double look_at_m[3];
    double yaw_deg, pitch_deg;/* azimuth from +z toward +x; pitch up from horizontal */
    double fov_deg;           /* vertical field of view, (0, 180) */
    int width, height;        /* pixels */
    /* derived: orthonormal frame. right = normalize(cross(forward, +y)), up = cross(right,
     * forward) (right-handed: right x up = -forward). Image x grows along right, image y
     * grows downward (along -up): the ray through pixel centre (px + 0.5, py + 0.5) is
     * forward + (2 (px + 0.5) / width - 1) tan(fov/2) (width/height) right
     *         - (2 (py + 0.5) / height - 1) tan(fov/2) up.
     * Looking straight up or down, right = (-cos yaw, 0, sin yaw) (the limit).
     * With look_at_m given, yaw_deg/pitch_deg are derived from forward; with yaw/pitch
     * given, look_at_m is derived as position + forward. */
    double forward[3], right[3], up[3];
} gr_camera;

typedef enum gr_occluder_type { GR_OCC_BOX = 0, GR_OCC_SPHERE = 1 } gr_occluder_type;

typedef struct gr_occluder {
    gr_occluder_type type;
    char name[64];            /* optional label, "" if none */
    double center_m[3];
    double size_m[3];         /* box: full extents along its local x, y, z */
    double yaw_deg;           /* box: rotation about +y */
    double radius_m;          /* sphere */
} gr_occluder;

typedef struct gr_scene {
    char name[128];
    gr_water water;
    gr_sun sun;
    gr_medium medium;
    gr_camera camera;
    int n_occluders;
    gr_occluder occluders[GR_MAX_OCCLUDERS];
    int has_seabed;
    double seabed_depth_m;    /* seabed plane at y = rest_height - depth */
    gr_reference_settings reference;
    /* Settings of every technique section known when the scene was loaded
     * (scene/sections.h): sections[i] holds table i's struct, n_sections of them. Use
     * gr_scene_section() or gr_technique_scene_settings() rather than indexing. */
    int n_sections;
    gr_section_store sections[GR_SCENE_MAX_SECTIONS];
    /* provenance */
    char source_path[1024];   /* file it was loaded from, "" for a string */
    char hash[17];            /* FNV-1a 64 of the normalized JSON, hex */
} gr_scene;

/* Loads, validates and normalizes a scene file. overrides: n_overrides strings of the
 * form "json.path=value" (e.g. "shafts.K=0.7", "medium.g=0.9", "sun.irradiance=[1,2,3]"),
 * applied to the JSON before validation so they are checked like the file itself.
 * Errors name the file, the JSON path and the reason; GR_E_INPUT for bad content,
 * GR_E_IO when the file cannot be read. */
gr_status gr_scene_load_file(const char *path, const char *const *overrides, int n_overrides,
                             gr_scene *out, gr_error *err);
/* Same, from a JSON string; `label` names the source in error messages. */
gr_status gr_scene_load_string(const char *json, const char *label,
                               const char *const *overrides, int n_overrides,
                               gr_scene *out, gr_error *err);
/* Parses JSON text (a scene, a user technique's manifest) into a cJSON tree (*out, the
 * caller's: cJSON_Delete); GR_E_INPUT "LABEL:LINE:COL: malformed JSON near '...'" (or at end
 * of input, or nested deeper than cJSON's limit): the one wording of a JSON syntax error. */
/* Reads a JSON file's text (*out, malloc'd, NUL-terminated): a regular file only, at most
 * max_bytes ("PATH: file too large for a WHAT (over N MiB)", GR_E_INPUT), no NUL byte inside;
 * GR_E_IO naming the file when it cannot be opened or read. Scenes, suites and presets. */
gr_status gr_json_read_file(const char *path, const char *what, size_t max_bytes, char **out, gr_error *err);
struct cJSON;
gr_status gr_json_parse(const char *text, const char *label, struct cJSON **out, gr_error *err);
/* "a number", "a string", "a boolean", "null", "an array", "an object" for error messages;
 * "nothing" for NULL (a missing value). */
const char *gr_json_type_name(const struct cJSON *v);
/* Normalized JSON (every default filled in, stable key order, 2-space indent).
 * Returns a malloc'd string the caller frees; NULL on allocation failure. */
char *gr_scene_to_json(const gr_scene *s);
/* Recomputes derived fields (wave k/dir/omega, sun direction, extinction, camera frame)
 * and the hash after a caller changed fields in place (e.g. a sweep). Re-validates.
 * A wave's omega_rad_s set to NaN is re-derived from w^2 = g k, and a section's
 * scene-derived settings (GR_PF_FROM_SCENE, e.g. shafts.extinction) set to NaN are re-taken
 * from their scene_source (their defaults); otherwise values
 * loaded from a file stay as they are. Errors are prefixed with source_path if set. */
gr_status gr_scene_refresh(gr_scene *s, gr_error *err);

/* Settings of technique section i (scene/sections.h) in s; NULL if the scene was loaded
 * before that section was added (or i is out of range). */
void *gr_scene_section(gr_scene *s, int i);
const void *gr_scene_section_const(const gr_scene *s, int i);
/* Sets every GR_PF_FROM_SCENE setting of settings (table t) that is NaN to the scene
 * quantity its descriptor's scene_source names ("medium.extinction", "medium.g", ...). */
void gr_scene_resolve_settings(const gr_param_table *t, void *settings, const gr_scene *s);

#endif
