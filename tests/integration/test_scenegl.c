/* Shared GL resources (src/realtime/scenegl.c) against closed forms:
 * - eye depth: the centre pixel of a camera looking at a sphere reads |C - E| - r (within the
 *   24 x 48 tessellation's sagitta), a pixel looking down at the seabed reads the ray-plane
 *   distance (E_y - y_bed) / (-d_y) for the scene's pixel ray d, the sky reads the far value;
 * - shadow map along the refracted sun (zenith sun: straight down): a point under a box is
 *   behind the stored depth, a point beside it sees the empty value 1, a point above it is in
 *   front; light_vp maps the box's top face centre to the texel that stores it;
 * - GPU timers give a non-negative time for a timed pass and -1 for an untimed one. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "gl/gl.h"
#include "realtime/scenegl.h"
#include "realtime/toolkit.h"

static gr_scene *load(const char *json)
{
    gr_error err;
    gr_scene *s = malloc(sizeof *s);
    if (!s || gr_scene_load_string(json, "test", NULL, 0, s, &err) != GR_OK) {
        fprintf(stderr, "scene: %s\n", s ? err.msg : "oom");
        exit(1);
    }
    return s;
}

static float *read_tex(unsigned tex, int w, int h, int depth)
{
    float *p = malloc((size_t)w * h * sizeof *p);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTexImage(GL_TEXTURE_2D, 0, depth ? GL_DEPTH_COMPONENT : GL_RED, GL_FLOAT, p);
    glBindTexture(GL_TEXTURE_2D, 0);
    return p;
}

int main(void)
{
    gr_error err;
    gr_gl *gl = NULL;
    if (gr_gl_create(NULL, &gl, &err) != GR_OK) {
        fprintf(stderr, "GL: %s\n", err.msg);
        return 1;
    }
    gr_scenegl *sg = NULL;
    CHECK_OK(gr_scenegl_create(gl, &sg, &err), err);
    if (!sg) return 1;

    const int W = 121, H = 81;
    gr_scene *s = load("{\"name\": \"sg\", \"water\": {\"waves\": []}, \"sun\": {\"elevation_deg\": 90},"
                       "\"camera\": {\"position_m\": [100, -8, 50], \"yaw_deg\": 0, \"pitch_deg\": -20, \"fov_deg\": 60,"
                       "\"width\": 121, \"height\": 81},"
                       "\"occluders\": [{\"type\": \"sphere\", \"center_m\": [100, -11.639702, 60], \"radius_m\": 2},"
                       "{\"type\": \"box\", \"center_m\": [0, -5, 0], \"size_m\": [2, 2, 2]}],"
                       "\"seabed\": {\"depth_m\": 25}}");
    gr_frame f;
    gr_frame_init(s, &f);
    gr_gl_timer tm;
    gr_gl_timer_init(&tm);
    unsigned tex = 0;
    gr_gl_timer_begin(&tm, 1);
    CHECK_OK(gr_scenegl_eye_depth(sg, s, &f, W, H, &tex, &err), err);
    gr_gl_timer_end(&tm);
    float *d = read_tex(tex, W, H, 0);
    /* The sphere centre lies on the centre pixel's ray: E + 10.642 (cos 20, -sin 20) in (z, y). */
    double dist_c = sqrt(10.0 * 10.0 + 3.639702 * 3.639702);
    double sag = 2.0 * (1.0 - cos(3.14159265358979 / 24));
    float centre = d[(size_t)(H / 2) * W + W / 2];
    printf("centre %.4f want %.4f (sagitta %.4f)\n", centre, dist_c - 2.0, sag);
    CHECK(centre >= dist_c - 2.0 - 1e-3 && centre <= dist_c - 2.0 + sag + 1e-3);
    /* Bottom row (GL row 0 = image bottom), left column: seabed. */
    {
        const gr_camera *c = &s->camera;
        double t = tan(30.0 * 3.14159265358979 / 180.0), a = (double)W / H;
        double sx = (2.0 * 0.5 / W - 1.0) * t * a, sy = (2.0 * (H - 0.5) / H - 1.0) * t, r[3];
        for (int k = 0; k < 3; k++) r[k] = c->forward[k] + sx * c->right[k] - sy * c->up[k];
        double l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        double want = (-8.0 + 25.0) / (-r[1] / l);
        printf("seabed %.4f want %.4f\n", d[0], want);
        CHECK_REL(d[0], want, 1e-4);
    }
    /* Top row: water above, nothing hit. */
    CHECK_NEAR(d[(size_t)(H - 1) * W + 0], GR_FRAME_FAR_M, 0);
    free(d);
    long long ns = gr_gl_timer_ns(&tm, 1);
    CHECK(ns >= 0);
    CHECK(gr_gl_timer_ns(&tm, 0) == -1);
    gr_gl_timer_free(&tm);

    /* Shadow map, zenith sun: refr_dir = (0, -1, 0). */
    const int S = 64;
    double centre3[3] = {0, -5, 0}, lvp[16];
    CHECK_OK(gr_scenegl_shadow_map(sg, s, &f, S, centre3, 5.0, &tex, lvp, &err), err);
    float *sm = read_tex(tex, S, S, 1);
    struct { double p[3]; int expect; } pts[] = {
        {{0.3, -10, 0.2}, 1},  /* under the box: shadowed */
        {{3.5, -10, 0}, 0},    /* beside it: nothing stored */
        {{0, -3.5, 0}, 0},     /* above the top face (y = -4): in front of it */
    };
    for (int i = 0; i < 3; i++) {
        double in[4] = {pts[i].p[0], pts[i].p[1], pts[i].p[2], 1}, c[4];
        gr_mat4_apply(lvp, in, c);
        int tx = (int)floor((0.5 * c[0] / c[3] + 0.5) * S), ty = (int)floor((0.5 * c[1] / c[3] + 0.5) * S);
        double depth = 0.5 * c[2] / c[3] + 0.5;
        float stored = (tx >= 0 && tx < S && ty >= 0 && ty < S) ? sm[(size_t)ty * S + tx] : 1.0f;
        int shadowed = depth > stored + 1e-5;
        printf("point %d: depth %.4f stored %.4f\n", i, depth, stored);
        CHECK(shadowed == pts[i].expect);
        if (i == 1) CHECK_NEAR(stored, 1.0, 0);
    }
    /* The top face centre (0, -4, 0) is what the centre texel stores. */
    {
        double in[4] = {0, -4, 0, 1}, c[4];
        gr_mat4_apply(lvp, in, c);
        int tx = (int)floor((0.5 * c[0] + 0.5) * S), ty = (int)floor((0.5 * c[1] + 0.5) * S);
        CHECK_NEAR(sm[(size_t)ty * S + tx], 0.5 * c[2] + 0.5, 1e-5);
    }
    free(sm);
    CHECK_OK(gr_gl_check("test", &err), err);
    free(s);
    gr_scenegl_destroy(sg);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
