/* Scene format v1: loading (cJSON), overrides, validation, derived fields, normalized
 * printing and hashing. The format is specified for users in docs/scene-format.md.
 *
 * Pipeline: text -> cJSON tree -> overrides applied to the tree -> tree parsed into a
 * gr_scene (keys, types, finiteness) -> field ranges -> derived fields -> cross-field
 * checks (camera under the actual Gerstner surface, seabed below the camera, ...) -> hash.
 * Every error carries the JSON path it concerns, so an error caused by a --set override
 * can be attributed to that override rather than to the file. */
#include "scene/scene.h"
#include "common/outfile.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/gerstner.h"

#define DEG2RAD (3.14159265358979323846 / 180.0)
#define RAD2DEG (180.0 / 3.14159265358979323846)
#define GR_MAX_IMAGE_SIDE 16384
#define GR_MAX_SCENE_BYTES (64u << 20)
/* Positions beyond this are rejected: far enough for precision tests (1e5 m), near enough
 * that sums of coordinates and squared distances stay finite and meaningful. */
#define GR_MAX_COORD_M 1e7

/* ---- medium presets -----------------------------------------------------------------
 * Only presets whose every number has a published source (docs/scene-format.md).
 * RGB channels stand for 650 / 550 / 450 nm. */
typedef struct medium_preset {
    const char *name;
    double absorption[3], scattering[3], g;
} medium_preset;

static const medium_preset presets[] = {
    /* Absorption: pure water, Pope & Fry 1997 (Appl. Opt. 36(33):8710) at 650/550/450 nm.
     * Scattering: pure seawater, Morel 1974, b(500) = 0.00288 /m scaled as lambda^-4.32.
     * g = 0: molecular (Rayleigh-like) scattering is nearly symmetric. */
    {"pure_seawater", {0.340, 0.0565, 0.00922}, {0.0009, 0.0019, 0.0045}, 0.0},
};
static const int n_presets = (int)(sizeof presets / sizeof presets[0]);

/* Defaults of a medium given without a preset: clear oceanic water, illustrative
 * (docs/scene-format.md, "Default medium"). Chlorophyll C = 0.05 mg/m^3 assumed.
 * Absorption: Pope & Fry 1997 pure water + phytoplankton (Bricaud et al. 1998,
 * a_ph(440) = 0.0654 C^0.728) + a like amount of CDOM, rounded: +[0.002, 0.002, 0.012].
 * Scattering: Gordon & Morel 1983 b_p = 0.30 C^0.62 (550/lambda) + Morel 1974 seawater.
 * g = 0.9: Petzold's particle mean cosine ~0.92 diluted by 4-7% molecular (g = 0). */
static const double default_absorption[3] = {0.342, 0.0585, 0.0212};
static const double default_scattering[3] = {0.041, 0.049, 0.062};
static const double default_g = 0.9;

/* ---- error context ------------------------------------------------------------------ */
typedef struct vctx {
    gr_error *err;
    char path[384]; /* JSON path of the failing element, for override attribution */
} vctx;

static gr_status vfail(vctx *c, const char *path, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static gr_status vfail(vctx *c, const char *path, const char *fmt, ...)
{
    char msg[GR_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(c->path, sizeof c->path, "%s", path);
    return gr_fail(c->err, GR_E_INPUT, "%s: %s", path[0] ? path : "(root)", msg);
}

/* Messages are one line: control characters that came from the input (a key or string
 * with an escaped newline, an override argument) are shown as '?'. */
static gr_status one_line(gr_error *err, gr_status st)
{
    if (err && st != GR_OK)
        for (char *q = err->msg; *q; q++)
            if ((unsigned char)*q < 0x20 || *q == 0x7f) *q = '?';
    return st;
}

static void join(char *out, size_t n, const char *parent, const char *key)
{
    if (parent[0]) snprintf(out, n, "%s.%s", parent, key);
    else snprintf(out, n, "%s", key);
}

/* Short text of a JSON value for "got VALUE" (numbers printed exactly, long values cut). */
static const char *got_text(const cJSON *v, char *buf, size_t n)
{
    if (cJSON_IsNumber(v)) return gr_format_double(v->valuedouble, buf, n);
    char *s = cJSON_PrintUnformatted(v);
    if (!s) { snprintf(buf, n, "?"); return buf; }
    if (strlen(s) > 60) snprintf(buf, n, "%.57s...", s);
    else snprintf(buf, n, "%s", s);
    cJSON_free(s);
    return buf;
}

const char *gr_json_type_name(const struct cJSON *v)
{
    if (!v) return "nothing";
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "an invalid value";
}

/* Levenshtein distance, for "did you mean" suggestions (names are short). */
static int edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 63 || lb > 63) return 99;
    int row[64];
    for (size_t j = 0; j <= lb; j++) row[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int up = row[j];
            int cost = a[i - 1] == b[j - 1] ? 0 : 1;
            int best = diag + cost;
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb];
}

/* Closest of names[0..n) to key within a small distance, else NULL. */
static const char *suggest(const char *key, const char *const *names, size_t n)
{
    const char *best = NULL;
    int bestd = 99;
    for (size_t i = 0; i < n; i++) {
        int d = edit_distance(key, names[i]);
        if (d < bestd) { bestd = d; best = names[i]; }
        /* a key that merely lacks its unit suffix ("fov" for "fov_deg") is also close */
        size_t lk = strlen(key);
        if (lk >= 2 && !strncmp(key, names[i], lk) && names[i][lk] == '_' && bestd > 1) {
            bestd = 1;
            best = names[i];
        }
    }
    int limit = (int)strlen(key) / 3 + 1;
    if (limit < 2) limit = 2;
    return bestd <= limit ? best : NULL;
}

static gr_status unknown_key(vctx *c, const char *path, const char *key, const char *const *names, size_t n)
{
    const char *s = suggest(key, names, n);
    if (s) return vfail(c, path, "unknown key, did you mean '%s'?", s);
    char list[512];
    size_t used = 0;
    list[0] = '\0';
    for (size_t i = 0; i < n; i++) {
        int w = snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", names[i]);
        if (w < 0 || (size_t)w >= sizeof list - used) break;
        used += (size_t)w;
    }
    return vfail(c, path, "unknown key (known keys: %s)", list);
}

/* Requires obj to be an object whose keys are all in names and appear once. */
static gr_status check_keys(vctx *c, const cJSON *obj, const char *path, const char *const *names, size_t n)
{
    char p[320];
    for (const cJSON *it = obj->child; it; it = it->next) {
        join(p, sizeof p, path, it->string ? it->string : "");
        size_t i = 0;
        while (i < n && strcmp(names[i], it->string ? it->string : "")) i++;
        if (i == n) return unknown_key(c, p, it->string ? it->string : "", names, n);
        for (const cJSON *prev = obj->child; prev != it; prev = prev->next)
            if (!strcmp(prev->string, it->string)) return vfail(c, p, "duplicate key");
    }
    return GR_OK;
}

static gr_status want_object(vctx *c, const cJSON *v, const char *path)
{
    char got[80];
    if (!cJSON_IsObject(v)) return vfail(c, path, "must be an object, got %s", got_text(v, got, sizeof got));
    return GR_OK;
}

static gr_status number_value(vctx *c, const cJSON *v, const char *path, double *out)
{
    char got[80];
    if (!cJSON_IsNumber(v))
        return vfail(c, path, "must be a number, got %s %s", gr_json_type_name(v), got_text(v, got, sizeof got));
    if (!isfinite(v->valuedouble))
        return vfail(c, path, "must be a finite number, got %s", got_text(v, got, sizeof got));
    *out = v->valuedouble;
    return GR_OK;
}

/* Optional number; absent keeps *out (the caller put the default there). */
static gr_status get_num(vctx *c, const cJSON *obj, const char *parent, const char *key, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[320];
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    return number_value(c, v, p, out);
}

static gr_status get_int(vctx *c, const cJSON *obj, const char *parent, const char *key, int lo, int hi, int *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[320], got[80];
    double d = 0; /* set by number_value on success (GCC cannot always see it) */
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    gr_status st = number_value(c, v, p, &d);
    if (st) return st;
    if (d != floor(d)) return vfail(c, p, "must be an integer, got %s", got_text(v, got, sizeof got));
    if (d < lo || d > hi) return vfail(c, p, "must be in [%d, %d], got %s", lo, hi, got_text(v, got, sizeof got));
    *out = (int)d;
    return GR_OK;
}

