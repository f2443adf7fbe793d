/* Headless OpenGL 4.5 core context through EGL, with no window: the EGL device platform
 * on a GPU (EGL_EXT_platform_device), Mesa's surfaceless platform (llvmpipe) elsewhere.
 * GL entry points: include "gl/gl.h" (core profile prototypes through libOpenGL). */
#ifndef GR_GLCTX_H
#define GR_GLCTX_H

#include "common/status.h"

/* Opaque: display + context, current on the creating thread. A context is used from ONE
 * thread only (EGL binds it per thread); create, use and destroy it on that thread. */
typedef struct gr_gl gr_gl;

typedef enum gr_gl_platform {
    GR_GL_AUTO = 0,        /* device platform if a hardware device works, else surfaceless */
    GR_GL_SURFACELESS = 1, /* EGL_PLATFORM_SURFACELESS_MESA */
    GR_GL_DEVICE = 2       /* EGL_PLATFORM_DEVICE_EXT */
} gr_gl_platform;

typedef struct gr_gl_options {
    gr_gl_platform platform; /* 0 = auto; env GODRAYS_GL_PLATFORM=surfaceless|device overrides */
    int debug;               /* create a debug context and print GL debug messages */
} gr_gl_options;

/* Creates the context and makes it current. opts may be NULL. Errors (GR_E_GL) say which
 * EGL step failed and what to install. */
gr_status gr_gl_create(const gr_gl_options *opts, gr_gl **out, gr_error *err);
void gr_gl_destroy(gr_gl *gl); /* accepts NULL */
const char *gr_gl_vendor(const gr_gl *gl);
const char *gr_gl_renderer(const gr_gl *gl);
const char *gr_gl_version(const gr_gl *gl);
const char *gr_gl_platform_name(const gr_gl *gl); /* "surfaceless" or "device" */
/* Returns GR_OK, or GR_E_GL with the pending glGetError codes named after `what`. */
gr_status gr_gl_check(const char *what, gr_error *err);

/* Added by the GL module: */
const char *gr_gl_glsl_version(const gr_gl *gl); /* GL_SHADING_LANGUAGE_VERSION */
/* Gives up gl for good: work still queued in it (a user shader over its time limit) is never
 * waited for. Later gr_gl_make_current fails (GR_E_GL) and gr_gl_destroy frees only the
 * handle, never touching the context (whose destruction could wait for that work). */
void gr_gl_abandon(gr_gl *gl);
int gr_gl_abandoned(const gr_gl *gl); /* 1 after gr_gl_abandon */
/* Makes gl current again on the calling thread (after another gr_gl was created there). */
gr_status gr_gl_make_current(gr_gl *gl, gr_error *err);
/* Context version actually obtained (4.5 asked; 4.3 or 3.3 core if the driver refused). */
void gr_gl_context_version(const gr_gl *gl, int *major, int *minor);
/* Compiles a vertex + fragment shader pair and links them. `name` (e.g. the shader file)
 * prefixes errors; a compile or link failure returns GR_E_GL with the driver's log (first
 * lines, joined on one line). *program is 0 on failure. Needs a current context. */
gr_status gr_gl_build_program(const char *name, const char *vert_src, const char *frag_src,
                              unsigned *program, gr_error *err);
/* Links compiled vertex and fragment shaders vs and fs (deleted here, whatever the outcome)
 * into *program; a link failure returns GR_E_GL "NAME: program does not link: LOG" (the
 * driver's log on one line), *program 0. The link step of gr_gl_build_program, for callers that
 * compile their stages themselves (user techniques, which map the compile log to their files). */
gr_status gr_gl_link_program(const char *name, unsigned vs, unsigned fs, unsigned *program, gr_error *err);

/* Whether a w x h render target of `internal_format` (GL_RGBA32F for the god-ray layer) fits
 * this context before it is made: against GL_MAX_TEXTURE_SIZE, GL_MAX_RENDERBUFFER_SIZE and
 * GL_MAX_VIEWPORT_DIMS, then as a proxy texture (the driver's own refusal: llvmpipe holds at
 * most 1 GiB in one texture, so a 16384 x 16384 RGBA32F target failed as "framebuffer
 * incomplete (0x8cd6)"). GR_E_INPUT naming `what` (e.g. "camera.width/height"), the size and
 * the limit it is over. Needs a current context. */
gr_status gr_gl_check_target_size(const char *what, int w, int h, unsigned internal_format, gr_error *err);

#endif
