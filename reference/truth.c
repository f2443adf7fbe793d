/* The ground-truth provider (truth.h). */
#include "reference/truth.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "common/signals.h"
#include "reference/cache.h"
#include "reference/memory.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void gr_truth_options_default(gr_truth_options *o)
{
    memset(o, 0, sizeof *o);
    o->use_cache = 1;
    gr_ref_options_default(&o->ref);
    o->ref.progress = 0;
}

/* The cache holds whole renders with the integrator's defaults: anything else (a part, AOVs,
 * a test's switch) would be stored under a key that does not describe it. */
static int cacheable(const gr_ref_options *o)
{
    gr_ref_options d;
    gr_ref_options_default(&d);
    return o->fresnel == d.fresnel && o->force_beams == d.force_beams && o->aovs == d.aovs &&
           o->max_prims == d.max_prims && o->max_rounds == d.max_rounds && o->fixed_grid == d.fixed_grid &&
           o->lit_box_valid == d.lit_box_valid && o->full_column == d.full_column && o->row0 == d.row0 &&
           o->row1 == d.row1 && o->batch0 == d.batch0 &&
           o->batch1 == d.batch1 && o->keep_sums == d.keep_sums;
}

/* A renderer for scene and what its memory estimate needs (its info, its sets sampled:
 * reference/memory.h); nothing built yet */
static gr_status create_sampled(const gr_scene *scene, const gr_ref_options *o, gr_ref_renderer **r, gr_ref_info *info,
                                gr_error *err)
{
    gr_status st = gr_ref_create(scene, o, r, err);
    if (st != GR_OK) return st;
    gr_ref_get_info(*r, info);
    gr_ref_sample_sets(*r, info);
    return GR_OK;
}

/* Create, memory check, render in a held region, destroy. Building the scene and the beams'
 * lit region renders nothing yet and holds nothing to keep: a signal before the held region
 * ends the process at once (common/signals). */
static gr_status render(const gr_scene *scene, const gr_ref_options *opt, gr_ref_result *res, int *passes_per_round,
                        gr_error *err)
{
    gr_ref_options o = *opt;
    o.interrupt = gr_signals_flag(); /* SIGINT and SIGTERM (common/signals, installed by main) */
    gr_ref_renderer *r = NULL;
    gr_ref_info info;
    gr_status st = create_sampled(scene, &o, &r, &info, err);
    if (st != GR_OK) return st;
    *passes_per_round = info.passes_per_round;
    st = gr_ref_memory_check(scene, &info, err);
    if (st == GR_OK) {
        gr_signals_hold_begin(); /* the first signal only sets the flag; the renderer stops at its next check */
        st = gr_ref_render(r, res, err);
        gr_signals_hold_end();
    }
    gr_ref_destroy(r);
    return st;
}

/* The truth's surface-bias estimate from its metadata (-1 when absent or not a number). */
static double bias_of(const gr_metadata *m)
{
    const gr_meta_item *it = gr_meta_get(m, "godrays:bias_surface_rel_est");
    return it && it->type != GR_META_STRING && isfinite(it->num) ? it->num : -1.0;
}

/* The cache's part of gr_truth_get: *hit = 1 with res filled from a valid entry; else
 * info->cache_on, info->path, *key and *dir ready for the store, info->note set when the cache
 * is off or an entry was ignored. Only allocation failures and overlong names are errors. */
static gr_status look_up(const gr_scene *scene, gr_ref_result *res, gr_truth_info *info, char *dir, size_t dir_n,
                         char *key, int *hit, gr_error *err)
{
    *hit = 0;
    gr_error cerr = {GR_OK, ""};
    if (gr_cache_dir(dir, dir_n, &cerr) != GR_OK) {
        snprintf(info->note, sizeof info->note, "cache off: %.1300s", cerr.msg);
        return GR_OK;
    }
    gr_status st = gr_cache_key(scene, key, err);
    if (st == GR_OK) st = gr_cache_path(dir, key, info->path, sizeof info->path, err);
    if (st != GR_OK) return st;
    info->cache_on = 1;
    char why[1300] = "";
    st = gr_cache_load(dir, key, scene->camera.width, scene->camera.height, &res->image, &res->meta, hit, why,
                       sizeof why, err);
    if (st == GR_OK && !*hit && strstr(why, "ignored"))
        snprintf(info->note, sizeof info->note, "cache entry %s", why);
    return st;
}

