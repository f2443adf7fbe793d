/* docs/scene-format.md stays in step with the code: each renderer setting has a table row
 * with its current type, unit, default, range and doc line (the row the descriptor table
 * generates), and every scene key and preset is documented. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene/params.h"
#include "scene/settings.h"
#include "realtime/technique.h"

static char *read_doc(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/docs/scene-format.md", src ? src : GR_SOURCE_DIR);
    FILE *f = fopen(path, "rb");
    CHECK_MSG(f != NULL, "cannot open %s", path);
    if (!f) return NULL;
    char *buf = malloc(1 << 20);
    size_t n = fread(buf, 1, (1 << 20) - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* The markdown row for one descriptor (same layout as the doc's generated tables). */
static void row(const gr_param *p, char *out, size_t n)
{
    static const char *const types[] = {"number", "integer", "bool", "RGB", "string", "integer"};
    char def[96], range[160];
    if (p->flags & GR_PF_FROM_SCENE) snprintf(def, sizeof def, "from `%s`", p->scene_source);
    else if (p->type == GR_PT_ENUM) snprintf(def, sizeof def, "`\"%s\"`", gr_param_enum_name(p, (int)p->def));
    else if (p->type == GR_PT_BOOL) snprintf(def, sizeof def, "%s", p->def != 0.0 ? "true" : "false");
    else gr_format_double(p->def, def, sizeof def);
    gr_param_range_text(p, range, sizeof range);
    snprintf(out, n, "| `%s` | %s | %s | %s | %s | %s |", p->name, types[p->type], p->unit[0] ? p->unit : "-", def,
             range, p->doc);
}

int main(void)
{
    char *doc = read_doc();
    if (!doc) CHECK_DONE();
    /* the ground truth's table and every registered technique's */
    const gr_param_table *tables[1 + GR_TECH_MAX] = {&gr_reference_param_table};
    int n_tables = 1;
    for (int i = 0; i < gr_technique_count(); i++) tables[n_tables++] = gr_technique_at(i)->params;
    char line[1024], head[128];
    for (int t = 0; t < n_tables; t++) {
        snprintf(head, sizeof head, "### `%s`", tables[t]->section);
        const char *sec = strstr(doc, head);
        CHECK_MSG(sec != NULL, "no section %s", head);
        for (size_t i = 0; sec && i < tables[t]->count; i++) {
            row(&tables[t]->params[i], line, sizeof line);
            const char *hit = strstr(sec, line);
            const char *next = strstr(sec + 1, "\n### ");
            CHECK_MSG(hit && (!next || hit < next), "docs/scene-format.md section %s lacks the row\n%s",
                      tables[t]->section, line);
        }
    }
    /* scene keys (src/scene/scene.c key lists) and presets */
    static const char *const keys[] = {
        "version", "name", "water", "sun", "medium", "camera", "occluders", "seabed", "reference",
        "rest_height_m", "time_s", "waves", "amplitude_m", "wavelength_m", "direction_deg", "phase_rad",
        "angular_frequency_rad_s", "elevation_deg", "azimuth_deg", "irradiance", "angular_diameter_deg",
        "preset", "absorption_per_m", "scattering_per_m", "g", "ior", "position_m", "look_at_m", "yaw_deg",
        "pitch_deg", "fov_deg", "width", "height", "type", "center_m", "size_m", "radius_m", "depth_m"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        snprintf(line, sizeof line, "| `%s` |", keys[i]);
        CHECK_MSG(strstr(doc, line) != NULL, "docs/scene-format.md has no row for key '%s'", keys[i]);
    }
    CHECK(strstr(doc, "| `pure_seawater` |") != NULL);
    free(doc);
    CHECK_DONE();
}
