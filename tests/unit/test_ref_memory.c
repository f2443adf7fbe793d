/* reference/memory: the ground truth's memory estimate and its check (docs/reliability.md,
 * "Memory"), against three oracles:
 *  1. the beam builds themselves: gr_beams_sample_prims (nothing built) must come within 8 %
 *     of the primitives gr_beams_build makes and gr_beams_entries_per_prim within -8 % and
 *     +25 % of its lookup grid's entries per primitive (above where the grid coarsens its cells), on gentle and steep waves, a high and a low sun,
 *     slabs of 0.5, 1 and 2 cells of drift, a set whose every cell is refined 3 x 3 (its drift
 *     in plain cells 3x larger) and one 100 m deep (slabs of 2 cells, long disc kernels);
 *  2. the byte counts written out by hand from the model's constants (memory.c);
 *  3. the operating system: what a render of the default scene's sets (2 passes, 16 x 9
 *     pixels) adds to the process's peak RSS (getrusage's ru_maxrss) must lie under the
 *     estimate's pixels and sets and above 0.6 of them. The old estimate (at most two
 *     primitives per cell: 0.11 GiB against 0.26-0.31 GB on the default scene) fails this.
 *     Skipped under the sanitizers, whose shadow memory is not the render's. */
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "check.h"
#include "common/memlimit.h"
#include "core/optics.h"
#include "reference/beam_grid.h"
#include "reference/embree_scene.h"
#include "reference/memory.h"
#include "scene/scene.h"
#include "test_ref_util.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define GR_TEST_SANITIZED 1
#else
#define GR_TEST_SANITIZED 0
#endif

/* the sampled count against a build's, for the beam parameters of scene s */
static void prims_against_build(gr_rtc *rtc, const char *label, const gr_scene *s, double slab_cells, int F, double y_min)
{
    gr_beam_params p;
    /* the refined set under the primitive budget (over it the build coarsens its slabs) */
    ref_beam_params(s, 3.0, y_min, F > 1 ? 32 : 96, slab_cells, &p);
    p.jitter[0] = 0.3;
    p.jitter[1] = 0.6;
    p.threads = 2;
    if (F > 1) { /* every cell refined: a radius far beyond the patch */
        p.refine_factor = F;
        p.refine_radius_m = 100.0;
        p.eye = gr_v3(0.0f, -1.0f, 0.0f);
    }
    gr_error err = {GR_OK, ""};
    gr_beams *b = NULL;
    CHECK_OK(gr_beams_build(rtc, &p, &b, &err), err);
    if (!b) exit(1);
    const gr_beam_stats *st = gr_beams_stats(b);
    gr_beam_prim_sample sm;
    gr_beams_sample_prims(&p, F, 32, &sm);
    double w = (double)st->triangles / sm.tris, est = w * sm.prims, entries = gr_beams_entries_per_prim(&sm, &w, 1);
    double built = (double)st->grid_entries / (double)st->prims;
    double rel = est / (double)st->prims - 1.0, rel_e = entries / built - 1.0;
    printf("%-36s %zu triangles, %zu primitives built, %.0f sampled (%+.1f %%); grid entries per primitive %.2f "
           "built, %.2f sampled (%+.1f %%)\n",
           label, st->triangles, st->prims, est, 100.0 * rel, built, entries, 100.0 * rel_e);
    CHECK_MSG(st->prims > st->triangles, "%s: %zu primitives for %zu triangles: no slabs, the check says nothing", label,
              st->prims, st->triangles);
    CHECK_MSG(fabs(rel) <= 0.08, "%s: the sampled primitives are %+.1f %% off the build's", label, 100.0 * rel);
    /* above, not below: where the grid has more cells than its budget allows it coarsens them,
     * and its boxes then meet fewer cells than the model's (1 + e / c)^3 */
    CHECK_MSG(rel_e >= -0.08 && rel_e <= 0.25, "%s: the sampled grid entries are %+.1f %% off the build's", label,
              100.0 * rel_e);
    gr_beams_destroy(b);
}

/* 3. the operating system's peak against the estimate, first in the process (nothing big
 * allocated before it) */
