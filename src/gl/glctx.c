/* Headless OpenGL context through EGL: no window, no X, no surface.
 * Order in AUTO mode: the EGL device platform (EGL_EXT_device_enumeration, or EGL_EXT_device_base
 * which includes it, + EGL_EXT_platform_device) on a hardware device, else Mesa's surfaceless platform
 * (EGL_MESA_platform_surfaceless, llvmpipe on machines without a GPU). The context is made
 * current with EGL_NO_SURFACE (EGL_KHR_surfaceless_context); rendering goes into FBOs.
 * EGL binds a context to one thread: a gr_gl is created, used and destroyed on one thread. */
#include "gl/glctx.h"

#include "gl/gl.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_GL_INSTALL_HINT "install libegl-mesa0 libgl1-mesa-dri (Mesa's EGL and llvmpipe)"

struct gr_gl {
    EGLDisplay dpy;
    EGLContext ctx;
    const char *platform; /* "device" or "surfaceless" */
    int major, minor;
    int abandoned; /* gr_gl_abandon: the context is never used or destroyed again */
};

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    case EGL_BAD_DEVICE_EXT: return "EGL_BAD_DEVICE_EXT";
    }
    return "unknown EGL error";
}

/* Whole-word match in a space-separated extension string. */
static int has_ext(const char *list, const char *name)
{
    if (!list) return 0;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    return 0;
}

static gr_status egl_fail(gr_error *err, const char *platform, const char *step)
{
    return gr_fail(err, GR_E_GL, "EGL %s platform: %s failed (%s); %s", platform, step,
                   egl_error_name(eglGetError()), GR_GL_INSTALL_HINT);
}

static void APIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity,
                                      GLsizei length, const GLchar *message, const void *user)
{
    (void)source; (void)id; (void)length; (void)user;
    const char *sev = severity == GL_DEBUG_SEVERITY_HIGH     ? "high"
                      : severity == GL_DEBUG_SEVERITY_MEDIUM ? "medium"
                      : severity == GL_DEBUG_SEVERITY_LOW    ? "low"
                                                             : "note";
    fprintf(stderr, "GL debug (%s%s): %s\n", sev, type == GL_DEBUG_TYPE_ERROR ? ", error" : "", message);
}

/* Initializes dpy and creates a core-profile context on it, made current without a surface.
 * Tries 4.5, then 4.3, then 3.3 (what the driver grants is recorded in gl->major/minor). */
static gr_status init_on_display(gr_gl *gl, EGLDisplay dpy, const char *platform, int debug,
                                 gr_error *err)
{
    EGLint emaj = 0, emin = 0;
    if (dpy == EGL_NO_DISPLAY) return egl_fail(err, platform, "eglGetPlatformDisplayEXT");
    if (!eglInitialize(dpy, &emaj, &emin)) return egl_fail(err, platform, "eglInitialize");
    gl->dpy = dpy;
    const char *exts = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_ext(exts, "EGL_KHR_surfaceless_context"))
        return gr_fail(err, GR_E_GL, "EGL %s platform: EGL_KHR_surfaceless_context is missing; %s",
                       platform, GR_GL_INSTALL_HINT);
    if (!(emaj > 1 || (emaj == 1 && emin >= 5)) && !has_ext(exts, "EGL_KHR_create_context"))
        return gr_fail(err, GR_E_GL, "EGL %s platform: EGL %d.%d without EGL_KHR_create_context "
                       "cannot create a core-profile context; %s", platform, emaj, emin,
                       GR_GL_INSTALL_HINT);
    if (!eglBindAPI(EGL_OPENGL_API)) return egl_fail(err, platform, "eglBindAPI(EGL_OPENGL_API)");

    /* No surface is ever drawn to, so any OpenGL-capable config will do; without
     * EGL_KHR_no_config_context pick one that renders desktop GL. */
    EGLConfig cfg = EGL_NO_CONFIG_KHR;
    if (!has_ext(exts, "EGL_KHR_no_config_context")) {
        const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_DONT_CARE,
                               EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(dpy, want, &cfg, 1, &n)) return egl_fail(err, platform, "eglChooseConfig");
        if (n < 1)
            return gr_fail(err, GR_E_GL, "EGL %s platform: no EGL config renders desktop OpenGL; %s",
                           platform, GR_GL_INSTALL_HINT);
    }
    static const int versions[3][2] = {{4, 5}, {4, 3}, {3, 3}};
    for (int i = 0; i < 3 && gl->ctx == EGL_NO_CONTEXT; i++) {
        const EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION_KHR, versions[i][0],
                               EGL_CONTEXT_MINOR_VERSION_KHR, versions[i][1],
                               EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
                               EGL_CONTEXT_FLAGS_KHR, debug ? EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR : 0,
                               EGL_NONE};
        gl->ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, attr);
    }
    if (gl->ctx == EGL_NO_CONTEXT)
        return egl_fail(err, platform, "eglCreateContext (OpenGL 4.5/4.3/3.3 core profile)");
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->ctx))
        return egl_fail(err, platform, "eglMakeCurrent (no surface)");
    GLint maj = 0, min = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &maj);
    glGetIntegerv(GL_MINOR_VERSION, &min);
    if (maj < 3 || (maj == 3 && min < 3))
        return gr_fail(err, GR_E_GL, "EGL %s platform: got OpenGL %d.%d, need 3.3 core or later; %s",
                       platform, (int)maj, (int)min, GR_GL_INSTALL_HINT);
    gl->major = maj;
    gl->minor = min;
    gl->platform = platform;
    if (debug && (maj > 4 || (maj == 4 && min >= 3))) { /* KHR_debug is core in 4.3 */
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debug_callback, NULL);
    }
    return GR_OK;
}