/* The three numbers of an array already checked to hold three items; out is written only
 * when all three are finite numbers. */
static gr_status three_numbers(vctx *c, const cJSON *v, const char *p, double out[3])
{
    char pe[340];
    double tmp[3];
    for (int i = 0; i < 3; i++) {
        snprintf(pe, sizeof pe, "%s[%d]", p, i);
        gr_status st = number_value(c, cJSON_GetArrayItem(v, i), pe, &tmp[i]);
        if (st) return st;
    }
    memcpy(out, tmp, sizeof tmp);
    return GR_OK;
}

/* [x, y, z]: exactly three finite numbers. */
static gr_status get_vec3(vctx *c, const cJSON *obj, const char *parent, const char *key, double out[3])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[320], got[80];
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return vfail(c, p, "must be an array of 3 numbers, got %s", got_text(v, got, sizeof got));
    return three_numbers(c, v, p, out);
}

/* RGB: [r, g, b] or one number for all three channels. */
static gr_status rgb_value(vctx *c, const cJSON *v, const char *p, double out[3])
{
    char got[80];
    if (cJSON_IsNumber(v)) {
        double d;
        gr_status st = number_value(c, v, p, &d);
        if (st) return st;
        out[0] = out[1] = out[2] = d;
        return GR_OK;
    }
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return vfail(c, p, "must be [r, g, b] or one number, got %s", got_text(v, got, sizeof got));
    return three_numbers(c, v, p, out);
}

static gr_status get_rgb(vctx *c, const cJSON *obj, const char *parent, const char *key, double out[3])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[320];
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    return rgb_value(c, v, p, out);
}

static gr_status get_str(vctx *c, const cJSON *obj, const char *parent, const char *key, char *out, size_t cap)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[320], got[80];
    if (!v) return GR_OK;
    join(p, sizeof p, parent, key);
    if (!cJSON_IsString(v) || !v->valuestring)
        return vfail(c, p, "must be a string, got %s", got_text(v, got, sizeof got));
    if (strlen(v->valuestring) >= cap)
        return vfail(c, p, "too long (at most %zu bytes), got %zu bytes", cap - 1, strlen(v->valuestring));
    snprintf(out, cap, "%s", v->valuestring);
    return GR_OK;
}

/* Names reach the terminal, JSON and HTML: control characters (C0, DEL, C1) and bytes that are
 * not well-formed UTF-8 (RFC 3629: no overlongs, no surrogates, at most U+10FFFF) become '?'
 * in place, so an escape sequence in a name cannot drive a terminal and every output stays
 * valid UTF-8 for strict parsers. */
static void sanitize_name(char *s)
{
    unsigned char *p = (unsigned char *)s;
    while (*p) {
        const unsigned c = p[0];
        int n = c < 0x80 ? 1 : (c >= 0xc2 && c <= 0xdf) ? 2 : (c >= 0xe0 && c <= 0xef) ? 3 : (c >= 0xf0 && c <= 0xf4) ? 4 : 0;
        unsigned cp = n == 1 ? c : n == 2 ? (c & 0x1f) : n == 3 ? (c & 0x0f) : (c & 0x07);
        for (int k = 1; k < n; k++) {
            if ((p[k] & 0xc0) != 0x80) { n = 0; break; }
            cp = (cp << 6) | (p[k] & 0x3fu);
        }
        if (n == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) n = 0;
        if (n == 4 && (cp < 0x10000 || cp > 0x10ffff)) n = 0;
        if (n == 0 || cp < 0x20 || cp == 0x7f || (cp >= 0x80 && cp <= 0x9f)) {
            if (n == 0) n = 1;
            for (int k = 0; k < n; k++) p[k] = '?';
        }
        p += n;
    }
}

/* Range check with the same wording as the settings tables ("must be in (0, 180), got 190"). */
static gr_status range(vctx *c, const char *path, double v, double lo, double hi, unsigned flags)
{
    gr_param p = {.name = "", .type = GR_PT_DOUBLE, .min = lo, .max = hi, .flags = flags};
    char r[96], got[40];
    int lo_ok = (flags & GR_PF_MIN_EXCL) ? v > lo : v >= lo;
    int hi_ok = (flags & GR_PF_MAX_EXCL) ? v < hi : v <= hi;
    if (isfinite(v) && lo_ok && hi_ok) return GR_OK;
    if (!isfinite(v)) return vfail(c, path, "must be a finite number, got %s", gr_format_double(v, got, sizeof got));
    return vfail(c, path, "must be %s%s, got %s", (isinf(lo) || isinf(hi)) ? "" : "in ",
                 gr_param_range_text(&p, r, sizeof r), gr_format_double(v, got, sizeof got));
}

/* ---- defaults ------------------------------------------------------------------------ */
static void set_defaults(gr_scene *s)
{
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "default");
    s->water.rest_height_m = 0.0;
    s->water.time_s = 0.0;
    s->sun.elevation_deg = 60.0;
    s->sun.azimuth_deg = 0.0;
    s->sun.irradiance[0] = s->sun.irradiance[1] = s->sun.irradiance[2] = 1.0;
    s->sun.angular_diameter_deg = 0.53;
    memcpy(s->medium.absorption, default_absorption, sizeof default_absorption);
    memcpy(s->medium.scattering, default_scattering, sizeof default_scattering);
    s->medium.g = default_g;
    s->medium.ior = 1.333;
    s->camera.position_m[1] = -8.0;
    s->camera.yaw_deg = 0.0;
    s->camera.pitch_deg = 45.0;
    s->camera.fov_deg = 60.0;
    s->camera.width = 640;
    s->camera.height = 360;
    s->has_seabed = 0;
    s->seabed_depth_m = 25.0;
    gr_param_defaults(&gr_reference_param_table, &s->reference);
    /* technique sections: every one known now (scene/sections.h), at its defaults */
    s->n_sections = gr_sections_count();
    for (int i = 0; i < s->n_sections; i++) gr_param_defaults(gr_sections_table(i), s->sections[i].bytes);
}

static void wave_defaults(gr_wave *w)
{
    memset(w, 0, sizeof *w);
    w->amplitude_m = 0.1;
    w->wavelength_m = 8.0;
    w->direction_deg = 0.0;
    w->phase_rad = 0.0;
    w->omega_rad_s = NAN; /* NaN = derive from deep-water dispersion */
}

/* ---- JSON -> struct ------------------------------------------------------------------ */
/* The format's own top-level keys; technique sections (scene/sections.h) come on top. */
static const char *const root_keys[] = {"version", "name", "water", "sun", "medium", "camera",
                                        "occluders", "seabed", "reference"};
static const char *const water_keys[] = {"rest_height_m", "time_s", "waves"};
static const char *const wave_keys[] = {"amplitude_m", "wavelength_m", "direction_deg", "phase_rad",
                                        "angular_frequency_rad_s"};
static const char *const sun_keys[] = {"elevation_deg", "azimuth_deg", "irradiance", "angular_diameter_deg"};
static const char *const medium_keys[] = {"preset", "absorption_per_m", "scattering_per_m", "g", "ior"};
static const char *const camera_keys[] = {"position_m", "look_at_m", "yaw_deg", "pitch_deg", "fov_deg",
                                          "width", "height"};
static const char *const box_keys[] = {"type", "name", "center_m", "size_m", "yaw_deg"};
static const char *const sphere_keys[] = {"type", "name", "center_m", "radius_m"};
static const char *const seabed_keys[] = {"depth_m"};
#define NKEYS(a) (sizeof(a) / sizeof((a)[0]))

/* The root's keys: the format's own and every technique section known now. An unknown key
 * may be a user technique's section whose folder was not given: the message says so. */
static gr_status check_root_keys(vctx *c, const cJSON *root)
{
    const char *names[NKEYS(root_keys) + GR_SCENE_MAX_SECTIONS];
    size_t n = 0;
    for (size_t i = 0; i < NKEYS(root_keys); i++) names[n++] = root_keys[i];
    for (int i = 0; i < gr_sections_count(); i++) names[n++] = gr_sections_table(i)->section;
    gr_status st = check_keys(c, root, "", names, n);
    if (st == GR_E_INPUT && strstr(c->err->msg, "unknown key"))
        snprintf(c->err->msg + strlen(c->err->msg), sizeof c->err->msg - strlen(c->err->msg), "%s",
                 "; a user technique's section needs its --technique-dir");
    return st;
}

/* Every technique section's settings against its table (allow_unresolved: NaN accepted
 * for scene-derived settings). */
