/* The shaft vertex shader (read back by transform feedback) against the core library's CPU
 * evaluation in double of seed eqs. 5.5.5 (P), 5.5.6 (S), 5.5.7 (Gerstner position),
 * 5.5.8 (normal), 5.5.1 (refraction), 5.5.2 (Schlick) and 5.5.3 (attenuation): every vertex
 * within 1e-4 m, every intensity within 1e-4. Also far from the world origin and at a large
 * time, where a naive float evaluation of the wave phase would fail. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/gerstner.h"
#include "core/optics.h"
#include "core/shaftgeom.h"
#include "shafts_test.h"

static const char *scene_json =
    "{\"name\": \"vertex\", \"water\": {\"time_s\": 3.7, \"waves\": ["
    "{\"amplitude_m\": 0.115, \"wavelength_m\": 12, \"direction_deg\": 40, \"phase_rad\": 0},"
    "{\"amplitude_m\": 0.079, \"wavelength_m\": 9, \"direction_deg\": 25, \"phase_rad\": 1.3},"
    "{\"amplitude_m\": 0.056, \"wavelength_m\": 7, \"direction_deg\": 58, \"phase_rad\": 2.9},"
    "{\"amplitude_m\": 0.044, \"wavelength_m\": 5.5, \"direction_deg\": 32, \"phase_rad\": 4.4},"
    "{\"amplitude_m\": 0.029, \"wavelength_m\": 4, \"direction_deg\": 70, \"phase_rad\": 0.7},"
    "{\"amplitude_m\": 0.021, \"wavelength_m\": 3, \"direction_deg\": 12, \"phase_rad\": 3.6},"
    "{\"amplitude_m\": 0.014, \"wavelength_m\": 2.2, \"direction_deg\": 50, \"phase_rad\": 5.5},"
    "{\"amplitude_m\": 0.008, \"wavelength_m\": 1.5, \"direction_deg\": 85, \"phase_rad\": 2.2},"
    "{\"amplitude_m\": 0.03, \"wavelength_m\": 2.7, \"direction_deg\": 140, \"phase_rad\": 1.0}]},"
    "\"sun\": {\"elevation_deg\": 50, \"azimuth_deg\": 120},"
    "\"medium\": {\"absorption_per_m\": [0.3, 0.06, 0.03], \"scattering_per_m\": 0.03, \"g\": 0.8},"
    "\"camera\": {\"position_m\": [3, -12, -4], \"yaw_deg\": 100, \"pitch_deg\": 40, \"fov_deg\": 55,"
    "\"width\": 64, \"height\": 36},"
    "\"shafts\": {\"N\": 9, \"K\": 0.7, \"shaft_width\": 0.6, \"shaft_length_m\": 25}}";

static void check_scene(gr_shafts *r, const gr_scene *s, const char *label)
{
    gr_error err;
    gr_shafts_vertex *v = NULL;
    gr_shafts_stats st;
    int n = 0;
    CHECK_OK(gr_shafts_capture(r, s, NULL, &v, &n, &st, &err), err);
    if (!v) return;
    const gr_shafts_settings *sh = gr_shafts_scene_settings(s);
    CHECK(n == 8 * (sh->N - 1) * (sh->N - 1));

    /* Eq. 5.5.5 and 5.5.6 in closed form: P on the rest plane, P - E parallel to T. */
    gr_dvec3 E = gr_d3(s->camera.position_m[0], s->camera.position_m[1], s->camera.position_m[2]);
    gr_dvec3 I = gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]);
    double h0 = s->water.rest_height_m, ior = s->medium.ior;
    gr_dvec3 T;
    gr_dvec3 P = gr_shafts_center(E, I, h0, ior, &T);
    CHECK_NEAR(st.center[0], P.x, 1e-9);
    CHECK_NEAR(st.center[1], h0, 1e-9);
    CHECK_NEAR(st.center[2], P.z, 1e-9);
    gr_dvec3 pe = gr_d3_sub(P, E);
    CHECK_NEAR(gr_d3_len(gr_d3_cross(pe, T)), 0.0, 1e-9 * gr_d3_len(pe));
    double d = h0 - E.y, fov = s->camera.fov_deg * GR_PI / 180.0;
    CHECK_REL(st.spacing_m, sh->K * 2.0 * d * tan(0.5 * fov) / sh->N, 1e-12);

    double max_pos = 0.0, max_int = 0.0, r0 = gr_fresnel_r0(1.0, ior);
    int n_bottom = 0;
    for (int i = 0; i < n; i++) {
        double x0 = P.x + st.spacing_m * (v[i].cell[0] + v[i].corner[0] * sh->shaft_width);
        double z0 = P.z + st.spacing_m * (v[i].cell[1] + v[i].corner[1] * sh->shaft_width);
        double t = s->water.time_s;
        gr_dvec3 p = gr_gerstner_position(&s->water, x0, z0, t), nrm;
        gr_gerstner_frame(&s->water, x0, z0, t, NULL, NULL, &nrm);
        double len = 0.0;
        if (v[i].bottom) {
            len = sh->shaft_length_m;
            p = gr_d3_madd(p, gr_refract_d(I, nrm, 1.0 / ior), len);
            n_bottom++;
        }
        double tr = 1.0 - gr_fresnel_schlick(gr_d3_dot(gr_d3_scale(I, -1.0), nrm), r0);
        double dist = len + gr_d3_len(gr_d3_sub(p, E));
        double e = fmax(fabs(p.x - v[i].pos[0]), fmax(fabs(p.y - v[i].pos[1]), fabs(p.z - v[i].pos[2])));
        if (e > max_pos) max_pos = e;
        for (int c = 0; c < 3; c++) {
            double want = exp(-sh->extinction[c] * dist) * tr;
            double ei = fabs(want - v[i].intensity[c]);
            if (ei > max_int) max_int = ei;
        }
    }
    printf("%s: %d vertices, max |pos error| %.3g m, max |intensity error| %.3g\n", label, n, max_pos, max_int);
    CHECK(n_bottom == n / 2);
    CHECK_MSG(max_pos <= 1e-4, "%s: vertex position error %.3g m", label, max_pos);
    CHECK_MSG(max_int <= 1e-4, "%s: intensity error %.3g", label, max_int);
    free(v);
}

int main(void)
{
    gr_shafts *r = shafts_test_renderer();
    gr_scene *s = shafts_test_scene(scene_json, NULL, 0);
    check_scene(r, s, "near origin");

    /* 5 km from the origin at t = 1234.5 s: positions are viewer-relative and the phase
     * constant is folded mod 2 pi in double, so float keeps the same accuracy. */
    static const char *const far_sets[] = {"camera.position_m=[5000, -15, -3000]", "water.time_s=1234.5"};
    gr_scene *far = shafts_test_scene(scene_json, far_sets, 2);
    check_scene(r, far, "far from origin");

    /* A different N and width in the same renderer (buffers rebuilt, programs kept). */
    static const char *const n_sets[] = {"shafts.N=4", "shafts.shaft_width=1"};
    gr_scene *s4 = shafts_test_scene(scene_json, n_sets, 2);
    check_scene(r, s4, "N = 4");

    free(s);
    free(far);
    free(s4);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
