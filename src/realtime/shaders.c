/* GLSL program loading for the real-time renderers (see shaders.h). */
#include "realtime/shaders.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gl/gl.h"
#include "gl/shaders_embedded.h"

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

static gr_status read_text(const char *path, char **out, gr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return gr_fail(err, GR_E_IO, "%s: cannot open: %s", path, strerror(errno));
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (len + 1 >= cap) {
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len - 1, f);
        len += got;
        if (got == 0) break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return gr_fail(err, GR_E_IO, "%s: read error", path);
    }
    buf[len] = '\0';
    *out = buf;
    return GR_OK;
}

gr_status gr_shader_check_dir(const char *dir, gr_error *err)
{
    struct stat st;
    if (!dir) return GR_OK;
    if (stat(dir, &st) != 0)
        return gr_fail(err, GR_E_INPUT, "--shader-dir %s: %s", dir, strerror(errno));
    if (!S_ISDIR(st.st_mode)) return gr_fail(err, GR_E_INPUT, "--shader-dir %s: not a directory", dir);
    return GR_OK;
}

gr_status gr_shader_source(const char *dir, const char *name, char **out, int *from_dir,
                           gr_error *err)
{
    *out = NULL;
    if (from_dir) *from_dir = 0;
    if (dir) {
        char path[4096];
        struct stat st;
        int n = snprintf(path, sizeof path, "%s/%s", dir, name);
        if (n < 0 || (size_t)n >= sizeof path)
            return gr_fail(err, GR_E_INPUT, "--shader-dir %s: path too long", dir);
        if (stat(path, &st) == 0) {
            gr_status st2 = read_text(path, out, err);
            if (st2 == GR_OK && from_dir) *from_dir = 1;
            return st2;
        }
    }
    for (const gr_embedded_shader *e = gr_embedded_shaders; e->name; e++) {
        if (!strcmp(e->name, name)) {
            *out = dup_string(e->source);
            return *out ? GR_OK : gr_fail(err, GR_E_NOMEM, "%s: out of memory", name);
        }
    }
    return gr_fail(err, GR_E_INPUT, "%s: no such shader (embedded or in --shader-dir)", name);
}

/* The driver's log on one line: newlines become " | ", trailing blanks dropped. */
static void flatten_log(char *log)
{
    size_t n = strlen(log);
    while (n > 0 && (log[n - 1] == '\n' || log[n - 1] == '\r' || log[n - 1] == ' ')) log[--n] = '\0';
    for (size_t i = 0; i < n; i++)
        if (log[i] == '\n' || log[i] == '\r' || log[i] == '\t') log[i] = ' ';
}

/* The outcome of compiling a shader (program = 0) or linking a program: on failure the
 * object is deleted, *obj set to 0, and the driver's log returned on one line. */
static gr_status gl_outcome(GLuint *obj, int program, const char *name, gr_error *err)
{
    GLint ok = 0;
    if (program) glGetProgramiv(*obj, GL_LINK_STATUS, &ok);
    else glGetShaderiv(*obj, GL_COMPILE_STATUS, &ok);
    if (ok) return GR_OK;
    char log[900];
    log[0] = '\0';
    if (program) glGetProgramInfoLog(*obj, (GLsizei)sizeof log, NULL, log);
    else glGetShaderInfoLog(*obj, (GLsizei)sizeof log, NULL, log);
    flatten_log(log);
    if (program) glDeleteProgram(*obj);
    else glDeleteShader(*obj);
    *obj = 0;
    return gr_fail(err, GR_E_GL, "%s: GLSL %s failed: %s", name, program ? "link" : "compile", log[0] ? log : "(no log)");
}

/* One stage: its files read (from dir or embedded) and compiled as one source, in order;
 * the log names the stage's last file (its own code; the first ones are shared preludes). */
static gr_status compile_stage(const char *dir, const gr_shader_stage *sg, GLuint *out, int *n_dir, gr_error *err)
{
    char *src[GR_SHADER_MAX_FILES] = {NULL};
    int k = 0, from = 0;
    gr_status st = GR_OK;
    *out = 0;
    for (; k < GR_SHADER_MAX_FILES && sg->files[k]; k++) {
        if ((st = gr_shader_source(dir, sg->files[k], &src[k], &from, err)) != GR_OK) break;
        *n_dir += from;
    }
    const char *name = k > 0 ? sg->files[k - 1] : "(no file)";
    if (st == GR_OK && k == 0) st = gr_fail(err, GR_E_INPUT, "shader stage with no file");
    GLuint sh = 0;
    if (st == GR_OK && !(sh = glCreateShader(sg->type))) st = gr_fail(err, GR_E_GL, "%s: glCreateShader failed", name);
    if (st == GR_OK) {
        glShaderSource(sh, k, (const GLchar *const *)src, NULL);
        glCompileShader(sh);
        st = gl_outcome(&sh, 0, name, err);
    }
    for (int j = 0; j < k; j++) free(src[j]);
    *out = sh;
    return st;
}

gr_status gr_shader_program_stages(const char *dir, const gr_shader_stage *stages, int n,
                                   const char *const *tf_varyings, int n_tf, unsigned *program,
                                   int *n_from_dir, gr_error *err)
{
    GLuint sh[GR_SHADER_MAX_STAGES] = {0}, prog = 0;
    int n_dir = 0;
    gr_status st = GR_OK;
    *program = 0;
    if (n < 1 || n > GR_SHADER_MAX_STAGES) return gr_fail(err, GR_E_INPUT, "shader program with %d stages", n);
    const char *name = stages[n - 1].files[0]; /* the program is named by its last stage */
    for (int s = 0; s < n && st == GR_OK; s++) st = compile_stage(dir, &stages[s], &sh[s], &n_dir, err);
    if (n_from_dir) *n_from_dir = n_dir;
    if (st == GR_OK && !(prog = glCreateProgram())) st = gr_fail(err, GR_E_GL, "%s: glCreateProgram failed", name);
    if (st == GR_OK) {
        for (int s = 0; s < n; s++) glAttachShader(prog, sh[s]);
        if (n_tf > 0) glTransformFeedbackVaryings(prog, n_tf, (const GLchar *const *)tf_varyings, GL_INTERLEAVED_ATTRIBS);
        glLinkProgram(prog);
        st = gl_outcome(&prog, 1, name, err);
    }
    for (int s = 0; s < n; s++)
        if (sh[s]) glDeleteShader(sh[s]);
    if (st == GR_OK) *program = prog;
    return st;
}

gr_status gr_shader_program(const char *dir, const char *vert_name, const char *frag_name,
                            const char *const *tf_varyings, int n_tf, unsigned *program,
                            int *n_from_dir, gr_error *err)
{
    const gr_shader_stage stages[2] = {{GL_VERTEX_SHADER, {vert_name, NULL}}, {GL_FRAGMENT_SHADER, {frag_name, NULL}}};
    return gr_shader_program_stages(dir, stages, 2, tf_varyings, n_tf, program, n_from_dir, err);
}
