#include "reference/bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/rng.h"
#include "reference/beams.h"
#include "reference/embree_scene.h"
#include "reference/integrator.h"

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Random occlusion rays from points in the lit volume toward random upward directions:
 * the kind of query the shadow rays make, without any of our own work around it. */
static double occluded_rate(RTCScene scene, const double box[6], int n)
{
    if (!scene) return 0.0;
    gr_rng g = gr_rng_make(42, 3, 0);
    int hits = 0;
    double t0 = mono_s();
    for (int i = 0; i < n; i++) {
        gr_vec3 o = gr_v3((float)(box[0] + (box[1] - box[0]) * gr_rng_double(&g)),
                          (float)(box[4] + (box[5] - box[4]) * gr_rng_double(&g)),
                          (float)(box[2] + (box[3] - box[2]) * gr_rng_double(&g)));
        double ph = 2.0 * 3.14159265358979323846 * gr_rng_double(&g), ct = gr_rng_double(&g), st = sqrt(1.0 - ct * ct);
        gr_vec3 d = gr_v3((float)(st * cos(ph)), (float)ct, (float)(st * sin(ph)));
        hits += gr_rtc_occluded(scene, o, d, 0.0f, 30.0f);
    }
    double dt = mono_s() - t0;
    (void)hits;
    return dt > 0.0 ? n / dt : 0.0;
}

gr_status gr_ref_bench(const gr_scene *s, gr_ref_bench_result *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    gr_ref_result res[2];
    memset(res, 0, sizeof res);
    gr_status st = GR_OK;
    for (int k = 0; k < 2 && st == GR_OK; k++) {
        gr_scene *sc = malloc(sizeof *sc);
        if (!sc) return gr_fail(err, GR_E_NOMEM, "bench: out of memory");
        *sc = *s;
        sc->reference.threads = k + 1;
        gr_ref_renderer *r = NULL;
        st = gr_ref_create(sc, &o, &r, err);
        if (st == GR_OK) st = gr_ref_render(r, &res[k], err);
        if (st == GR_OK) {
            out->qps[k] = res[k].queries_per_s;
            out->wall_s[k] = res[k].wall_s;
        }
        gr_ref_destroy(r);
        free(sc);
    }
    if (st == GR_OK) {
        out->speedup = out->wall_s[1] > 0.0 ? out->wall_s[0] / out->wall_s[1] : 0.0;
        out->frac_se_1pct = res[1].frac_se_1pct;
        size_t n = (size_t)res[0].image->width * res[0].image->height * res[0].image->nchannels * sizeof(float);
        out->identical = memcmp(res[0].image->pixels, res[1].image->pixels, n) == 0;
    }
    gr_ref_result_free(&res[0]);
    gr_ref_result_free(&res[1]);
    if (st != GR_OK) return st;

    /* raw Embree figures on the same scene: the occluders and the displaced surface mesh */
    gr_ref_renderer *r = NULL;
    st = gr_ref_create(s, &o, &r, err);
    if (st == GR_OK) st = gr_ref_prepare_pass(r, 0, err);
    if (st == GR_OK) {
        gr_ref_info info;
        gr_ref_get_info(r, &info);
        double box[6] = {info.region[0], info.region[1], info.region[2], info.region[3], info.region[4], 0.0};
        gr_rtc *rtc = NULL;
        gr_ref_geometry *geom = NULL;
        gr_dvec3 origin = gr_d3(s->camera.position_m[0], s->water.rest_height_m, s->camera.position_m[2]);
        st = gr_rtc_create(1, &rtc, err);
        if (st == GR_OK) st = gr_ref_geometry_create(rtc, s, origin, 100.0, &geom, err);
        if (st == GR_OK) {
            out->occluded_occluders_per_s = occluded_rate(geom->shadow, box, 2000000);
            out->occluded_surface_per_s = occluded_rate((RTCScene)gr_ref_surface_scene_ptr(r), box, 1000000);
            out->point_queries_per_s = gr_ref_lookup_rate(r, box, 1000000);
            out->beam_prims = (long long)info.prims;
            out->surface_triangles = gr_ref_surface_triangles(r);
        }
        gr_ref_geometry_destroy(geom);
        gr_rtc_destroy(rtc);
    }
    gr_ref_destroy(r);
    return st;
}