static gr_status validate_sections(const gr_scene *s, int allow_unresolved, gr_error *err)
{
    for (int i = 0; i < s->n_sections; i++) {
        gr_status st = gr_param_validate(gr_sections_table(i), s->sections[i].bytes, allow_unresolved, err);
        if (st) return st;
    }
    return GR_OK;
}

static gr_status parse_water(vctx *c, const cJSON *w, gr_water *out)
{
    gr_status st;
    if ((st = want_object(c, w, "water")) || (st = check_keys(c, w, "water", water_keys, NKEYS(water_keys))) ||
        (st = get_num(c, w, "water", "rest_height_m", &out->rest_height_m)) ||
        (st = get_num(c, w, "water", "time_s", &out->time_s)))
        return st;
    const cJSON *waves = cJSON_GetObjectItemCaseSensitive(w, "waves");
    if (!waves) return GR_OK;
    char got[80], p[64];
    if (!cJSON_IsArray(waves))
        return vfail(c, "water.waves", "must be an array of wave objects, got %s", got_text(waves, got, sizeof got));
    int n = cJSON_GetArraySize(waves);
    if (n > GR_MAX_WAVES) return vfail(c, "water.waves", "too many waves (at most %d), got %d", GR_MAX_WAVES, n);
    int i = 0;
    for (const cJSON *it = waves->child; it; it = it->next, i++) {
        gr_wave *wv = &out->waves[i];
        wave_defaults(wv);
        snprintf(p, sizeof p, "water.waves[%d]", i);
        if ((st = want_object(c, it, p)) || (st = check_keys(c, it, p, wave_keys, NKEYS(wave_keys))) ||
            (st = get_num(c, it, p, "amplitude_m", &wv->amplitude_m)) ||
            (st = get_num(c, it, p, "wavelength_m", &wv->wavelength_m)) ||
            (st = get_num(c, it, p, "direction_deg", &wv->direction_deg)) ||
            (st = get_num(c, it, p, "phase_rad", &wv->phase_rad)) ||
            (st = get_num(c, it, p, "angular_frequency_rad_s", &wv->omega_rad_s)))
            return st;
    }
    out->n_waves = n;
    return GR_OK;
}

static gr_status parse_sun(vctx *c, const cJSON *v, gr_sun *out)
{
    gr_status st;
    if ((st = want_object(c, v, "sun")) || (st = check_keys(c, v, "sun", sun_keys, NKEYS(sun_keys))) ||
        (st = get_num(c, v, "sun", "elevation_deg", &out->elevation_deg)) ||
        (st = get_num(c, v, "sun", "azimuth_deg", &out->azimuth_deg)) ||
        (st = get_rgb(c, v, "sun", "irradiance", out->irradiance)) ||
        (st = get_num(c, v, "sun", "angular_diameter_deg", &out->angular_diameter_deg)))
        return st;
    return GR_OK;
}

static gr_status parse_medium(vctx *c, const cJSON *v, gr_medium *out)
{
    gr_status st;
    if ((st = want_object(c, v, "medium")) || (st = check_keys(c, v, "medium", medium_keys, NKEYS(medium_keys))) ||
        (st = get_str(c, v, "medium", "preset", out->preset, sizeof out->preset)))
        return st;
    if (out->preset[0]) {
        /* A preset replaces the default coefficients; explicit keys below override it per key. */
        int i = 0;
        while (i < n_presets && strcmp(presets[i].name, out->preset)) i++;
        if (i == n_presets) {
            char list[256] = "";
            size_t used = 0;
            for (int k = 0; k < n_presets; k++) {
                int w = snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", presets[k].name);
                if (w < 0 || (size_t)w >= sizeof list - used) break;
                used += (size_t)w;
            }
            return vfail(c, "medium.preset", "unknown preset (known: %s), got \"%s\"", list, out->preset);
        }
        memcpy(out->absorption, presets[i].absorption, sizeof out->absorption);
        memcpy(out->scattering, presets[i].scattering, sizeof out->scattering);
        out->g = presets[i].g;
    }
    if ((st = get_rgb(c, v, "medium", "absorption_per_m", out->absorption)) ||
        (st = get_rgb(c, v, "medium", "scattering_per_m", out->scattering)) ||
        (st = get_num(c, v, "medium", "g", &out->g)) || (st = get_num(c, v, "medium", "ior", &out->ior)))
        return st;
    return GR_OK;
}

static gr_status parse_camera(vctx *c, const cJSON *v, gr_camera *out)
{
    gr_status st;
    if ((st = want_object(c, v, "camera")) || (st = check_keys(c, v, "camera", camera_keys, NKEYS(camera_keys))))
        return st;
    int has_look = cJSON_GetObjectItemCaseSensitive(v, "look_at_m") != NULL;
    int has_angles = cJSON_GetObjectItemCaseSensitive(v, "yaw_deg") || cJSON_GetObjectItemCaseSensitive(v, "pitch_deg");
    if (has_look && has_angles)
        return vfail(c, "camera.look_at_m", "give either look_at_m or yaw_deg/pitch_deg, not both");
    out->has_look_at = has_look;
    if ((st = get_vec3(c, v, "camera", "position_m", out->position_m)) ||
        (st = get_vec3(c, v, "camera", "look_at_m", out->look_at_m)) ||
        (st = get_num(c, v, "camera", "yaw_deg", &out->yaw_deg)) ||
        (st = get_num(c, v, "camera", "pitch_deg", &out->pitch_deg)) ||
        (st = get_num(c, v, "camera", "fov_deg", &out->fov_deg)) ||
        (st = get_int(c, v, "camera", "width", 1, GR_MAX_IMAGE_SIDE, &out->width)) ||
        (st = get_int(c, v, "camera", "height", 1, GR_MAX_IMAGE_SIDE, &out->height)))
        return st;
    return GR_OK;
}

static gr_status parse_occluders(vctx *c, const cJSON *v, gr_scene *s)
{
    char got[80], p[64], pt[80];
    gr_status st;
    if (!cJSON_IsArray(v))
        return vfail(c, "occluders", "must be an array of occluder objects, got %s", got_text(v, got, sizeof got));
    int n = cJSON_GetArraySize(v);
    if (n > GR_MAX_OCCLUDERS) return vfail(c, "occluders", "too many occluders (at most %d), got %d", GR_MAX_OCCLUDERS, n);
    int i = 0;
    for (const cJSON *it = v->child; it; it = it->next, i++) {
        gr_occluder *o = &s->occluders[i];
        memset(o, 0, sizeof *o);
        snprintf(p, sizeof p, "occluders[%d]", i);
        snprintf(pt, sizeof pt, "%s.type", p);
        if ((st = want_object(c, it, p))) return st;
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(it, "type");
        if (!type) return vfail(c, pt, "missing, expected \"box\" or \"sphere\"");
        if (!cJSON_IsString(type))
            return vfail(c, pt, "must be \"box\" or \"sphere\", got %s", got_text(type, got, sizeof got));
        if (!strcmp(type->valuestring, "box")) {
            o->type = GR_OCC_BOX;
            o->size_m[0] = o->size_m[1] = o->size_m[2] = 1.0;
            if ((st = check_keys(c, it, p, box_keys, NKEYS(box_keys))) ||
                (st = get_vec3(c, it, p, "size_m", o->size_m)) || (st = get_num(c, it, p, "yaw_deg", &o->yaw_deg)))
                return st;
        } else if (!strcmp(type->valuestring, "sphere")) {
            o->type = GR_OCC_SPHERE;
            o->radius_m = 1.0;
            if ((st = check_keys(c, it, p, sphere_keys, NKEYS(sphere_keys))) ||
                (st = get_num(c, it, p, "radius_m", &o->radius_m)))
                return st;
        } else {
            return vfail(c, pt, "unknown occluder type, expected \"box\" or \"sphere\", got %s",
                         got_text(type, got, sizeof got));
        }
        if ((st = get_str(c, it, p, "name", o->name, sizeof o->name)) ||
            (st = get_vec3(c, it, p, "center_m", o->center_m)))
            return st;
        sanitize_name(o->name);
    }
    s->n_occluders = n;
    return GR_OK;
}