/* Releases the context, leaving gl ready for another attempt. The display is deliberately
 * never eglTerminate'd: EGL hands every caller the same display per platform + device, so
 * terminating it would kill other live contexts on it; and terminating Mesa's display unloads
 * the driver, which drops llvmpipe allocations (LeakSanitizer reports them) and makes the next
 * context pay ~9 ms instead of ~2 ms. An initialized display lives until the process exits. */
static void release(gr_gl *gl)
{
    if (gl->dpy != EGL_NO_DISPLAY && gl->ctx != EGL_NO_CONTEXT) {
        if (eglGetCurrentContext() == gl->ctx)
            eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(gl->dpy, gl->ctx);
    }
    gl->dpy = EGL_NO_DISPLAY;
    gl->ctx = EGL_NO_CONTEXT;
}

static gr_status try_surfaceless(gr_gl *gl, int debug, gr_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_ext(client, "EGL_MESA_platform_surfaceless"))
        return gr_fail(err, GR_E_GL, "EGL surfaceless platform: EGL_MESA_platform_surfaceless is "
                       "not offered by libEGL; %s", GR_GL_INSTALL_HINT);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display) return egl_fail(err, "surfaceless", "eglGetProcAddress(eglGetPlatformDisplayEXT)");
    EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    gr_status st = init_on_display(gl, dpy, "surfaceless", debug, err);
    if (st != GR_OK) release(gl);
    return st;
}

/* Tries each EGL device; hardware ones first. Mesa's software device (llvmpipe, flagged by
 * EGL_MESA_device_software) is accepted only when allow_software is set (a forced "device"). */
static gr_status try_device(gr_gl *gl, int debug, int allow_software, gr_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    /* EGL_EXT_device_base is EGL_EXT_device_enumeration + EGL_EXT_device_query under one name:
     * glvnd's libEGL with only NVIDIA's driver (580) lists device_base, not enumeration. */
    int enumeration = has_ext(client, "EGL_EXT_device_enumeration") ||
                      has_ext(client, "EGL_EXT_device_base");
    if (!enumeration || !has_ext(client, "EGL_EXT_platform_device"))
        return gr_fail(err, GR_E_GL, "EGL device platform: libEGL lacks EGL_EXT_device_enumeration "
                       "(or EGL_EXT_device_base) or EGL_EXT_platform_device; %s", GR_GL_INSTALL_HINT);
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC device_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!query_devices || !device_string || !get_display)
        return egl_fail(err, "device", "eglGetProcAddress(eglQueryDevicesEXT)");
    EGLDeviceEXT devs[16];
    EGLint n = 0;
    if (!query_devices(16, devs, &n)) return egl_fail(err, "device", "eglQueryDevicesEXT");
    gr_status st = gr_fail(err, GR_E_GL, "EGL device platform: no %sEGL device found; %s",
                           allow_software ? "" : "hardware ", GR_GL_INSTALL_HINT);
    for (int pass = 0; pass < (allow_software ? 2 : 1); pass++) {
        for (EGLint i = 0; i < n; i++) {
            int software = has_ext(device_string(devs[i], EGL_EXTENSIONS), "EGL_MESA_device_software");
            if (software != pass) continue;
            EGLDisplay dpy = get_display(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
            st = init_on_display(gl, dpy, "device", debug, err);
            if (st == GR_OK) return GR_OK;
            release(gl);
        }
    }
    return st;
}