static void peak_against_estimate(void)
{
    gr_error err = {GR_OK, ""};
    gr_ref_info info;
    gr_memlimit_set(1e12);
    char path[4096];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", getenv("GODRAYS_SOURCE_DIR") ? getenv("GODRAYS_SOURCE_DIR") : ".");
    const char *dov[] = {"camera.width=16", "camera.height=9", "reference.batches=2", "reference.sun_samples=2",
                         "reference.bias_probe=false", "reference.threads=2"};
    gr_scene *d = ref_scene_file(path, dov, 6);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const double before = (double)ru.ru_maxrss * 1024.0;
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = 0;
    gr_ref_renderer *r = NULL;
    CHECK_OK(gr_ref_create(d, &opt, &r, &err), err);
    if (!r) exit(1);
    gr_ref_get_info(r, &info);
    gr_ref_sample_sets(r, &info);
    double fixed = 0.0, pixels = 0.0, sets = 0.0;
    gr_ref_memory_parts(d, &info, &fixed, &pixels, &sets);
    const double est = pixels + sets; /* the render's part: no preview's libraries here */
    gr_ref_result res;
    CHECK_OK(gr_ref_render(r, &res, &err), err);
    gr_ref_destroy(r);
    gr_ref_result_free(&res);
    getrusage(RUSAGE_SELF, &ru);
    const double peak = (double)ru.ru_maxrss * 1024.0 - before; /* what the render added */
    printf("default scene, 2 passes: the render added %.1f MB of peak RSS (%.1f MB before it), estimate %.1f MB\n",
           peak / 1e6, before / 1e6, est / 1e6);
    CHECK_MSG(peak <= est, "the render added %.1f MB, over its estimate of %.1f MB", peak / 1e6, est / 1e6);
    CHECK_MSG(peak >= 0.6 * est, "the render added %.1f MB, under 0.6 of its estimate of %.1f MB", peak / 1e6, est / 1e6);
    free(d);
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    /* 3. first: the process has allocated nothing big yet */
    if (GR_TEST_SANITIZED) printf("the peak against the estimate: skipped under the sanitizers\n");
    else peak_against_estimate();
    /* 1. sampled primitives against the builds */
    gr_rtc *rtc = NULL;
    CHECK_OK(gr_rtc_create(2, &rtc, &err), err);
    if (!rtc) return 1;
    gr_scene *gentle = ref_scene("{\"water\":{\"waves\":[{\"amplitude_m\":0.05,\"wavelength_m\":2,\"direction_deg\":0}]},"
                                 "\"sun\":{\"elevation_deg\":50,\"azimuth_deg\":20}}");
    gr_scene *steep = ref_scene("{" REF_DEFAULT_WAVES ",\"sun\":{\"elevation_deg\":20,\"azimuth_deg\":200}}");
    prims_against_build(rtc, "one gentle wave, sun 50 deg, slabs 0.5", gentle, 0.5, 1, -7.0);
    prims_against_build(rtc, "one gentle wave, sun 50 deg, slabs 2", gentle, 2.0, 1, -7.0);
    prims_against_build(rtc, "default waves, sun 20 deg, slabs 1", steep, 1.0, 1, -20.0);
    prims_against_build(rtc, "default waves, sun 20 deg, 3x3 refined", steep, 0.5, 3, -7.0);
    prims_against_build(rtc, "default waves, sun 20 deg, 100 m, slabs 2", steep, 2.0, 1, -100.0);
    gr_rtc_destroy(rtc);
    free(gentle);
    free(steep);

    /* 2. the model's bytes by hand: 4 x 2 pixels, 3 batches (3 x 28 + 16 + 32 = 132 B a pixel),
     * FIXED 144 MiB, SLACK 1.35; a set keeps per cell 2 x (128 + 85) + 40 = 466 B and per
     * primitive 4 + 10 B per grid entry (10 entries here: 104 B; 16 for the probe's finer near
     * set: 164 B), and its build adds 40 B a cell and 56 B a primitive; the sets are built in order
     * (plain, cone, near) and kept, so the peak is the largest of the kept ones plus the one
     * being built */
    gr_scene *s = calloc(1, sizeof *s);
    const char *ov[] = {"camera.width=4", "camera.height=2", "reference.batches=3", "reference.surface_res=10",
                        "reference.refine_factor=3"};
    CHECK_OK(gr_scene_load_string("{\"name\": \"m\"}", "t", ov, 5, s, &err), err);
    const double fixed = 144.0 * 1048576.0 + 8.0 * 132.0;
    gr_ref_info info;
    memset(&info, 0, sizeof info);
    info.plain_prims = 1000.0;
    info.plain_entries = info.cone_entries = info.near_entries = 10.0;
    info.probe_near_entries = 16.0;
    const double plain = 100.0 * 466.0 + 1000.0 * 104.0, plain_build = 100.0 * 40.0 + 1000.0 * 56.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), fixed + 1.35 * (plain + plain_build), 1e-6);
    /* a camera cone kept beside the plain set: its build on top of both */
    info.cone_cells = 50.0;
    info.cone_prims = 2000.0;
    const double cone = 50.0 * 466.0 + 2000.0 * 104.0, cone_build = 50.0 * 40.0 + 2000.0 * 56.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), fixed + 1.35 * (plain + cone + cone_build), 1e-6);
    /* a cone much smaller than the plain set: the plain set's own build is the peak */
    info.cone_prims = 10.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), fixed + 1.35 * (plain + plain_build), 1e-6);
    info.cone_prims = 2000.0;
    /* the near set and the probe's finer one in its place: the larger */
    info.near_cells = 70.0;
    info.near_prims = 500.0;
    info.near_factor = 3;
    info.near_radius_m = 8.5;
    info.probe_near_cells = 200.0;
    info.probe_near_prims = 3000.0;
    const double pnear = 200.0 * 466.0 + 3000.0 * 164.0, pnear_build = 200.0 * 40.0 + 3000.0 * 56.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), fixed + 1.35 * (plain + cone + pnear + pnear_build), 1e-6);
    double f = 0.0, px = 0.0, sets = 0.0;
    gr_ref_memory_parts(s, &info, &f, &px, &sets);
    CHECK_NEAR(f + px + sets, gr_ref_memory_estimate(s, &info), 1e-6);
    CHECK_NEAR(px, 8.0 * 132.0, 0.0);
    /* flat water: no set */
    info.flat = 1;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), fixed, 1e-6);
    info.flat = 0;
    /* the primitives stop at the budget of 2^24 per set */
    gr_ref_info big;
    memset(&big, 0, sizeof big);
    big.plain_prims = 1e9;
    big.plain_entries = 10.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &big), fixed + 1.35 * (100.0 * 506.0 + 16777216.0 * 160.0), 1e-3);

    gr_memlimit_set(1e12);
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_OK);
    gr_memlimit_set(1000.0);
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "the ground truth needs about") && strstr(err.msg, "4 x 2 pixels x 3 batches, surface_res 10") &&
                  strstr(err.msg, "refine_factor 3 (50 cells near the camera)") &&
                  strstr(err.msg, "near_factor 3 within 8.5 m of the camera (200 cells at the bias probe's 2x finer level)") &&
                  strstr(err.msg, "; beam sets 0.00 GiB for 6e+03 primitives") && strstr(err.msg, "--max-memory"),
              "message: %s", err.msg);
    free(s);

    CHECK_DONE();
}
