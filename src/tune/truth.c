/* Ground truth through the cache (truth.h). */
#include "tune/truth.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "reference/integrator.h"
#include "report/cache.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static gr_status render(const gr_scene *scene, int progress, gr_image **img, gr_metadata *meta, gr_error *err)
{
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = progress;
    gr_ref_renderer *r = NULL;
    gr_status st = gr_ref_create(scene, &opt, &r, err);
    if (st != GR_OK) return st;
    gr_ref_result res;
    st = gr_ref_render(r, &res, err);
    gr_ref_destroy(r);
    if (st != GR_OK) return st;
    if (res.partial) {
        gr_ref_result_free(&res);
        return gr_fail(err, GR_E_INTERRUPTED, "interrupted while rendering the ground truth");
    }
    *img = res.image;
    res.image = NULL;
    if (meta) {
        gr_meta_free(meta);
        *meta = res.meta; /* hand the items over */
        gr_meta_init(&res.meta);
    }
    gr_ref_result_free(&res);
    return GR_OK;
}

gr_status gr_truth_render(const gr_scene *scene, int progress, gr_image **img, double *seconds, gr_error *err)
{
    double t0 = now_s();
    gr_status st = render(scene, progress, img, NULL, err);
    if (seconds) *seconds = now_s() - t0;
    return st;
}

gr_status gr_truth_get(const gr_scene *scene, int use_cache, int progress, gr_image **img, gr_truth_info *info,
                       gr_error *err)
{
    memset(info, 0, sizeof *info);
    *img = NULL;
    double t0 = now_s();
    char dir[4096], key[GR_CACHE_KEY_LEN + 1];
    int cache_on = 0;
    gr_status st;
    gr_metadata meta;
    gr_meta_init(&meta);
    if (use_cache) {
        gr_error cerr = {GR_OK, ""};
        if (gr_cache_dir(dir, sizeof dir, &cerr) != GR_OK) {
            snprintf(info->note, sizeof info->note, "cache off: %.1000s", cerr.msg);
        } else {
            if ((st = gr_cache_key(scene, key, err)) != GR_OK) return st;
            if ((st = gr_cache_path(dir, key, info->path, sizeof info->path, err)) != GR_OK) return st;
            cache_on = 1;
            char why[1100] = "";
            st = gr_cache_load(dir, key, scene->camera.width, scene->camera.height, img, &meta, &info->cached, why,
                               sizeof why, err);
            if (st != GR_OK) {
                gr_meta_free(&meta);
                return st;
            }
            if (info->cached) {
                gr_meta_free(&meta);
                info->seconds = now_s() - t0;
                return GR_OK;
            }
            if (strstr(why, "ignored")) snprintf(info->note, sizeof info->note, "%s", why);
        }
    }
    st = render(scene, progress, img, &meta, err);
    if (st == GR_OK && cache_on) {
        gr_error serr = {GR_OK, ""};
        /* a cache that cannot be written costs time later, not correctness now */
        if (gr_cache_store(dir, key, *img, &meta, &serr) != GR_OK)
            snprintf(info->note, sizeof info->note, "not cached: %.1000s", serr.msg);
        else
            info->stored = 1;
    }
    if (!cache_on) info->path[0] = '\0';
    gr_meta_free(&meta);
    info->seconds = now_s() - t0;
    return st;
}