gr_status gr_gl_create(const gr_gl_options *opts, gr_gl **out, gr_error *err)
{
    if (!out) return gr_fail(err, GR_E_USAGE, "gr_gl_create: out is NULL");
    *out = NULL;
    gr_gl_platform platform = opts ? opts->platform : GR_GL_AUTO;
    int debug = opts ? opts->debug : 0;
    const char *env = getenv("GODRAYS_GL_PLATFORM");
    if (env && *env) {
        if (!strcmp(env, "surfaceless")) platform = GR_GL_SURFACELESS;
        else if (!strcmp(env, "device")) platform = GR_GL_DEVICE;
        else if (!strcmp(env, "auto")) platform = GR_GL_AUTO;
        else
            return gr_fail(err, GR_E_USAGE, "env GODRAYS_GL_PLATFORM: '%s' is not surfaceless, "
                           "device or auto", env);
    }
    gr_gl *gl = calloc(1, sizeof *gl);
    if (!gl) return gr_fail(err, GR_E_NOMEM, "gr_gl_create: out of memory");
    gl->dpy = EGL_NO_DISPLAY;
    gl->ctx = EGL_NO_CONTEXT;
    gr_status st;
    if (platform == GR_GL_DEVICE) {
        st = try_device(gl, debug, 1, err);
    } else if (platform == GR_GL_SURFACELESS) {
        st = try_surfaceless(gl, debug, err);
    } else {
        /* A failed device attempt is normal on a machine without a GPU: its message is
         * dropped and the surfaceless platform's result is what the caller sees. */
        st = try_device(gl, debug, 0, NULL);
        if (st != GR_OK) st = try_surfaceless(gl, debug, err);
    }
    if (st != GR_OK) {
        free(gl);
        return st;
    }
    *out = gl;
    return GR_OK;
}

void gr_gl_destroy(gr_gl *gl)
{
    if (!gl) return;
    if (gl->abandoned) {
        free(gl);
        return;
    }
    release(gl);
    eglReleaseThread();
    free(gl);
}

void gr_gl_abandon(gr_gl *gl)
{
    if (gl) gl->abandoned = 1;
}

int gr_gl_abandoned(const gr_gl *gl) { return gl && gl->abandoned; }

gr_status gr_gl_make_current(gr_gl *gl, gr_error *err)
{
    if (!gl) return gr_fail(err, GR_E_USAGE, "gr_gl_make_current: gl is NULL");
    if (gl->abandoned)
        return gr_fail(err, GR_E_GL, "the GL context was abandoned after a render over its time limit: make a new one");
    if (!eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->ctx))
        return gr_fail(err, GR_E_GL, "EGL %s platform: eglMakeCurrent failed (%s)", gl->platform,
                       egl_error_name(eglGetError()));
    return GR_OK;
}

/* glGetString needs the context current; every gr_gl is current on its (only) thread. */
static const char *gl_string(const gr_gl *gl, GLenum name)
{
    if (!gl) return "";
    const GLubyte *s = glGetString(name);
    return s ? (const char *)s : "";
}

const char *gr_gl_vendor(const gr_gl *gl) { return gl_string(gl, GL_VENDOR); }
const char *gr_gl_renderer(const gr_gl *gl) { return gl_string(gl, GL_RENDERER); }
const char *gr_gl_version(const gr_gl *gl) { return gl_string(gl, GL_VERSION); }
const char *gr_gl_glsl_version(const gr_gl *gl) { return gl_string(gl, GL_SHADING_LANGUAGE_VERSION); }
const char *gr_gl_platform_name(const gr_gl *gl) { return gl ? gl->platform : ""; }

void gr_gl_context_version(const gr_gl *gl, int *major, int *minor)
{
    if (major) *major = gl ? gl->major : 0;
    if (minor) *minor = gl ? gl->minor : 0;
}

static const char *gl_error_name(GLenum e)
{
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
    }
    return "unknown GL error";
}

gr_status gr_gl_check(const char *what, gr_error *err)
{
    char list[256] = "";
    size_t len = 0;
    /* glGetError returns one flag per call until all are cleared; the bound stops a lost
     * context (which may repeat GL_CONTEXT_LOST) from looping forever. */
    for (int i = 0; i < 8; i++) {
        GLenum e = glGetError();
        if (e == GL_NO_ERROR) break;
        int w = snprintf(list + len, sizeof list - len, "%s%s (0x%04x)", len ? ", " : "",
                         gl_error_name(e), (unsigned)e);
        if (w > 0 && (size_t)w < sizeof list - len) len += (size_t)w;
        if (e == GL_CONTEXT_LOST) break;
    }
    if (!len) return GR_OK;
    return gr_fail(err, GR_E_GL, "%s: OpenGL error %s", what ? what : "OpenGL", list);
}

/* Copies a driver log into dst as one line: newlines become " | ", trailing blanks dropped. */
static void one_line(char *dst, size_t cap, const char *log)
{
    size_t n = 0;
    for (const char *p = log; *p && n + 4 < cap; p++) {
        if (*p == '\n' || *p == '\r') {
            while (p[1] == '\n' || p[1] == '\r') p++;
            if (p[1] == '\0') break;
            memcpy(dst + n, " | ", 3);
            n += 3;
        } else {
            dst[n++] = *p;
        }
    }
    while (n > 0 && (dst[n - 1] == ' ' || dst[n - 1] == '|')) n--;
    dst[n] = '\0';
}