static gr_status parse_section(vctx *c, const cJSON *v, const gr_param_table *t, void *settings)
{
    char p[320], got[80];
    gr_status st;
    if ((st = want_object(c, v, t->section))) return st;
    const char *names[64];
    size_t nn = t->count < 64 ? t->count : 64;
    for (size_t i = 0; i < nn; i++) names[i] = t->params[i].name;
    if ((st = check_keys(c, v, t->section, names, nn))) return st;
    for (const cJSON *it = v->child; it; it = it->next) {
        const gr_param *prm = gr_param_find(t, it->string);
        join(p, sizeof p, t->section, it->string);
        snprintf(c->path, sizeof c->path, "%s", p);
        switch (prm->type) {
        case GR_PT_BOOL:
            if (!cJSON_IsBool(it)) return vfail(c, p, "must be true or false, got %s", got_text(it, got, sizeof got));
            st = gr_param_set_number(t, settings, prm->name, -1, cJSON_IsTrue(it) ? 1.0 : 0.0, c->err);
            break;
        case GR_PT_ENUM: {
            if (!cJSON_IsString(it)) {
                char r[160];
                return vfail(c, p, "must be one of %s (a string), got %s", gr_param_range_text(prm, r, sizeof r),
                             got_text(it, got, sizeof got));
            }
            st = gr_param_set_enum(t, settings, prm->name, it->valuestring, c->err);
            break;
        }
        case GR_PT_RGB: {
            double rgb[3];
            if ((st = rgb_value(c, it, p, rgb))) return st;
            for (int ch = 0; ch < 3 && !st; ch++)
                st = gr_param_set_number(t, settings, prm->name, cJSON_IsNumber(it) ? -1 : ch, rgb[ch], c->err);
            break;
        }
        case GR_PT_DOUBLE:
        case GR_PT_INT:
        case GR_PT_U64: {
            double d;
            if ((st = number_value(c, it, p, &d))) return st;
            st = gr_param_set_number(t, settings, prm->name, -1, d, c->err);
            break;
        }
        }
        if (st) return st; /* message already "section.key: reason, got V"; c->path set above */
    }
    return GR_OK;
}

static gr_status parse_scene(vctx *c, const cJSON *root, gr_scene *s)
{
    gr_status st;
    char got[80];
    set_defaults(s);
    if ((st = want_object(c, root, ""))) return st;
    if ((st = check_root_keys(c, root))) return st;
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (ver && (!cJSON_IsNumber(ver) || ver->valuedouble != 1.0))
        return vfail(c, "version", "unsupported scene format version, expected 1, got %s", got_text(ver, got, sizeof got));
    if ((st = get_str(c, root, "", "name", s->name, sizeof s->name))) return st;
    sanitize_name(s->name);
    const cJSON *v;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "water")) && (st = parse_water(c, v, &s->water))) return st;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "sun")) && (st = parse_sun(c, v, &s->sun))) return st;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "medium")) && (st = parse_medium(c, v, &s->medium))) return st;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "camera")) && (st = parse_camera(c, v, &s->camera))) return st;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "occluders")) && (st = parse_occluders(c, v, s))) return st;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "seabed")) && !cJSON_IsNull(v)) {
        /* absent or null: no seabed */
        if ((st = want_object(c, v, "seabed")) || (st = check_keys(c, v, "seabed", seabed_keys, NKEYS(seabed_keys))) ||
            (st = get_num(c, v, "seabed", "depth_m", &s->seabed_depth_m)))
            return st;
        s->has_seabed = 1;
    }
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "reference")) &&
        (st = parse_section(c, v, &gr_reference_param_table, &s->reference)))
        return st;
    for (int i = 0; i < s->n_sections; i++) {
        const gr_param_table *t = gr_sections_table(i);
        if ((v = cJSON_GetObjectItemCaseSensitive(root, t->section)) &&
            (st = parse_section(c, v, t, s->sections[i].bytes)))
            return st;
    }
    return GR_OK;
}

/* ---- validation and derived fields ---------------------------------------------------- */
enum { LO_X = GR_PF_MIN_EXCL, HI_X = GR_PF_MAX_EXCL };

/* Field ranges that need no other field. NaN omega / FROM_SCENE settings are "derive me". */
static gr_status validate_fields(vctx *c, const gr_scene *s)
{
    char p[96];
    gr_status st;
    const double inf = INFINITY;
    if ((st = range(c, "water.rest_height_m", s->water.rest_height_m, -GR_MAX_COORD_M, GR_MAX_COORD_M, 0)) ||
        (st = range(c, "water.time_s", s->water.time_s, -inf, inf, 0)))
        return st;
    if (s->water.n_waves < 0 || s->water.n_waves > GR_MAX_WAVES)
        return vfail(c, "water.waves", "too many waves (at most %d), got %d", GR_MAX_WAVES, s->water.n_waves);
    for (int i = 0; i < s->water.n_waves; i++) {
        const gr_wave *w = &s->water.waves[i];
        snprintf(p, sizeof p, "water.waves[%d].amplitude_m", i);
        if ((st = range(c, p, w->amplitude_m, 0, inf, 0))) return st;
        snprintf(p, sizeof p, "water.waves[%d].wavelength_m", i);
        if ((st = range(c, p, w->wavelength_m, 0, 1e6, LO_X))) return st;
        snprintf(p, sizeof p, "water.waves[%d].direction_deg", i);
        if ((st = range(c, p, w->direction_deg, -inf, inf, 0))) return st;
        snprintf(p, sizeof p, "water.waves[%d].phase_rad", i);
        if ((st = range(c, p, w->phase_rad, -inf, inf, 0))) return st;
        snprintf(p, sizeof p, "water.waves[%d].angular_frequency_rad_s", i);
        if (!isnan(w->omega_rad_s) && (st = range(c, p, w->omega_rad_s, 0, inf, 0))) return st;
    }
    if ((st = range(c, "sun.elevation_deg", s->sun.elevation_deg, 0, 90, LO_X)) ||
        (st = range(c, "sun.azimuth_deg", s->sun.azimuth_deg, -inf, inf, 0)) ||
        (st = range(c, "sun.angular_diameter_deg", s->sun.angular_diameter_deg, 0, 10, 0)))
        return st;
    for (int k = 0; k < 3; k++) {
        snprintf(p, sizeof p, "sun.irradiance[%d]", k);
        if ((st = range(c, p, s->sun.irradiance[k], 0, inf, 0))) return st;
        snprintf(p, sizeof p, "medium.absorption_per_m[%d]", k);
        if ((st = range(c, p, s->medium.absorption[k], 0, 1000, 0))) return st;
        snprintf(p, sizeof p, "medium.scattering_per_m[%d]", k);
        if ((st = range(c, p, s->medium.scattering[k], 0, 1000, 0))) return st;
    }
    if ((st = range(c, "medium.g", s->medium.g, -1, 1, LO_X | HI_X)) ||
        (st = range(c, "medium.ior", s->medium.ior, 1, 3, 0)))
        return st;
    const gr_camera *cam = &s->camera;
    for (int k = 0; k < 3; k++) {
        snprintf(p, sizeof p, "camera.position_m[%d]", k);
        if ((st = range(c, p, cam->position_m[k], -GR_MAX_COORD_M, GR_MAX_COORD_M, 0))) return st;
        if (cam->has_look_at) {
            snprintf(p, sizeof p, "camera.look_at_m[%d]", k);
            if ((st = range(c, p, cam->look_at_m[k], -GR_MAX_COORD_M, GR_MAX_COORD_M, 0))) return st;
        }
    }
    if (!cam->has_look_at && ((st = range(c, "camera.yaw_deg", cam->yaw_deg, -inf, inf, 0)) ||
                              (st = range(c, "camera.pitch_deg", cam->pitch_deg, -90, 90, 0))))
        return st;
    if ((st = range(c, "camera.fov_deg", cam->fov_deg, 0, 180, LO_X | HI_X)) ||
        (st = range(c, "camera.width", cam->width, 1, GR_MAX_IMAGE_SIDE, 0)) ||
        (st = range(c, "camera.height", cam->height, 1, GR_MAX_IMAGE_SIDE, 0)))
        return st;
    if (s->n_occluders < 0 || s->n_occluders > GR_MAX_OCCLUDERS)
        return vfail(c, "occluders", "too many occluders (at most %d), got %d", GR_MAX_OCCLUDERS, s->n_occluders);
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *o = &s->occluders[i];
        for (int k = 0; k < 3; k++) {
            snprintf(p, sizeof p, "occluders[%d].center_m[%d]", i, k);
            if ((st = range(c, p, o->center_m[k], -GR_MAX_COORD_M, GR_MAX_COORD_M, 0))) return st;
        }
        if (o->type == GR_OCC_BOX) {
            for (int k = 0; k < 3; k++) {
                snprintf(p, sizeof p, "occluders[%d].size_m[%d]", i, k);
                if ((st = range(c, p, o->size_m[k], 0, 1e6, LO_X))) return st;
            }
            snprintf(p, sizeof p, "occluders[%d].yaw_deg", i);
            if ((st = range(c, p, o->yaw_deg, -inf, inf, 0))) return st;
        } else if (o->type == GR_OCC_SPHERE) {
            snprintf(p, sizeof p, "occluders[%d].radius_m", i);
            if ((st = range(c, p, o->radius_m, 0, 1e6, LO_X))) return st;
        } else {
            snprintf(p, sizeof p, "occluders[%d].type", i);
            return vfail(c, p, "unknown occluder type, got %d", (int)o->type);
        }
    }
    if (s->has_seabed && (st = range(c, "seabed.depth_m", s->seabed_depth_m, 0, 1e5, LO_X))) return st;
    /* Renderer sections: the descriptor tables hold the ranges. */
    if (gr_param_validate(&gr_reference_param_table, &s->reference, 1, c->err) ||
        validate_sections(s, 1, c->err)) {
        /* the message starts with "section.key"; use it as the path */
        size_t n = strcspn(c->err->msg, ":");
        snprintf(c->path, sizeof c->path, "%.*s", (int)(n < sizeof c->path ? n : sizeof c->path - 1), c->err->msg);
        return GR_E_INPUT;
    }
    return GR_OK;
}

