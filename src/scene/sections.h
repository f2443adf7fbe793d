/* The scene's technique sections: one settings section per real-time technique ("shafts",
 * "radial_blur", a user technique's name, ...), each described by its descriptor table.
 * The scene module does not know any technique: the technique registry
 * (src/realtime/technique.h) adds every technique's table here when it registers it, and
 * the scene loader parses, validates, overrides (--set NAME.KEY=V) and prints every section
 * listed here. Section i of a scene (gr_scene.sections[i]) belongs to table i.
 * Process-wide, append-only; add sections before loading scenes, from one thread. */
#ifndef GR_SCENE_SECTIONS_H
#define GR_SCENE_SECTIONS_H

#include <stddef.h>

#include "common/status.h"
#include "scene/params.h"

#define GR_SCENE_MAX_SECTIONS 32    /* technique sections per process */
#define GR_SCENE_SECTION_BYTES 1024 /* bytes of one section's settings struct, at most */

/* Storage of one section's settings (aligned for any field type). */
typedef struct gr_section_store {
    _Alignas(16) unsigned char bytes[GR_SCENE_SECTION_BYTES];
} gr_section_store;

/* Adds a section described by t (t->section is its JSON key; settings_size bytes). The
 * table must outlive the process. *index (may be NULL) receives its index. GR_E_INPUT for a
 * bad or reserved name ("reference", "camera", ...), a duplicate, a struct over
 * GR_SCENE_SECTION_BYTES or a full list. */
gr_status gr_sections_add(const gr_param_table *t, size_t settings_size, int *index, gr_error *err);
int gr_sections_count(void);
const gr_param_table *gr_sections_table(int i); /* NULL if out of range */
int gr_sections_find(const char *name);         /* -1 if none */
/* 1 if name is a top-level key of the scene format itself (not a technique section). */
int gr_sections_reserved(const char *name);

#endif
