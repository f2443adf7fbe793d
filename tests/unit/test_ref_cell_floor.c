/* The cells' floor (docs/reference.md 2.2): a small lit patch would get cells of
 * sqrt(area) / surface_res, far finer than the waves need; reference.cells_per_radius keeps
 * them no narrower than R_min / 8, R_min = (1 - Q)^2 / sum a_i k_i^2.
 * (a) The default scene's view has a wide patch: the floor leaves surface_res at 256 (its
 *     bytes are those without the floor).
 * (b) A diver 1.5 m deep looking up with a 10-degree field of view: the floor lowers
 *     surface_res, the beam primitives fall at least 3x, and the image's mean in each
 *     channel agrees with a render without the floor (another seed) within the two renders'
 *     error bars and reported tessellation bias.
 * Oracle 3's focus depth at the floor's cells is checked in test_ref_focus.c. */
#include "check.h"
#include "test_ref_util.h"

#include "core/gerstner.h"

static gr_scene *diver(int floor_on, int seed)
{
    return ref_scene("{" REF_DEFAULT_WAVES ",\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30}," REF_DEFAULT_MEDIUM ","
                     "\"camera\":{\"position_m\":[0,-1.5,0],\"yaw_deg\":30,\"pitch_deg\":85,\"fov_deg\":10,"
                     "\"width\":32,\"height\":18},"
                     "\"reference\":{\"cells_per_radius\":%d,\"seed\":%d}}",
                     floor_on ? 8 : 0, seed);
}

/* per channel: the image mean, its standard error (pixels independent) and the render's
 * reported tessellation bias (bias_surface_rel of the mean) */
static void image_stats(const gr_ref_result *res, double mean[3], double se[3], double *bias_rel)
{
    const gr_image *im = res->image;
    size_t n = (size_t)im->width * im->height;
    for (int c = 0; c < 3; c++) {
        double m = 0.0, v = 0.0;
        for (size_t p = 0; p < n; p++) {
            m += im->pixels[p * im->nchannels + c];
            double s = im->pixels[p * im->nchannels + 3 + c];
            v += s * s;
        }
        mean[c] = m / n;
        se[c] = sqrt(v) / n;
    }
    *bias_rel = res->bias_surface_rel;
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;

    /* (a) the default scene */
    char path[4096];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", getenv("GODRAYS_SOURCE_DIR") ? getenv("GODRAYS_SOURCE_DIR") : ".");
    const char *ov[] = {"camera.width=64", "camera.height=36"};
    gr_scene *d = ref_scene_file(path, ov, 2);
    gr_ref_renderer *r = NULL;
    CHECK_OK(gr_ref_create(d, &o, &r, &err), err);
    gr_ref_info info;
    gr_ref_get_info(r, &info);
    double Q = gr_gerstner_steepness(&d->water), hmin = (1.0 - Q) * (1.0 - Q) / gr_gerstner_curvature_sum(&d->water) / 8.0;
    double ext = sqrt((info.region[1] - info.region[0] + 2.0 * info.region[5]) * (info.region[3] - info.region[2] + 2.0 * info.region[5]));
    printf("default view: patch %.2f m, cells %.4f m at surface_res 256, floor %.4f m: surface_res used %d\n", ext, ext / 256.0,
           hmin, info.surface_res);
    CHECK(info.surface_res == 256);
    CHECK(ext / 256.0 > hmin);
    gr_ref_destroy(r);
    free(d);

    /* (b) the diver looking up: with and without the floor */
    gr_scene *sf = diver(1, 1), *so = diver(0, 2);
    gr_ref_renderer *rf = NULL, *ro = NULL;
    CHECK_OK(gr_ref_create(sf, &o, &rf, &err), err);
    CHECK_OK(gr_ref_create(so, &o, &ro, &err), err);
    gr_ref_info inf, ino;
    gr_ref_get_info(rf, &inf);
    gr_ref_get_info(ro, &ino);
    gr_ref_destroy(rf);
    gr_ref_destroy(ro);
    gr_ref_result a, b;
    ref_render(sf, &o, &a);
    ref_render(so, &o, &b);
    long long pa = (long long)gr_meta_get(&a.meta, "godrays:beam_prims")->num, pb = (long long)gr_meta_get(&b.meta, "godrays:beam_prims")->num;
    printf("diver: surface_res %d with the floor, %d without; beam primitives %lld and %lld (%.1fx)\n", inf.surface_res,
           ino.surface_res, pa, pb, (double)pb / (double)pa);
    CHECK(inf.surface_res < 256 && inf.surface_res >= 64);
    CHECK(ino.surface_res == 256);
    CHECK(gr_meta_get(&a.meta, "godrays:surface_res_used")->num == inf.surface_res);
    CHECK(gr_meta_get(&a.meta, "godrays:reference.surface_res")->num == 256); /* the setting as given */
    CHECK(3 * pa <= pb);
    double ma[3], sa[3], ba, mb[3], sb[3], bb;
    image_stats(&a, ma, sa, &ba);
    image_stats(&b, mb, sb, &bb);
    CHECK(ba >= 0.0 && bb >= 0.0);
    for (int c = 0; c < 3; c++) {
        double d_ = ma[c] - mb[c], tol = 3.0 * sqrt(sa[c] * sa[c] + sb[c] * sb[c]) + (ba * ma[c] + bb * mb[c]);
        printf("channel %d: mean %.6g with the floor, %.6g without (%+.4f%%), allowed %.4f%% (stderr %.4f%%, %.4f%%; bias %.4f%%, "
               "%.4f%%)\n", c, ma[c], mb[c], 100.0 * d_ / mb[c], 100.0 * tol / mb[c], 100.0 * sa[c] / ma[c], 100.0 * sb[c] / mb[c],
               100.0 * ba, 100.0 * bb);
        CHECK_MSG(fabs(d_) <= tol, "channel %d: %g against %g, allowed %g", c, ma[c], mb[c], tol);
    }
    gr_ref_result_free(&a);
    gr_ref_result_free(&b);
    free(sf);
    free(so);
    CHECK_DONE();
}