/* A scene quantity a FROM_SCENE setting defaults to (gr_param.scene_source). */
static double scene_source_value(const gr_scene *s, const char *src, int channel)
{
    int ch = channel < 0 ? 0 : channel;
    if (!src) return NAN;
    if (!strcmp(src, "medium.extinction")) return s->medium.extinction[ch];
    if (!strcmp(src, "medium.g")) return s->medium.g;
    if (!strcmp(src, "medium.absorption")) return s->medium.absorption[ch];
    if (!strcmp(src, "medium.scattering")) return s->medium.scattering[ch];
    if (!strcmp(src, "medium.ior")) return s->medium.ior;
    if (!strcmp(src, "camera.position_m")) return s->camera.position_m[ch];
    return NAN;
}

static void resolve_from_scene(const gr_param_table *t, void *settings, const gr_scene *s)
{
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        if (!(p->flags & GR_PF_FROM_SCENE)) continue;
        int nch = p->type == GR_PT_RGB ? 3 : 1;
        for (int ch = 0; ch < nch; ch++) {
            if (!isnan(gr_param_get_number(p, settings, ch))) continue;
            double v = scene_source_value(s, p->scene_source, ch);
            double *dst = (double *)(void *)((char *)settings + p->offset);
            if (p->type == GR_PT_RGB) dst[ch] = v;
            else if (p->type == GR_PT_DOUBLE) *dst = v;
        }
    }
}

/* Unit vector of an azimuth (from +z toward +x) and an elevation above the horizon. */
static void direction(double azimuth_deg, double elevation_deg, double out[3])
{
    double a = azimuth_deg * DEG2RAD, e = elevation_deg * DEG2RAD;
    out[0] = cos(e) * sin(a);
    out[1] = sin(e);
    out[2] = cos(e) * cos(a);
}

static gr_status derive(vctx *c, gr_scene *s)
{
    for (int i = 0; i < s->water.n_waves; i++) {
        gr_wave *w = &s->water.waves[i];
        w->k = 2.0 * 3.14159265358979323846 / w->wavelength_m;
        double a = w->direction_deg * DEG2RAD;
        w->dir[0] = sin(a);
        w->dir[1] = cos(a);
        /* deep-water dispersion of linear waves, w^2 = g k (e.g. Tessendorf 2001, "Simulating
         * Ocean Water"), unless given */
        if (isnan(w->omega_rad_s)) w->omega_rad_s = sqrt(GR_GRAVITY * w->k);
    }
    /* sun.to_sun = (cos el sin az, sin el, cos el cos az); light travels along -to_sun */
    direction(s->sun.azimuth_deg, s->sun.elevation_deg, s->sun.to_sun);
    for (int k = 0; k < 3; k++) {
        s->sun.dir[k] = -s->sun.to_sun[k];
        s->medium.extinction[k] = s->medium.absorption[k] + s->medium.scattering[k];
    }
    gr_camera *cam = &s->camera;
    double f[3];
    if (cam->has_look_at) {
        double d[3], len = 0.0;
        for (int k = 0; k < 3; k++) { d[k] = cam->look_at_m[k] - cam->position_m[k]; len += d[k] * d[k]; }
        len = sqrt(len);
        if (!(len > 0.0) || !isfinite(len))
            return vfail(c, "camera.look_at_m", "must differ from camera.position_m, got the same point");
        for (int k = 0; k < 3; k++) f[k] = d[k] / len;
        /* yaw/pitch are derived in this mode (yaw 0 when looking straight up or down) */
        double h = sqrt(f[0] * f[0] + f[2] * f[2]);
        cam->yaw_deg = h > 0.0 ? atan2(f[0], f[2]) * RAD2DEG : 0.0;
        cam->pitch_deg = atan2(f[1], h) * RAD2DEG;
    } else {
        direction(cam->yaw_deg, cam->pitch_deg, f);
        /* look_at is derived in this mode: the point 1 m ahead */
        for (int k = 0; k < 3; k++) cam->look_at_m[k] = cam->position_m[k] + f[k];
    }
    /* right = normalize(cross(forward, +y)) = (-f.z, 0, f.x) / |.|; looking straight up or
     * down it is the limit of that expression for the camera's yaw: (-cos yaw, 0, sin yaw). */
    double r[3] = {-f[2], 0.0, f[0]}, rl = sqrt(r[0] * r[0] + r[2] * r[2]);
    if (rl > 1e-12) {
        r[0] /= rl;
        r[2] /= rl;
    } else {
        double y = cam->yaw_deg * DEG2RAD;
        r[0] = -cos(y);
        r[2] = sin(y);
    }
    /* up = cross(right, forward): completes a right-handed frame (right, up, -forward) */
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    for (int k = 0; k < 3; k++) {
        cam->forward[k] = f[k];
        cam->right[k] = r[k];
        cam->up[k] = u[k];
    }
    for (int i = 0; i < s->n_sections; i++) resolve_from_scene(gr_sections_table(i), s->sections[i].bytes, s);
    resolve_from_scene(&gr_reference_param_table, &s->reference, s);
    return GR_OK;
}

/* Checks that need several fields (after derive). */
static gr_status validate_cross(vctx *c, const gr_scene *s)
{
    char a[40], b[40], d[40];
    /* FROM_SCENE settings now hold scene values: they too must lie in the table's range */
    if (gr_param_validate(&gr_reference_param_table, &s->reference, 0, c->err) ||
        validate_sections(s, 0, c->err)) {
        size_t n = strcspn(c->err->msg, ":");
        snprintf(c->path, sizeof c->path, "%.*s", (int)(n < sizeof c->path ? n : sizeof c->path - 1), c->err->msg);
        return GR_E_INPUT;
    }
    const gr_water *w = &s->water;
    double steep = gr_gerstner_steepness(w);
    if (!(steep < 1.0))
        return vfail(c, "water.waves", "steepness sum(a k) must be < 1 or the surface loops, got %s",
                     gr_format_double(steep, a, sizeof a));
    const double *cp = s->camera.position_m;
    double surf = w->rest_height_m;
    if (w->n_waves > 0) {
        double h;
        if (gr_gerstner_height_at(w, cp[0], cp[2], w->time_s, &h, NULL, NULL) != 0)
            return vfail(c, "camera.position_m", "could not find the water surface height above the camera");
        surf = h;
    }
    /* the camera must be under water: strictly below the displaced surface at its (x, z) */
    if (!(cp[1] < surf))
        return vfail(c, "camera.position_m", "camera is not under water (surface at y = %s m), got y = %s",
                     gr_format_double(surf, a, sizeof a), gr_format_double(cp[1], b, sizeof b));
    if (s->has_seabed) {
        double bed = w->rest_height_m - s->seabed_depth_m;
        if (!(bed < cp[1]))
            return vfail(c, "seabed.depth_m", "seabed (y = %s m) must be below the camera (y = %s m), got %s",
                         gr_format_double(bed, a, sizeof a), gr_format_double(cp[1], b, sizeof b),
                         gr_format_double(s->seabed_depth_m, d, sizeof d));
        double troughs = 0.0;
        for (int i = 0; i < w->n_waves; i++) troughs += w->waves[i].amplitude_m;
        if (!(s->seabed_depth_m > troughs))
            return vfail(c, "seabed.depth_m", "seabed must lie below the deepest wave trough (%s m), got %s",
                         gr_format_double(troughs, a, sizeof a), gr_format_double(s->seabed_depth_m, d, sizeof d));
    }
    return GR_OK;
}

