/* godrays info: library versions and what a real headless GL context reports.
 * Versions come from the libraries at run time (not from headers), so a mismatch between the
 * build and the installed runtime shows here. */
#include "cli/cli.h"

#include "gl/gl.h"
#include "gl/glctx.h"
#include "image/oiio.h"
#include "reference/cache.h"

#include <cjson/cJSON.h>
#include <embree3/rtcore.h>
#include <openexr.h>
#include <stdio.h>
#include <string.h>
#ifdef GR_HAVE_PLPLOT
#include <plplot.h>
#endif

#ifndef GR_VERSION
#define GR_VERSION "unknown"
#endif

typedef struct info {
    char embree[32], embree_tasking[16], exr[48], plplot[96];
    const char *cpu_isa, *embree_error;
    char embree_err[GR_ERROR_MSG_MAX];
} info;

/* Widest x86 ISA the CPU offers. Embree 3 has no API that reports the ISA it selected; it
 * dispatches to the widest one it was built with that the CPU supports, so this is the best
 * honest proxy (Debian's build includes SSE2 up to AVX-512 kernels). */
static const char *cpu_isa(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    /* Embree's AVX-512 kernels are the SKX set; its AVX2 kernels also use FMA3. */
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512vl"))
        return "AVX-512";
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "AVX2";
    if (__builtin_cpu_supports("avx")) return "AVX";
    if (__builtin_cpu_supports("sse4.2")) return "SSE4.2";
    return "SSE2";
#else
    return "non-x86";
#endif
}

static void embree_error_cb(void *user, enum RTCError code, const char *str)
{
    info *in = user;
    snprintf(in->embree_err, sizeof in->embree_err, "Embree error %d: %s", (int)code, str ? str : "");
}

static void gather(info *in)
{
    memset(in, 0, sizeof *in);
    in->cpu_isa = cpu_isa();
    RTCDevice dev = rtcNewDevice(NULL);
    if (!dev) {
        snprintf(in->embree_err, sizeof in->embree_err, "rtcNewDevice failed (error %d)",
                 (int)rtcGetDeviceError(NULL));
        in->embree_error = in->embree_err;
    } else {
        rtcSetDeviceErrorFunction(dev, embree_error_cb, in);
        long v = (long)rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_VERSION); /* e.g. 31305 */
        snprintf(in->embree, sizeof in->embree, "%ld.%ld.%ld", v / 10000, v / 100 % 100, v % 100);
        long t = (long)rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_TASKING_SYSTEM);
        snprintf(in->embree_tasking, sizeof in->embree_tasking, "%s",
                 t == 0 ? "internal" : t == 1 ? "TBB" : t == 2 ? "PPL" : "unknown");
        rtcReleaseDevice(dev);
    }
    int maj = 0, min = 0, patch = 0;
    const char *extra = NULL;
    exr_get_library_version(&maj, &min, &patch, &extra);
    snprintf(in->exr, sizeof in->exr, "%d.%d.%d%s", maj, min, patch, extra ? extra : "");
#ifdef GR_HAVE_PLPLOT
    char ver[96] = ""; /* plgver writes at most 80 characters */
    plgver(ver);
    snprintf(in->plplot, sizeof in->plplot, "%s", ver);
#endif
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays info [--json]\n"
            "\n"
            "Prints the versions of godrays and of the libraries it runs with (Embree, OpenEXR,\n"
            "OpenImageIO, cJSON, PLplot), then creates a headless OpenGL context through EGL and\n"
            "prints its vendor, renderer, version, GLSL version, EGL platform and max texture size.\n"
            "\n"
            "options:\n"
            "  --json   one JSON object on stdout instead of text\n"
            "  --help   this text\n"
            "\n"
            "environment: GODRAYS_GL_PLATFORM=surfaceless|device|auto picks the EGL platform.\n"
            "Exit codes: 0 ok, 1 no OpenGL context (or Embree device) could be made, 2 bad usage.\n");
}

static void print_text_libs(const info *in)
{
    printf("godrays          %s\n", GR_VERSION);
    /* the build digest of the ground truth's sources, part of every cache key (reference/cache.h) */
    printf("truth digest     %s\n", gr_cache_digest());
    if (in->embree_error)
        printf("Embree           unavailable: %s\n", in->embree_error);
    else
        printf("Embree           %s (tasking %s; CPU ISA %s, Embree uses the widest it was built for)\n",
               in->embree, in->embree_tasking, in->cpu_isa);
    printf("OpenEXR          %s\n", in->exr);
    printf("OpenImageIO      %s\n", gr_oiio_version());
    printf("cJSON            %s\n", cJSON_Version());
    printf("PLplot           %s\n", in->plplot[0] ? in->plplot : "not linked");
    fflush(stdout);
}

