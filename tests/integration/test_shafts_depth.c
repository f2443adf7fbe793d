/* Acceptance (issue 12): `depth_test` hides the shafts behind the occluders as seen from the
 * eye. Flat water, sun at the zenith, a viewer 20 m deep looking straight up, shafts 10 m long
 * (depth 0..10 m) and a sphere of radius 1 m centred 3 m above the viewer: nothing of the
 * shafts lies between the eye and the sphere, so inside the sphere's silhouette (view rays
 * within 15 degrees of the axis; the sphere subtends asin(1/3) = 19.5 degrees) the truth has
 * no shaft light. There the seed variant's layer with depth_test must equal its bias-only
 * layer (intensity 0: bias x phase) exactly up to float rounding, while without depth_test it
 * is brighter (the seed draws shafts over occluders); the path and flux variants must be 0
 * there. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "realtime/shafts.h"
#include "scene/scene.h"

static const char *scene_json =
    "{\"name\": \"depth\", \"water\": {\"waves\": []},"
    "\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0},"
    "\"medium\": {\"absorption_per_m\": [0.04, 0.07, 0.11], \"scattering_per_m\": 0.01, \"g\": 0.5},"
    "\"camera\": {\"position_m\": [0, -20, 0], \"yaw_deg\": 0, \"pitch_deg\": 90, \"fov_deg\": 60,"
    "\"width\": 96, \"height\": 64},"
    "\"occluders\": [{\"type\": \"sphere\", \"center_m\": [0, -17, 0], \"radius_m\": 1}],"
    "\"shafts\": {\"N\": 11, \"K\": 0.8, \"shaft_length_m\": 10, \"target_format\": \"rgba16f\"}}";

static gr_image *render(gr_shafts *r, const char *const *sets, int n)
{
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    gr_image *img = gr_image_create(96, 64, 3, NULL);
    CHECK_OK(gr_scene_load_string(scene_json, "depth.json", sets, n, s, &err), err);
    CHECK_OK(gr_shafts_render(r, s, NULL, img, NULL, &err), err);
    free(s);
    return img;
}

int main(void)
{
    gr_error err = {0};
    gr_shafts *r = NULL;
    (void)gr_technique_count(); /* registers the built-in techniques' scene sections */
    CHECK_OK(gr_shafts_create(NULL, &r, &err), err);
    if (!r) CHECK_DONE();
    static const char *const s_on[] = {"shafts.depth_test=true"};
    static const char *const s_off[] = {"shafts.depth_test=false"};
    static const char *const s_bias[] = {"shafts.intensity=0"};
    static const char *const s_path[] = {"shafts.depth_test=true", "shafts.variant=path"};
    static const char *const s_path_off[] = {"shafts.variant=path"};
    static const char *const s_flux[] = {"shafts.depth_test=true", "shafts.variant=flux", "shafts.slabs=4"};
    gr_image *on = render(r, s_on, 1), *off = render(r, s_off, 1), *bias = render(r, s_bias, 1);
    gr_image *path = render(r, s_path, 2), *path_off = render(r, s_path_off, 1), *flux = render(r, s_flux, 3);
    const double tanh_ = tan(30.0 * 3.14159265358979323846 / 180.0), aspect = 96.0 / 64.0, lim = cos(15.0 * 3.14159265358979323846 / 180.0);
    int inside = 0;
    double max_dev = 0.0, sum_off = 0.0, sum_bias = 0.0, max_path = 0.0, sum_path_off = 0.0, max_flux = 0.0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 96; x++) {
            double u = (2.0 * (x + 0.5) / 96.0 - 1.0) * tanh_ * aspect, v = (1.0 - 2.0 * (y + 0.5) / 64.0) * tanh_;
            if (1.0 / sqrt(1.0 + u * u + v * v) < lim) continue;
            inside++;
            for (int c = 0; c < 3; c++) {
                size_t i = ((size_t)y * 96 + (size_t)x) * 3 + (size_t)c;
                double d = fabs(on->pixels[i] - bias->pixels[i]) / bias->pixels[i];
                if (d > max_dev) max_dev = d;
                sum_off += off->pixels[i];
                sum_bias += bias->pixels[i];
                if (fabs(path->pixels[i]) > max_path) max_path = fabs(path->pixels[i]);
                if (fabs(flux->pixels[i]) > max_flux) max_flux = fabs(flux->pixels[i]);
                sum_path_off += path_off->pixels[i];
            }
        }
    printf("%d pixels inside the silhouette: depth_test vs bias-only max rel dev %.2e; without depth_test "
           "%.3f x brighter; path max |value| %.3g (without depth_test mean %.3g), flux max |value| %.3g\n",
           inside, max_dev, sum_off / sum_bias, max_path, sum_path_off / (3.0 * inside), max_flux);
    CHECK(inside > 100);
    CHECK_MSG(max_dev < 1e-5, "shaft light inside the silhouette with depth_test: rel %.3g", max_dev);
    CHECK_MSG(sum_off > 1.5 * sum_bias, "without depth_test the shafts should show over the sphere");
    CHECK_MSG(max_path < 1e-4 * sum_path_off / (3.0 * inside), "path: shaft light inside the silhouette %.3g",
              max_path);
    CHECK_MSG(max_flux < 1e-4 * sum_path_off / (3.0 * inside), "flux: shaft light inside the silhouette %.3g",
              max_flux);
    gr_image_destroy(on), gr_image_destroy(off), gr_image_destroy(bias), gr_image_destroy(path),
        gr_image_destroy(path_off), gr_image_destroy(flux);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
