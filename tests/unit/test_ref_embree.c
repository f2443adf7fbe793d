/* The Embree layer of the ground truth: errors reported by Embree arrive as one-line
 * gr_errors (GR_E_EMBREE, the operation named); ray ends against a box (rotated by yaw) and
 * a sphere match their analytic distances; a scene 1e5 m from the origin gives the same
 * distances (local frame); the shadow rays' bundle prefilter never clears an occluded bundle;
 * bad settings are refused with the setting named. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include <string.h>
#include "core/rng.h"
#include "reference/embree_scene.h"

/* The bundle prefilter (gr_ref_shadow_near) against Embree: random points around the two
 * occluders, random bundles of unit directions within a cone around an axis d; whenever the
 * prefilter answers 0, no ray of the bundle may be occluded (traced by Embree, the oracle),
 * and it must answer 0 for some bundles and 1 for bundles that are occluded. */
static void bundles(const gr_ref_geometry *g)
{
    gr_rng rng = gr_rng_make(7, 1, 0);
    int zero = 0, occluded = 0, missed = 0;
    for (int k = 0; k < 4000; k++) {
        gr_vec3 x = gr_v3((float)(-6.0 + 20.0 * gr_rng_double(&rng)), (float)(-16.0 + 12.0 * gr_rng_double(&rng)),
                          (float)(-6.0 + 22.0 * gr_rng_double(&rng)));
        double ph = 2.0 * 3.14159265358979 * gr_rng_double(&rng), ct = 2.0 * gr_rng_double(&rng) - 1.0, st = sqrt(1.0 - ct * ct);
        gr_vec3 d = gr_v3((float)(st * cos(ph)), (float)ct, (float)(st * sin(ph)));
        float L = (float)(12.0 * gr_rng_double(&rng)), cone = (float)(0.3 * gr_rng_double(&rng));
        gr_vec3 dirs[8];
        float lens[8], spread = 0.0f;
        for (int i = 0; i < 8; i++) {
            gr_vec3 e = gr_v3((float)(gr_rng_double(&rng) - 0.5), (float)(gr_rng_double(&rng) - 0.5), (float)(gr_rng_double(&rng) - 0.5));
            dirs[i] = gr_v3_norm(gr_v3_madd(d, e, cone));
            lens[i] = L * (float)gr_rng_double(&rng);
            gr_vec3 dd = gr_v3_sub(dirs[i], d);
            float s = L * sqrtf(gr_v3_dot(dd, dd));
            spread = s > spread ? s : spread;
        }
        int near = gr_ref_shadow_near(g, x, d, L, spread), any = 0;
        for (int i = 0; i < 8; i++) any |= gr_rtc_occluded(g->shadow, x, dirs[i], 0.0f, lens[i]);
        zero += !near;
        occluded += any;
        missed += !near && any;
    }
    CHECK_MSG(missed == 0, "the bundle prefilter answered 0 for %d occluded bundles", missed);
    CHECK_MSG(zero > 400 && occluded > 50, "a test that can fail: %d bundles cleared, %d occluded", zero, occluded);
}

static void distances(double off)
{
    gr_scene *s = ref_scene(
        "{\"water\":{\"waves\":[]},\"camera\":{\"position_m\":[%.17g,-10,%.17g]},"
        "\"occluders\":[{\"type\":\"box\",\"center_m\":[%.17g,-5,%.17g],\"size_m\":[2,2,4],\"yaw_deg\":90},"
        "{\"type\":\"sphere\",\"center_m\":[%.17g,-10,%.17g],\"radius_m\":1.5}],\"seabed\":{\"depth_m\":30}}",
        off, off, off, off + 10.0, off + 8.0, off);
    gr_rtc *rtc = NULL;
    gr_ref_geometry *g = NULL;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_rtc_create(1, &rtc, &err), err);
    gr_dvec3 origin = gr_d3(off, 0.0, off);
    CHECK_OK(gr_ref_geometry_create(rtc, s, origin, 100.0, &g, &err), err);
    if (g) {
        /* box at local (0, -5, 10), extents 2 x 2 x 4 turned by 90 deg: x half 2, z half 1 */
        float t = gr_rtc_intersect(g->ends, gr_v3(0, -5, 0), gr_v3(0, 0, 1), 0.0f, 1e3f, NULL, NULL);
        CHECK_NEAR(t, 9.0, 1e-4);
        t = gr_rtc_intersect(g->ends, gr_v3(-5, -5, 10), gr_v3(1, 0, 0), 0.0f, 1e3f, NULL, NULL);
        CHECK_NEAR(t, 3.0, 1e-4);
        /* sphere at local (8, -10, 0), r 1.5 */
        t = gr_rtc_intersect(g->ends, gr_v3(0, -10, 0), gr_v3(1, 0, 0), 0.0f, 1e3f, NULL, NULL);
        CHECK_NEAR(t, 6.5, 1e-4);
        /* seabed at y = -30 */
        t = gr_rtc_intersect(g->ends, gr_v3(0, -10, 0), gr_v3(0, -1, 0), 0.0f, 1e3f, NULL, NULL);
        CHECK_NEAR(t, 20.0, 1e-4);
        CHECK(gr_rtc_occluded(g->shadow, gr_v3(0, -10, 0), gr_v3(1, 0, 0), 0.0f, 7.0f) == 1);
        CHECK(gr_rtc_occluded(g->shadow, gr_v3(0, -10, 0), gr_v3(1, 0, 0), 0.0f, 6.0f) == 0);
        CHECK(gr_rtc_occluded(g->shadow, gr_v3(0, -10, 0), gr_v3(0, -1, 0), 0.0f, 100.0f) == 0); /* seabed is no caster */
        bundles(g);
    }
    gr_ref_geometry_destroy(g);
    gr_rtc_destroy(rtc);
    free(s);
}

int main(void)
{
    distances(0.0);
    distances(1e5);

    gr_rtc *rtc = NULL;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_rtc_create(0, &rtc, &err), err);
    if (rtc) {
        CHECK(gr_rtc_check(rtc, "nothing", &err) == GR_OK);
        /* an invalid operation: a user primitive count on a triangle mesh */
        RTCGeometry geo = rtcNewGeometry(rtc->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryUserPrimitiveCount(geo, 3);
        rtcReleaseGeometry(geo);
        gr_status st = gr_rtc_check(rtc, "test op", &err);
        CHECK(st == GR_E_EMBREE);
        CHECK_MSG(strstr(err.msg, "test op: Embree error") != NULL && !strchr(err.msg, '\n'), "message: %s", err.msg);
        CHECK(gr_rtc_check(rtc, "again", &err) == GR_OK); /* cleared */
    }
    gr_rtc_destroy(rtc);
    gr_rtc_destroy(NULL);
    gr_ref_geometry_destroy(NULL);
    gr_ref_destroy(NULL);
    gr_ref_result_free(NULL);

    /* the scene loader refuses batches < 2 now; the integrator must too (a scene built in code) */
    gr_scene *s = ref_scene("{\"water\":{\"waves\":[]}}");
    s->reference.batches = 1;
    gr_ref_renderer *r = NULL;
    gr_ref_options o;
    gr_ref_options_default(&o);
    CHECK(gr_ref_create(s, &o, &r, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "reference.batches") != NULL, "message: %s", err.msg);
    CHECK(r == NULL);
    free(s);
    CHECK_DONE();
}
