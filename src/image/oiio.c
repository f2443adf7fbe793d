/* oiio.h's functions: OpenImageIO is loaded on the first call (oiio_module.h says why), from
 *   1. $GODRAYS_OIIO_MODULE, when set (the only place tried then);
 *   2. libgodrays_oiio.so beside the running binary (build/ for build/godrays);
 *   3. the build folder this binary was built in (GR_OIIO_MODULE_DIR: the test binaries).
 * Built with GR_OIIO_STATIC (cmake -DGODRAYS_OIIO_MODULE=OFF, and the fuzz targets) the module
 * is linked in and nothing is loaded. */
#include "image/oiio.h"
#include "common/memlimit.h"
#include "common/outfile.h"
#include "image/exr.h"
#include "image/oiio_module.h"

#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifndef GR_OIIO_STATIC
#include <dlfcn.h>
#endif

static const gr_oiio_host host = {
    gr_fail,          gr_image_create,     gr_image_destroy, gr_image_check_finite,
    gr_image_check_size, gr_memlimit_check, gr_check_regular_input, gr_exr_check,
    gr_outfile_begin, gr_outfile_commit,   gr_outfile_abort,
};

static const gr_oiio_api *api;          /* set once by load(), NULL when it failed */
static char load_error[2048];           /* why, when it failed */
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

#ifdef GR_OIIO_STATIC
static void load(void)
{
    api = gr_oiio_module_open(&host, GR_OIIO_MODULE_ABI);
    if (!api) snprintf(load_error, sizeof load_error, "the linked OpenImageIO module refused ABI %d", GR_OIIO_MODULE_ABI);
}
#else
/* Appends "path: why" to load_error. */
static void note_failure(const char *path, const char *why)
{
    size_t n = strlen(load_error);
    if (n + 8 < sizeof load_error)
        snprintf(load_error + n, sizeof load_error - n, "%s%s: %s", n ? "; " : "", path, why ? why : "unknown");
}

/* Opens the module at path; 1 when api is set. */
static int try_path(const char *path)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        note_failure(path, dlerror());
        return 0;
    }
    gr_oiio_module_open_fn open_fn;
    *(void **)&open_fn = dlsym(h, GR_OIIO_MODULE_ENTRY); /* POSIX's way to a function pointer */
    if (!open_fn) {
        note_failure(path, "no " GR_OIIO_MODULE_ENTRY " in it");
        dlclose(h);
        return 0;
    }
    api = open_fn(&host, GR_OIIO_MODULE_ABI);
    if (!api) {
        note_failure(path, "built for another version of godrays (module ABI differs): rebuild");
        dlclose(h);
        return 0;
    }
    return 1; /* stays loaded for the process's life */
}

static void load(void)
{
    char path[PATH_MAX + sizeof GR_OIIO_MODULE_FILE + 1];
    const char *env = getenv("GODRAYS_OIIO_MODULE");
    if (env && env[0]) {
        try_path(env);
        return;
    }
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            snprintf(path, sizeof path, "%s/%s", exe, GR_OIIO_MODULE_FILE);
            if (try_path(path)) return;
        }
    }
#ifdef GR_OIIO_MODULE_DIR
    snprintf(path, sizeof path, "%s/%s", GR_OIIO_MODULE_DIR, GR_OIIO_MODULE_FILE);
    if (try_path(path)) return;
#endif
}
#endif

/* The module's table, or NULL with err set (GR_E_RUNTIME). */
static const gr_oiio_api *loaded(gr_error *err)
{
    pthread_once(&load_once, load);
    if (!api)
        gr_fail(err, GR_E_RUNTIME,
                "OpenImageIO (image files other than EXR and PNG previews, text, maps) is not available: cannot load "
                "%s (%s); set GODRAYS_OIIO_MODULE to its path",
                GR_OIIO_MODULE_FILE, load_error);
    return api;
}

gr_status gr_oiio_available(gr_error *err)
{
    return loaded(err) ? GR_OK : GR_E_RUNTIME;
}

const char *gr_oiio_version(void)
{
    const gr_oiio_api *a = loaded(NULL);
    return a ? a->version() : "not loaded";
}

gr_status gr_oiio_read(const char *path, int linearize, gr_image **out, gr_error *err)
{
    return gr_oiio_read_info(path, linearize, out, NULL, err);
}

gr_status gr_oiio_read_info(const char *path, int linearize, gr_image **out, gr_oiio_info *info, gr_error *err)
{
    if (out) *out = NULL;
    if (info) memset(info, 0, sizeof *info);
    const gr_oiio_api *a = loaded(err);
    return a ? a->read_info(path, linearize, out, info, err) : GR_E_RUNTIME;
}

gr_status gr_oiio_write(const char *path, const gr_image *img, gr_error *err)
{
    const gr_oiio_api *a = loaded(err);
    return a ? a->write(path, img, err) : GR_E_RUNTIME;
}

gr_status gr_oiio_color_map(const gr_image *src, int channel, const char *map, gr_image **out, gr_error *err)
{
    if (out) *out = NULL;
    const gr_oiio_api *a = loaded(err);
    return a ? a->color_map(src, channel, map, out, err) : GR_E_RUNTIME;
}

gr_status gr_oiio_render_text(gr_image *img, int x, int y, const char *text, int size_px, const float rgb[3],
                              int align, gr_error *err)
{
    const gr_oiio_api *a = loaded(err);
    return a ? a->render_text(img, x, y, text, size_px, rgb, align, err) : GR_E_RUNTIME;
}

gr_status gr_oiio_write_animation(const char *path, const gr_image *const *frames, int n, double fps,
                                  gr_error *err)
{
    const gr_oiio_api *a = loaded(err);
    return a ? a->write_animation(path, frames, n, fps, err) : GR_E_RUNTIME;
}