/* ---- normalized JSON ------------------------------------------------------------------ */
typedef struct sbuf {
    char *p;
    size_t len, cap;
    int oom;
} sbuf;

static void sb_putn(sbuf *b, const char *s, size_t n)
{
    if (b->oom) return;
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (b->len + n + 1 > cap) cap *= 2;
        char *q = realloc(b->p, cap);
        if (!q) { b->oom = 1; return; }
        b->p = q;
        b->cap = cap;
    }
    memcpy(b->p + b->len, s, n);
    b->len += n;
    b->p[b->len] = '\0';
}
static void sb_puts(sbuf *b, const char *s) { sb_putn(b, s, strlen(s)); }
static void sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(sbuf *b, const char *fmt, ...)
{
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n < 0) { b->oom = 1; return; }
    sb_putn(b, tmp, (size_t)n < sizeof tmp ? (size_t)n : sizeof tmp - 1);
}
static void sb_num(sbuf *b, double v)
{
    char t[40];
    sb_puts(b, gr_format_double(v, t, sizeof t));
}
static void sb_str(sbuf *b, const char *s)
{
    sb_puts(b, "\"");
    for (const unsigned char *q = (const unsigned char *)s; *q; q++) {
        if (*q == '"') sb_puts(b, "\\\"");
        else if (*q == '\\') sb_puts(b, "\\\\");
        else if (*q < 0x20) sb_printf(b, "\\u%04x", *q);
        else sb_putn(b, (const char *)q, 1);
    }
    sb_puts(b, "\"");
}
static void sb_vec(sbuf *b, const double *v)
{
    sb_puts(b, "[");
    sb_num(b, v[0]);
    sb_puts(b, ", ");
    sb_num(b, v[1]);
    sb_puts(b, ", ");
    sb_num(b, v[2]);
    sb_puts(b, "]");
}
/* "key": value, with the indentation and comma handled by the caller */
static void sb_key(sbuf *b, const char *indent, const char *key, int first)
{
    sb_puts(b, first ? "\n" : ",\n");
    sb_puts(b, indent);
    sb_str(b, key);
    sb_puts(b, ": ");
}

static void print_section(sbuf *b, const gr_param_table *t, const void *settings)
{
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        sb_key(b, "    ", p->name, i == 0);
        switch (p->type) {
        case GR_PT_DOUBLE: sb_num(b, gr_param_get_number(p, settings, 0)); break;
        case GR_PT_INT: sb_printf(b, "%d", (int)gr_param_get_number(p, settings, 0)); break;
        case GR_PT_U64:
            sb_printf(b, "%llu", *(const unsigned long long *)(const void *)((const char *)settings + p->offset));
            break;
        case GR_PT_BOOL: sb_puts(b, gr_param_get_number(p, settings, 0) != 0.0 ? "true" : "false"); break;
        case GR_PT_ENUM: {
            const char *nm = gr_param_enum_name(p, (int)gr_param_get_number(p, settings, 0));
            sb_str(b, nm ? nm : "");
            break;
        }
        case GR_PT_RGB: {
            double v[3] = {gr_param_get_number(p, settings, 0), gr_param_get_number(p, settings, 1),
                           gr_param_get_number(p, settings, 2)};
            sb_vec(b, v);
            break;
        }
        }
    }
    if (t->count) sb_puts(b, "\n  ");
}

char *gr_scene_to_json(const gr_scene *s)
{
    if (!s) return NULL;
    sbuf b = {0};
    sb_puts(&b, "{");
    sb_key(&b, "  ", "version", 1);
    sb_puts(&b, "1");
    sb_key(&b, "  ", "name", 0);
    sb_str(&b, s->name);

    sb_key(&b, "  ", "water", 0);
    sb_puts(&b, "{");
    sb_key(&b, "    ", "rest_height_m", 1);
    sb_num(&b, s->water.rest_height_m);
    sb_key(&b, "    ", "time_s", 0);
    sb_num(&b, s->water.time_s);
    sb_key(&b, "    ", "waves", 0);
    sb_puts(&b, "[");
    for (int i = 0; i < s->water.n_waves; i++) {
        const gr_wave *w = &s->water.waves[i];
        sb_puts(&b, i ? ",\n      " : "\n      ");
        sb_puts(&b, "{\"amplitude_m\": ");
        sb_num(&b, w->amplitude_m);
        sb_puts(&b, ", \"wavelength_m\": ");
        sb_num(&b, w->wavelength_m);
        sb_puts(&b, ", \"direction_deg\": ");
        sb_num(&b, w->direction_deg);
        sb_puts(&b, ", \"phase_rad\": ");
        sb_num(&b, w->phase_rad);
        sb_puts(&b, ", \"angular_frequency_rad_s\": ");
        sb_num(&b, w->omega_rad_s);
        sb_puts(&b, "}");
    }
    sb_puts(&b, s->water.n_waves ? "\n    ]\n  }" : "]\n  }");

    sb_key(&b, "  ", "sun", 0);
    sb_puts(&b, "{");
    sb_key(&b, "    ", "elevation_deg", 1);
    sb_num(&b, s->sun.elevation_deg);
    sb_key(&b, "    ", "azimuth_deg", 0);
    sb_num(&b, s->sun.azimuth_deg);
    sb_key(&b, "    ", "irradiance", 0);
    sb_vec(&b, s->sun.irradiance);
    sb_key(&b, "    ", "angular_diameter_deg", 0);
    sb_num(&b, s->sun.angular_diameter_deg);
    sb_puts(&b, "\n  }");

    sb_key(&b, "  ", "medium", 0);
    sb_puts(&b, "{");
    int first = 1;
    if (s->medium.preset[0]) {
        sb_key(&b, "    ", "preset", 1);
        sb_str(&b, s->medium.preset);
        first = 0;
    }
    sb_key(&b, "    ", "absorption_per_m", first);
    sb_vec(&b, s->medium.absorption);
    sb_key(&b, "    ", "scattering_per_m", 0);
    sb_vec(&b, s->medium.scattering);
    sb_key(&b, "    ", "g", 0);
    sb_num(&b, s->medium.g);
    sb_key(&b, "    ", "ior", 0);
    sb_num(&b, s->medium.ior);
    sb_puts(&b, "\n  }");

    const gr_camera *cam = &s->camera;
    sb_key(&b, "  ", "camera", 0);
    sb_puts(&b, "{");
    sb_key(&b, "    ", "position_m", 1);
    sb_vec(&b, cam->position_m);
    if (cam->has_look_at) {
        sb_key(&b, "    ", "look_at_m", 0);
        sb_vec(&b, cam->look_at_m);
    } else {
        sb_key(&b, "    ", "yaw_deg", 0);
        sb_num(&b, cam->yaw_deg);
        sb_key(&b, "    ", "pitch_deg", 0);
        sb_num(&b, cam->pitch_deg);
    }
    sb_key(&b, "    ", "fov_deg", 0);
    sb_num(&b, cam->fov_deg);
    sb_key(&b, "    ", "width", 0);
    sb_printf(&b, "%d", cam->width);
    sb_key(&b, "    ", "height", 0);
    sb_printf(&b, "%d", cam->height);
    sb_puts(&b, "\n  }");

    sb_key(&b, "  ", "occluders", 0);
    sb_puts(&b, "[");
    for (int i = 0; i < s->n_occluders; i++) {
        const gr_occluder *o = &s->occluders[i];
        sb_puts(&b, i ? ",\n    " : "\n    ");
        sb_puts(&b, o->type == GR_OCC_SPHERE ? "{\"type\": \"sphere\", \"name\": " : "{\"type\": \"box\", \"name\": ");
        sb_str(&b, o->name);
        sb_puts(&b, ", \"center_m\": ");
        sb_vec(&b, o->center_m);
        if (o->type == GR_OCC_SPHERE) {
            sb_puts(&b, ", \"radius_m\": ");
            sb_num(&b, o->radius_m);
        } else {
            sb_puts(&b, ", \"size_m\": ");
            sb_vec(&b, o->size_m);
            sb_puts(&b, ", \"yaw_deg\": ");
            sb_num(&b, o->yaw_deg);
        }
        sb_puts(&b, "}");
    }
    sb_puts(&b, s->n_occluders ? "\n  ]" : "]");

    sb_key(&b, "  ", "seabed", 0);
    if (s->has_seabed) {
        sb_puts(&b, "{\"depth_m\": ");
        sb_num(&b, s->seabed_depth_m);
        sb_puts(&b, "}");
    } else {
        sb_puts(&b, "null");
    }

    sb_key(&b, "  ", "reference", 0);
    sb_puts(&b, "{");
    print_section(&b, &gr_reference_param_table, &s->reference);
    sb_puts(&b, "}");
    for (int i = 0; i < s->n_sections; i++) {
        const gr_param_table *t = gr_sections_table(i);
        sb_key(&b, "  ", t->section, 0);
        sb_puts(&b, "{");
        print_section(&b, t, s->sections[i].bytes);
        sb_puts(&b, "}");
    }
    sb_puts(&b, "\n}\n");
    if (b.oom) {
        free(b.p);
        return NULL;
    }
    return b.p;
}