static gr_status compile(GLenum type, const char *name, const char *src, GLuint *out, gr_error *err)
{
    *out = 0;
    const char *kind = type == GL_VERTEX_SHADER ? "vertex" : "fragment";
    if (!src) return gr_fail(err, GR_E_GL, "%s: %s shader source is missing", name, kind);
    GLuint sh = glCreateShader(type);
    if (!sh) return gr_fail(err, GR_E_GL, "%s: glCreateShader(%s) failed", name, kind);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048] = "", line[GR_ERROR_MSG_MAX];
        glGetShaderInfoLog(sh, (GLsizei)sizeof log, NULL, log);
        one_line(line, sizeof line - 200, log);
        glDeleteShader(sh);
        return gr_fail(err, GR_E_GL, "%s: %s shader does not compile: %s", name, kind, line);
    }
    *out = sh;
    return GR_OK;
}

gr_status gr_gl_link_program(const char *name, unsigned vs, unsigned fs, unsigned *program, gr_error *err)
{
    if (!name) name = "shader";
    *program = 0;
    GLuint prog = glCreateProgram();
    glAttachShader(prog, vs);
    glAttachShader(prog, fs);
    glLinkProgram(prog);
    /* The program keeps its compiled stages; flagging the shaders lets GL free them with it. */
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048] = "", line[GR_ERROR_MSG_MAX];
        glGetProgramInfoLog(prog, (GLsizei)sizeof log, NULL, log);
        one_line(line, sizeof line - 200, log);
        glDeleteProgram(prog);
        return gr_fail(err, GR_E_GL, "%s: program does not link: %s", name, line);
    }
    *program = prog;
    return gr_gl_check(name, err);
}

gr_status gr_gl_build_program(const char *name, const char *vert_src, const char *frag_src,
                              unsigned *program, gr_error *err)
{
    if (!name) name = "shader";
    if (!program) return gr_fail(err, GR_E_USAGE, "%s: program is NULL", name);
    *program = 0;
    GLuint vs = 0, fs = 0;
    gr_status st = compile(GL_VERTEX_SHADER, name, vert_src, &vs, err);
    if (st == GR_OK) st = compile(GL_FRAGMENT_SHADER, name, frag_src, &fs, err);
    if (st != GR_OK) {
        if (vs) glDeleteShader(vs);
        return st;
    }
    return gr_gl_link_program(name, vs, fs, program, err);
}

gr_status gr_gl_check_target_size(const char *what, int w, int h, unsigned internal_format, gr_error *err)
{
    if (w < 1 || h < 1) return gr_fail(err, GR_E_INPUT, "%s: a %dx%d render target is empty", what, w, h);
    GLint tex = 0, rb = 0, vp[2] = {0, 0};
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &tex);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, vp);
    const char *rn = (const char *)glGetString(GL_RENDERER);
    if (!rn) rn = "unknown renderer";
    if (w > tex || h > tex || w > rb || h > rb || w > vp[0] || h > vp[1])
        return gr_fail(err, GR_E_INPUT, "%s: a %dx%d render target is over this OpenGL's limits (GL_MAX_TEXTURE_SIZE %d, "
                       "GL_MAX_RENDERBUFFER_SIZE %d, GL_MAX_VIEWPORT_DIMS %dx%d; %s): use a smaller size", what, w, h,
                       (int)tex, (int)rb, (int)vp[0], (int)vp[1], rn);
    /* the driver's answer for this size and format: a proxy texture of width 0 is refused */
    const int rgba32f = internal_format == GL_RGBA32F;
    glTexImage2D(GL_PROXY_TEXTURE_2D, 0, (GLint)internal_format, w, h, 0, GL_RGBA, GL_FLOAT, NULL);
    GLint pw = 0;
    glGetTexLevelParameteriv(GL_PROXY_TEXTURE_2D, 0, GL_TEXTURE_WIDTH, &pw);
    for (int k = 0; k < 8 && glGetError() != GL_NO_ERROR; k++) { /* a too-large proxy may set one; bounded if lost */
    }
    if (pw == 0)
        return gr_fail(err, GR_E_INPUT, "%s: a %dx%d render target (format 0x%04x%s) is more than this OpenGL holds in one "
                       "texture (%s; within GL_MAX_TEXTURE_SIZE %d, the driver refuses its memory): use a smaller size",
                       what, w, h, internal_format, rgba32f ? ", RGBA32F: 16 bytes per pixel" : "", rn, (int)tex);
    return GR_OK;
}