static int print_text_gl(const info *in, const gr_gl *gl, const gr_error *glerr)
{
    if (!gl) {
        fprintf(stderr, "godrays info: no OpenGL context: %s\n", glerr->msg);
        return gr_status_exit_code(glerr->status);
    }
    int maj = 0, min = 0;
    GLint max_tex = 0;
    gr_gl_context_version(gl, &maj, &min);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    printf("OpenGL vendor    %s\n", gr_gl_vendor(gl));
    printf("OpenGL renderer  %s\n", gr_gl_renderer(gl));
    printf("OpenGL version   %s (core profile %d.%d)\n", gr_gl_version(gl), maj, min);
    printf("GLSL version     %s\n", gr_gl_glsl_version(gl));
    printf("EGL platform     %s\n", gr_gl_platform_name(gl));
    printf("max texture size %d\n", (int)max_tex);
    return in->embree_error ? 1 : 0;
}

static int print_json(const info *in, const gr_gl *gl, const gr_error *glerr)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "godrays", GR_VERSION);
    cJSON_AddStringToObject(root, "truth_digest", gr_cache_digest());
    cJSON *emb = cJSON_AddObjectToObject(root, "embree");
    if (in->embree_error) {
        cJSON_AddNullToObject(emb, "version");
        cJSON_AddStringToObject(emb, "error", in->embree_error);
    } else {
        cJSON_AddStringToObject(emb, "version", in->embree);
        cJSON_AddStringToObject(emb, "tasking", in->embree_tasking);
    }
    cJSON_AddStringToObject(emb, "cpu_isa", in->cpu_isa);
    cJSON_AddStringToObject(root, "openexr", in->exr);
    cJSON_AddStringToObject(root, "openimageio", gr_oiio_version());
    cJSON_AddStringToObject(root, "cjson", cJSON_Version());
    if (in->plplot[0]) cJSON_AddStringToObject(root, "plplot", in->plplot);
    else cJSON_AddNullToObject(root, "plplot");
    if (gl) {
        int maj = 0, min = 0;
        GLint max_tex = 0;
        char cv[16];
        gr_gl_context_version(gl, &maj, &min);
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
        snprintf(cv, sizeof cv, "%d.%d", maj, min);
        cJSON *g = cJSON_AddObjectToObject(root, "gl");
        cJSON_AddStringToObject(g, "vendor", gr_gl_vendor(gl));
        cJSON_AddStringToObject(g, "renderer", gr_gl_renderer(gl));
        cJSON_AddStringToObject(g, "version", gr_gl_version(gl));
        cJSON_AddStringToObject(g, "context_version", cv);
        cJSON_AddStringToObject(g, "glsl_version", gr_gl_glsl_version(gl));
        cJSON_AddStringToObject(g, "egl_platform", gr_gl_platform_name(gl));
        cJSON_AddNumberToObject(g, "max_texture_size", (double)max_tex);
    } else {
        cJSON_AddNullToObject(root, "gl");
        cJSON_AddStringToObject(root, "gl_error", glerr->msg);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text) {
        fprintf(stderr, "godrays info: out of memory\n");
        return 1;
    }
    printf("%s\n", text);
    cJSON_free(text);
    if (!gl) {
        fflush(stdout);
        fprintf(stderr, "godrays info: no OpenGL context: %s\n", glerr->msg);
        return gr_status_exit_code(glerr->status);
    }
    return in->embree_error ? 1 : 0;
}

int cmd_info(int argc, char **argv)
{
    int json = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(argv[i], "--json")) json = 1;
        else return gr_cli_usage_error("info", "unknown argument '%s'", argv[i]);
    }
    info in;
    gather(&in);
    /* Library versions first, so they are out even if making a context fails (or crashes). */
    if (!json) print_text_libs(&in);
    gr_error err = {GR_OK, ""};
    gr_gl *gl = NULL;
    if (gr_gl_create(NULL, &gl, &err) != GR_OK) gl = NULL;
    int rc = json ? print_json(&in, gl, &err) : print_text_gl(&in, gl, &err);
    gr_gl_destroy(gl);
    return rc;
}
