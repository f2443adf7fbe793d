/* GLSL programs of the real-time renderers: sources embedded at build time
 * (src/shaders/NAME.glsl -> gr_embedded_shaders), overridable file by file from a directory
 * (`--shader-dir DIR`), compiled and linked with the driver's log in every error. */
#ifndef GR_REALTIME_SHADERS_H
#define GR_REALTIME_SHADERS_H

#include "common/status.h"

/* Source of shader `name` (e.g. "shafts.vert.glsl"): DIR/name when dir is not NULL and
 * that file exists, else the embedded copy. *out is malloc'd (caller frees); *from_dir
 * (may be NULL) is set to 1 when the file came from dir. GR_E_INPUT when no such shader
 * exists anywhere, GR_E_IO when DIR/name exists but cannot be read. */
gr_status gr_shader_source(const char *dir, const char *name, char **out, int *from_dir,
                           gr_error *err);

/* Checks that dir (if not NULL) is a readable directory; the error names --shader-dir. */
gr_status gr_shader_check_dir(const char *dir, gr_error *err);

/* A program's stage: its files, read as gr_shader_source does and compiled as one source
 * in this order (the first starts with #version; the others follow, e.g. a shared prelude
 * then the stage's own file), NULL-ended. */
#define GR_SHADER_MAX_FILES 6
#define GR_SHADER_MAX_STAGES 4
typedef struct gr_shader_stage {
    unsigned type;                         /* GL_VERTEX_SHADER, GL_GEOMETRY_SHADER, ... */
    const char *files[GR_SHADER_MAX_FILES];
} gr_shader_stage;

/* Compiles and links n stages (1 to GR_SHADER_MAX_STAGES); tf_varyings (n_tf, may be 0)
 * are captured interleaved by transform feedback. Failures return GR_E_GL naming the
 * stage's last file, with the GLSL log on one line; *program is 0. n_from_dir (may be NULL)
 * receives how many files came from dir. Needs a current GL context. */
gr_status gr_shader_program_stages(const char *dir, const gr_shader_stage *stages, int n,
                                   const char *const *tf_varyings, int n_tf, unsigned *program,
                                   int *n_from_dir, gr_error *err);

/* Compiles vert_name + frag_name (looked up as gr_shader_source does) and links them.
 * tf_varyings (n_tf of them, may be 0) are captured interleaved by transform feedback.
 * Failures return GR_E_GL with the file name and the GLSL log on one line; *program is 0.
 * n_from_dir (may be NULL) receives how many of the two came from dir. Needs a current
 * GL context. */
gr_status gr_shader_program(const char *dir, const char *vert_name, const char *frag_name,
                            const char *const *tf_varyings, int n_tf, unsigned *program,
                            int *n_from_dir, gr_error *err);

#endif
