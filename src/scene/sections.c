/* The list of technique sections the scene loader knows (sections.h). */
#include "scene/sections.h"

#include <string.h>

static const gr_param_table *tables[GR_SCENE_MAX_SECTIONS];
static int n_tables;

/* The scene format's own top-level keys (scene.c's root keys): never a technique's name. */
static const char *const reserved[] = {"version", "name",      "water",  "sun",      "medium",
                                       "camera",  "occluders", "seabed", "reference"};

int gr_sections_reserved(const char *name)
{
    for (size_t i = 0; i < sizeof reserved / sizeof reserved[0]; i++)
        if (!strcmp(reserved[i], name)) return 1;
    return 0;
}

gr_status gr_sections_add(const gr_param_table *t, size_t settings_size, int *index, gr_error *err)
{
    if (!t || !t->section || !t->section[0])
        return gr_fail(err, GR_E_INPUT, "scene section: no name");
    if (gr_sections_reserved(t->section))
        return gr_fail(err, GR_E_INPUT, "scene section '%s': a key of the scene format itself", t->section);
    if (gr_sections_find(t->section) >= 0)
        return gr_fail(err, GR_E_INPUT, "scene section '%s': already defined", t->section);
    if (settings_size > GR_SCENE_SECTION_BYTES)
        return gr_fail(err, GR_E_INPUT, "scene section '%s': settings of %zu bytes, at most %d", t->section,
                       settings_size, GR_SCENE_SECTION_BYTES);
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        size_t w = p->type == GR_PT_RGB ? 3 * sizeof(double)
                   : p->type == GR_PT_DOUBLE ? sizeof(double)
                   : p->type == GR_PT_U64 ? sizeof(unsigned long long) : sizeof(int);
        if (p->offset + w > settings_size)
            return gr_fail(err, GR_E_INPUT, "scene section '%s': setting %s lies outside its %zu-byte struct",
                           t->section, p->name, settings_size);
    }
    if (n_tables >= GR_SCENE_MAX_SECTIONS)
        return gr_fail(err, GR_E_INPUT, "scene section '%s': too many sections (at most %d)", t->section,
                       GR_SCENE_MAX_SECTIONS);
    tables[n_tables] = t;
    if (index) *index = n_tables;
    n_tables++;
    return GR_OK;
}

int gr_sections_count(void) { return n_tables; }

const gr_param_table *gr_sections_table(int i) { return i >= 0 && i < n_tables ? tables[i] : NULL; }

int gr_sections_find(const char *name)
{
    if (!name) return -1;
    for (int i = 0; i < n_tables; i++)
        if (!strcmp(tables[i]->section, name)) return i;
    return -1;
}