gr_status gr_truth_get(const gr_scene *scene, const gr_truth_options *o, gr_ref_result *res, gr_truth_info *info,
                       gr_error *err)
{
    memset(res, 0, sizeof *res);
    gr_meta_init(&res->meta);
    memset(info, 0, sizeof *info);
    const double t0 = now_s();
    if (o->use_cache && !cacheable(&o->ref))
        return gr_fail(err, GR_E_USAGE, "the ground-truth cache holds whole renders with the default options only");
    char dir[4096], key[GR_CACHE_KEY_LEN + 1];
    gr_status st;
    if (o->use_cache) {
        int hit = 0;
        if ((st = look_up(scene, res, info, dir, sizeof dir, key, &hit, err)) != GR_OK) return st;
        if (hit) {
            info->cached = 1;
            info->seconds = now_s() - t0;
            info->bias_rel_est = bias_of(&res->meta);
            return GR_OK;
        }
    }
    if (o->before_render) o->before_render(o->user, scene, info);
    st = render(scene, &o->ref, res, &info->passes_per_round, err);
    if (st != GR_OK) {
        gr_ref_result_free(res);
        return st;
    }
    if (res->partial && !o->keep_partial) {
        gr_ref_result_free(res);
        return gr_fail(err, GR_E_INTERRUPTED, "interrupted while rendering the ground truth (this ground truth not cached)");
    }
    if (info->cache_on && !res->partial) {
        gr_error serr = {GR_OK, ""};
        /* a cache that cannot be written costs time later, not correctness now */
        if (gr_cache_store(dir, key, res->image, &res->meta, &serr) != GR_OK) {
            snprintf(info->note, sizeof info->note, "not cached: %.1300s", serr.msg);
            info->cache_on = 0;
            info->path[0] = '\0';
        } else {
            info->stored = 1;
        }
    }
    info->seconds = now_s() - t0;
    info->bias_rel_est = bias_of(&res->meta);
    return GR_OK;
}

int gr_truth_coarse(const gr_truth_info *info, const gr_scene *scene, char *msg, size_t n)
{
    if (!(info->bias_rel_est > GR_TRUTH_COARSE_BIAS)) return 0;
    if (msg && n > 0)
        snprintf(msg, n,
                 "its surface tessellation's bias is about %.2g %% of the image mean in the worst channel, so errors of "
                 "that size are not the technique's; a finer truth: reference.surface_res %d",
                 100.0 * info->bias_rel_est, 2 * scene->reference.surface_res);
    return 1;
}

gr_status gr_truth_image(const gr_scene *scene, const gr_truth_options *o, gr_image **img, gr_truth_info *info,
                         gr_error *err)
{
    gr_truth_options d;
    if (!o) {
        gr_truth_options_default(&d);
        o = &d;
    }
    gr_ref_result res;
    *img = NULL;
    gr_status st = gr_truth_get(scene, o, &res, info, err);
    if (st == GR_OK) {
        *img = res.image;
        res.image = NULL;
    }
    gr_ref_result_free(&res);
    return st;
}

gr_status gr_truth_memory(const gr_scene *scene, double *fixed, double *pixels, double *sets, gr_error *err)
{
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    gr_ref_renderer *r = NULL;
    gr_ref_info info;
    gr_status st = create_sampled(scene, &o, &r, &info, err);
    if (st != GR_OK) return st;
    gr_ref_memory_parts(scene, &info, fixed, pixels, sets);
    gr_ref_destroy(r);
    return GR_OK;
}

gr_status gr_truth_assemble(const gr_scene *scene, const gr_ref_sums *sums, double wall_s, gr_truth_sums_check check,
                            void *user, gr_ref_result *out, gr_error *err)
{
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    gr_ref_renderer *r = NULL;
    gr_status st = gr_ref_create(scene, &o, &r, err);
    if (st == GR_OK && check) {
        gr_ref_info info;
        gr_ref_get_info(r, &info);
        st = check(user, &info, err);
    }
    if (st == GR_OK) st = gr_ref_assemble(r, sums, wall_s, out, err);
    gr_ref_destroy(r);
    return st;
}

gr_status gr_truth_store(const gr_scene *scene, const gr_image *img, const gr_metadata *meta, gr_truth_info *info,
                         gr_error *err)
{
    memset(info, 0, sizeof *info);
    char dir[4096], key[GR_CACHE_KEY_LEN + 1];
    gr_status st = gr_cache_dir(dir, sizeof dir, err);
    if (st == GR_OK) st = gr_cache_key(scene, key, err);
    if (st == GR_OK) st = gr_cache_path(dir, key, info->path, sizeof info->path, err);
    if (st == GR_OK) st = gr_cache_store(dir, key, img, meta, err);
    if (st != GR_OK) {
        info->path[0] = '\0';
        return st;
    }
    info->cache_on = info->stored = 1;
    return GR_OK;
}
