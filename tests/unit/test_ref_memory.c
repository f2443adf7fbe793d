/* reference/memory: the ground truth's memory estimate and its check (docs/reliability.md,
 * "Memory"), against the byte counts written out by hand:
 *  - 4 x 2 pixels, 3 batches, surface_res 10, no camera cone: per pixel 3 batches x (3 doubles
 *    + a uint32) + the two AOVs (16 B) + 8 image floats = 3 x 28 + 16 + 32 = 132 B; per surface
 *    cell 2 x 132 B of triangles + 80 B of vertex = 344 B, 2 beam primitives of 160 B each:
 *    8 x 132 + 100 x 344 + 200 x 160 = 67456 B;
 *  - a camera cone of 50 cells adds 50 x (344 + 2 x 160) B;
 *  - the primitives stop at the budget of 2^24 per set (surface_res 4096: 2 x 4096^2 > 2^24);
 *  - the check passes under a large limit and refuses under a small one with GR_E_INPUT and a
 *    message that names the size, the batches, surface_res and the cone. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "common/memlimit.h"
#include "reference/memory.h"
#include "scene/scene.h"

int main(void)
{
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err = {GR_OK, ""};
    const char *ov[] = {"camera.width=4", "camera.height=2", "reference.batches=3", "reference.surface_res=10",
                        "reference.refine_factor=3"};
    CHECK_OK(gr_scene_load_string("{\"name\": \"m\"}", "t", ov, 5, s, &err), err);
    gr_ref_info info;
    memset(&info, 0, sizeof info);
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), 8.0 * 132.0 + 100.0 * 344.0 + 200.0 * 160.0, 0.0);
    info.cone_cells = 50.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), 67456.0 + 50.0 * (344.0 + 320.0), 0.0);

    gr_scene *big = calloc(1, sizeof *big);
    const char *ob[] = {"camera.width=4", "camera.height=2", "reference.batches=3", "reference.surface_res=4096"};
    CHECK_OK(gr_scene_load_string("{\"name\": \"m\"}", "t", ob, 4, big, &err), err);
    info.cone_cells = 0.0;
    const double cells = 4096.0 * 4096.0;
    CHECK_NEAR(gr_ref_memory_estimate(big, &info), 8.0 * 132.0 + cells * 344.0 + 16777216.0 * 160.0, 0.0);

    gr_memlimit_set(1e12);
    info.cone_cells = 50.0;
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_OK);
    gr_memlimit_set(1000.0);
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "the ground truth needs about") && strstr(err.msg, "4 x 2 pixels x 3 batches, surface_res 10") &&
                  strstr(err.msg, "refine_factor 3 (50 cells near the camera)") && strstr(err.msg, "--max-memory"),
              "message: %s", err.msg);
    /* the set near the camera (docs/reference.md 2.2): its cells count like the others, and
     * the message names it */
    gr_memlimit_set(1e12);
    info.cone_cells = 0.0;
    info.near_cells = 70.0;
    info.near_factor = 3;
    info.near_radius_m = 8.5;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), 67456.0 + 70.0 * (344.0 + 320.0), 0.0);
    gr_memlimit_set(1000.0);
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "surface_res 10, near_factor 3 within 8.5 m of the camera (70 cells)"), "message: %s", err.msg);
    /* the bias probe's fourth level (docs/reference.md 4): its finer near set replaces the near
     * set for the probe's pixels, so the larger of the two counts, and the message says which */
    gr_memlimit_set(1e12);
    info.probe_near_cells = 200.0;
    CHECK_NEAR(gr_ref_memory_estimate(s, &info), 67456.0 + 200.0 * (344.0 + 320.0), 0.0);
    gr_memlimit_set(1000.0);
    CHECK(gr_ref_memory_check(s, &info, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "near_factor 3 within 8.5 m of the camera (200 cells at the bias probe's 2x finer level)"),
              "message: %s", err.msg);
    free(s);
    free(big);
    CHECK_DONE();
}