/* FNV-1a 64 (Fowler, Noll, Vo): offset basis 14695981039346656037, prime 1099511628211. */
static uint64_t fnv1a64(const char *s)
{
    uint64_t h = 14695981039346656037ull;
    for (const unsigned char *q = (const unsigned char *)s; *q; q++) {
        h ^= *q;
        h *= 1099511628211ull;
    }
    return h;
}

static gr_status finish(vctx *c, gr_scene *s)
{
    gr_status st;
    if ((st = validate_fields(c, s)) || (st = derive(c, s)) || (st = validate_cross(c, s))) return st;
    char *json = gr_scene_to_json(s);
    if (!json) return gr_fail(c->err, GR_E_NOMEM, "out of memory printing the scene");
    snprintf(s->hash, sizeof s->hash, "%016llx", (unsigned long long)fnv1a64(json));
    free(json);
    return GR_OK;
}

static gr_status refresh_impl(gr_scene *s, gr_error *err)
{
    gr_error local;
    vctx c = {err ? err : &local, ""};
    if (!s) return gr_fail(err, GR_E_RUNTIME, "gr_scene_refresh: no scene");
    gr_status st = finish(&c, s);
    if (st && s->source_path[0]) gr_error_prefix(c.err, "%s", s->source_path);
    return st;
}

/* ---- overrides ------------------------------------------------------------------------ */
typedef struct path_step {
    char key[64]; /* "" for an array index */
    int index;
} path_step;

/* Parses "a.b[2].c" into steps; writes the normalized text to norm. Returns the count or -1. */
static int parse_path(const char *path, path_step *steps, int max, char *norm, size_t nn)
{
    int n = 0;
    const char *q = path;
    size_t used = 0;
    norm[0] = '\0';
    for (;;) {
        size_t len = strcspn(q, ".[");
        if (len == 0 || len >= sizeof steps[0].key || n >= max) return -1;
        memcpy(steps[n].key, q, len);
        steps[n].key[len] = '\0';
        steps[n].index = -1;
        int w = snprintf(norm + used, nn - used, "%s%s", n ? "." : "", steps[n].key);
        if (w < 0 || (size_t)w >= nn - used) return -1;
        used += (size_t)w;
        n++;
        q += len;
        while (*q == '[') {
            char *end;
            errno = 0;
            if (q[1] < '0' || q[1] > '9') return -1;
            long idx = strtol(q + 1, &end, 10);
            if (errno || *end != ']' || idx > 1000000 || n >= max) return -1;
            steps[n].key[0] = '\0';
            steps[n].index = (int)idx;
            w = snprintf(norm + used, nn - used, "[%ld]", idx);
            if (w < 0 || (size_t)w >= nn - used) return -1;
            used += (size_t)w;
            n++;
            q = end + 1;
        }
        if (*q == '\0') return n;
        if (*q != '.') return -1;
        q++;
    }
}

/* Applies one "json.path=value" to the tree. On failure err names the override. */
static gr_status apply_override(cJSON *root, const char *ov, char *norm, size_t nn, gr_error *err)
{
    const char *eq = strchr(ov, '=');
    path_step steps[32];
    char pathtxt[512];
    if (!eq || eq == ov) return gr_fail(err, GR_E_INPUT, "--set %s: expected json.path=value", ov);
    size_t plen = (size_t)(eq - ov);
    if (plen >= sizeof pathtxt) return gr_fail(err, GR_E_INPUT, "--set %s: path too long", ov);
    memcpy(pathtxt, ov, plen);
    pathtxt[plen] = '\0';
    int n = parse_path(pathtxt, steps, 32, norm, nn);
    if (n < 0)
        return gr_fail(err, GR_E_INPUT, "--set %s: bad path '%s' (expected keys joined by '.', e.g. water.waves[0].amplitude_m)",
                       ov, pathtxt);
    const char *vtxt = eq + 1;
    /* The value is JSON if it parses as JSON; a bare word that does not is a string. */
    cJSON *val = cJSON_ParseWithOpts(vtxt, NULL, 1);
    if (!val) {
        size_t lead = strspn(vtxt, " \t");
        if (vtxt[lead] == '[' || vtxt[lead] == '{' || vtxt[lead] == '"')
            return gr_fail(err, GR_E_INPUT, "--set %s: value is not valid JSON", ov);
        val = cJSON_CreateString(vtxt);
        if (!val) return gr_fail(err, GR_E_NOMEM, "--set %s: out of memory", ov);
    }
    cJSON *cur = root;
    char sofar[512] = "";
    for (int i = 0; i < n; i++) {
        int last = i == n - 1;
        const path_step *st = &steps[i];
        if (st->key[0]) {
            if (!cJSON_IsObject(cur)) {
                cJSON_Delete(val);
                return gr_fail(err, GR_E_INPUT, "--set %s: %s: not an object", ov, sofar[0] ? sofar : "(root)");
            }
            cJSON *child = cJSON_GetObjectItemCaseSensitive(cur, st->key);
            if (last) {
                if (child) cJSON_ReplaceItemInObjectCaseSensitive(cur, st->key, val);
                else cJSON_AddItemToObject(cur, st->key, val);
                return GR_OK;
            }
            if (!child) {
                child = steps[i + 1].key[0] ? cJSON_CreateObject() : cJSON_CreateArray();
                if (!child) { cJSON_Delete(val); return gr_fail(err, GR_E_NOMEM, "--set %s: out of memory", ov); }
                cJSON_AddItemToObject(cur, st->key, child);
            }
            size_t l = strlen(sofar);
            snprintf(sofar + l, sizeof sofar - l, "%s%.63s", l ? "." : "", st->key);
            cur = child;
        } else {
            if (!cJSON_IsArray(cur)) {
                cJSON_Delete(val);
                return gr_fail(err, GR_E_INPUT, "--set %s: %s: not an array", ov, sofar[0] ? sofar : "(root)");
            }
            int size = cJSON_GetArraySize(cur);
            if (st->index > size) {
                cJSON_Delete(val);
                return gr_fail(err, GR_E_INPUT, "--set %s: %s[%d]: index out of range (array has %d elements; "
                               "index %d appends)", ov, sofar, st->index, size, size);
            }
            if (last) {
                if (st->index < size) cJSON_ReplaceItemInArray(cur, st->index, val);
                else cJSON_AddItemToArray(cur, val);
                return GR_OK;
            }
            cJSON *child = st->index < size ? cJSON_GetArrayItem(cur, st->index) : NULL;
            if (!child) {
                child = steps[i + 1].key[0] ? cJSON_CreateObject() : cJSON_CreateArray();
                if (!child) { cJSON_Delete(val); return gr_fail(err, GR_E_NOMEM, "--set %s: out of memory", ov); }
                cJSON_AddItemToArray(cur, child);
            }
            size_t l = strlen(sofar);
            snprintf(sofar + l, sizeof sofar - l, "[%d]", st->index);
            cur = child;
        }
    }
    cJSON_Delete(val);
    return GR_OK;
}

/* a is a prefix of b at a path-component boundary ("camera" of "camera.fov_deg") */
static int path_prefix(const char *a, const char *b)
{
    size_t n = strlen(a);
    return !strncmp(a, b, n) && (b[n] == '\0' || b[n] == '.' || b[n] == '[');
}

/* Parses text into a tree; fails with "LABEL:LINE:COL: malformed JSON ..." */
gr_status gr_json_parse(const char *json, const char *label, cJSON **out, gr_error *err)
{
    const char *end = NULL;
    *out = cJSON_ParseWithOpts(json, &end, 1);
    if (*out) return GR_OK;
    if (!end) end = json;
    int line = 1, col = 1;
    for (const char *q = json; q < end && *q; q++) {
        if (*q == '\n') { line++; col = 1; }
        else col++;
    }
    /* cJSON reports where it gave up, often just past the culprit: show both sides. */
    const char *from = end;
    while (from > json && from[-1] != '\n' && end - from < 16) from--;
    while (*from == ' ' || *from == '\t') from++;
    char near[48];
    size_t k = 0;
    for (const char *q = from < end ? from : end; *q && *q != '\n' && *q != '\r' && k < 32; q++) {
        if (q >= end + 12) break;
        near[k++] = *q;
    }
    near[k] = '\0';
    /* cJSON stops at CJSON_NESTING_LIMIT open brackets: say so rather than "malformed" */
    int depth = 0, in_str = 0;
    for (const char *q = json; q < end && *q; q++) {
        if (in_str) {
            if (*q == '\\' && q[1]) q++;
            else if (*q == '"') in_str = 0;
        } else if (*q == '"') {
            in_str = 1;
        } else if (*q == '[' || *q == '{') {
            depth++;
        } else if (*q == ']' || *q == '}') {
            depth--;
        }
    }
    if (depth >= CJSON_NESTING_LIMIT)
        return gr_fail(err, GR_E_INPUT, "%s:%d:%d: JSON nested deeper than %d levels", label, line, col,
                       CJSON_NESTING_LIMIT);
    if (k == 0) return gr_fail(err, GR_E_INPUT, "%s:%d:%d: malformed JSON at end of input", label, line, col);
    return gr_fail(err, GR_E_INPUT, "%s:%d:%d: malformed JSON near '%s'", label, line, col, near);
}

/* Builds the tree of the text with the first n overrides applied, parses and validates it. */
static gr_status load_tree(const char *json, const char *label, const char *const *ov, int n, gr_scene *out,
                           char *errpath, size_t errpath_n, int *override_failed, gr_error *err)
{
    cJSON *root;
    gr_status st = gr_json_parse(json, label, &root, err);
    *override_failed = -1;
    errpath[0] = '\0';
    if (st) return st;
    vctx c = {err, ""};
    if (!cJSON_IsObject(root)) {
        st = want_object(&c, root, "");
        cJSON_Delete(root);
        gr_error_prefix(err, "%s", label);
        return st;
    }
    char norm[512];
    for (int i = 0; i < n; i++) {
        if ((st = apply_override(root, ov[i], norm, sizeof norm, err))) {
            *override_failed = i;
            cJSON_Delete(root);
            return st;
        }
    }
    st = parse_scene(&c, root, out);
    cJSON_Delete(root);
    if (!st) st = finish(&c, out);
    if (st) snprintf(errpath, errpath_n, "%s", c.path);
    return st;
}

static gr_status load_string_impl(const char *json, const char *label, const char *const *overrides,
                                  int n_overrides, gr_scene *out, gr_error *err)
{
    gr_error local;
    if (!err) err = &local;
    if (!label || !label[0]) label = "(string)";
    if (!json || !out) return gr_fail(err, GR_E_RUNTIME, "%s: no scene text or output", label);
    if (n_overrides < 0 || (n_overrides > 0 && !overrides))
        return gr_fail(err, GR_E_RUNTIME, "%s: bad override list", label);
    gr_scene *tmp = malloc(sizeof *tmp);
    if (!tmp) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", label);
    char errpath[256];
    int ovfail;
    gr_status st = load_tree(json, label, overrides, n_overrides, tmp, errpath, sizeof errpath, &ovfail, err);
    if (st == GR_OK) {
        memcpy(out, tmp, sizeof *tmp);
        out->source_path[0] = '\0';
        free(tmp);
        return GR_OK;
    }
    if (ovfail >= 0 || st != GR_E_INPUT || !errpath[0]) {
        /* override syntax errors already name the override; parse errors the file */
        free(tmp);
        return st;
    }
    /* Attribute the error: to the last override whose path covers the failing path ... */
    int culprit = -1;
    char norm[512];
    path_step steps[32];
    for (int i = n_overrides - 1; i >= 0 && culprit < 0; i--) {
        const char *eq = strchr(overrides[i], '=');
        char p[512];
        size_t l = eq ? (size_t)(eq - overrides[i]) : 0;
        if (!eq || l >= sizeof p) continue;
        memcpy(p, overrides[i], l);
        p[l] = '\0';
        if (parse_path(p, steps, 32, norm, sizeof norm) < 0) continue;
        if (path_prefix(norm, errpath) || path_prefix(errpath, norm)) culprit = i;
    }
    /* ... else, if the file alone is valid, to the first override that breaks it. */
    if (culprit < 0 && n_overrides > 0) {
        gr_error e2;
        char p2[256];
        int f2;
        if (load_tree(json, label, overrides, 0, tmp, p2, sizeof p2, &f2, &e2) == GR_OK)
            for (int k = 1; k <= n_overrides && culprit < 0; k++)
                if (load_tree(json, label, overrides, k, tmp, p2, sizeof p2, &f2, &e2) != GR_OK) culprit = k - 1;
    }
    free(tmp);
    if (culprit >= 0) return gr_error_prefix(err, "--set %s", overrides[culprit]);
    return gr_error_prefix(err, "%s", label);
}

/* A JSON file's text (scene, suite, preset): the one reader; see scene.h. */
gr_status gr_json_read_file(const char *path, const char *what, size_t max_bytes, char **out, gr_error *err)
{
    *out = NULL;
    gr_status reg = gr_check_regular_input(path, err); /* a FIFO would block the open */
    if (reg != GR_OK) return reg;
    FILE *f = fopen(path, "rb");
    if (!f) return gr_fail(err, GR_E_IO, "%s: cannot open: %s", path, strerror(errno));
    size_t cap = 1 << 14, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (len + 1 >= cap) {
            if (cap >= max_bytes) {
                free(buf);
                fclose(f);
                return gr_fail(err, GR_E_INPUT, "%s: file too large for a %s (over %zu MiB)", path, what,
                               max_bytes >> 20);
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0) break;
    }
    int rerr = ferror(f) ? errno : 0;
    fclose(f);
    if (rerr) {
        free(buf);
        return gr_fail(err, GR_E_IO, "%s: cannot read: %s", path, strerror(rerr));
    }
    buf[len] = '\0';
    if (memchr(buf, '\0', len)) {
        free(buf);
        return gr_fail(err, GR_E_INPUT, "%s: not a JSON text (contains a NUL byte)", path);
    }
    *out = buf;
    return GR_OK;
}

static gr_status load_file_impl(const char *path, const char *const *overrides, int n_overrides, gr_scene *out,
                                gr_error *err)
{
    if (!path) return gr_fail(err, GR_E_RUNTIME, "gr_scene_load_file: no path");
    char *buf = NULL;
    gr_status rd = gr_json_read_file(path, "scene", GR_MAX_SCENE_BYTES, &buf, err);
    if (rd != GR_OK) return rd;
    gr_status st = load_string_impl(buf, path, overrides, n_overrides, out, err);
    free(buf);
    if (st == GR_OK) snprintf(out->source_path, sizeof out->source_path, "%s", path);
    return st;
}

/* ---- public entry points: every message leaves as one line ---------------------------- */
gr_status gr_scene_refresh(gr_scene *s, gr_error *err)
{
    return one_line(err, refresh_impl(s, err));
}

gr_status gr_scene_load_string(const char *json, const char *label, const char *const *overrides, int n_overrides,
                               gr_scene *out, gr_error *err)
{
    return one_line(err, load_string_impl(json, label, overrides, n_overrides, out, err));
}

gr_status gr_scene_load_file(const char *path, const char *const *overrides, int n_overrides, gr_scene *out,
                             gr_error *err)
{
    return one_line(err, load_file_impl(path, overrides, n_overrides, out, err));
}

void *gr_scene_section(gr_scene *s, int i)
{
    return s && i >= 0 && i < s->n_sections ? s->sections[i].bytes : NULL;
}

const void *gr_scene_section_const(const gr_scene *s, int i)
{
    return s && i >= 0 && i < s->n_sections ? s->sections[i].bytes : NULL;
}

void gr_scene_resolve_settings(const gr_param_table *t, void *settings, const gr_scene *s)
{
    resolve_from_scene(t, settings, s);
}
