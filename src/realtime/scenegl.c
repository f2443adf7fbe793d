/* Shared GL resources of the real-time techniques (see scenegl.h). The occluder mesh is the
 * one src/realtime/shafts.c builds (boxes: 12 triangles with the scene's yaw convention;
 * spheres: 24 stacks x 48 slices), kept in double on the CPU and uploaded relative to each
 * pass's origin so float keeps precision far from the world origin. */
#include "realtime/scenegl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "core/vec.h"
#include "gl/gl.h"
#include "realtime/shaders.h"
#include "realtime/toolkit.h"

#define SPHERE_STACKS 24
#define SPHERE_SLICES 48

struct gr_scenegl {
    gr_gl *gl;
    GLuint prog_shadow, prog_depth, prog_seabed;
    GLint loc_shadow_mvp, loc_depth_mvp, loc_seabed_inv, loc_seabed_rel, loc_seabed_far;
    GLuint vao_occ, vbo_occ, vao_empty;
    double *mesh;     /* world positions, 3 doubles per vertex */
    size_t mesh_n, mesh_cap;
    float *upload;
    size_t upload_cap;
    gr_target shadow, depth; /* the shadow map (depth), the eye depth (R32F) */
};

gr_status gr_scenegl_create(gr_gl *gl, gr_scenegl **out, gr_error *err)
{
    return gr_scenegl_create_dir(gl, NULL, out, err);
}

gr_status gr_scenegl_create_dir(gr_gl *gl, const char *shader_dir, gr_scenegl **out, gr_error *err)
{
    gr_status st;
    *out = NULL;
    gr_scenegl *s = calloc(1, sizeof *s);
    if (!s) return gr_fail(err, GR_E_NOMEM, "scene GL resources: out of memory");
    s->gl = gl;
    if ((st = gr_shader_program(shader_dir, "scenegl_occ.vert.glsl", "scenegl_shadow.frag.glsl", NULL, 0,
                                &s->prog_shadow, NULL, err)) != GR_OK)
        goto fail;
    if ((st = gr_shader_program(shader_dir, "scenegl_occ.vert.glsl", "scenegl_depth.frag.glsl", NULL, 0,
                                &s->prog_depth, NULL, err)) != GR_OK)
        goto fail;
    if ((st = gr_shader_program(shader_dir, "scenegl_seabed.vert.glsl", "scenegl_seabed.frag.glsl", NULL, 0,
                                &s->prog_seabed, NULL, err)) != GR_OK)
        goto fail;
    s->loc_shadow_mvp = glGetUniformLocation(s->prog_shadow, "u_mvp");
    s->loc_depth_mvp = glGetUniformLocation(s->prog_depth, "u_mvp");
    s->loc_seabed_inv = glGetUniformLocation(s->prog_seabed, "u_inv_vp_rot");
    s->loc_seabed_rel = glGetUniformLocation(s->prog_seabed, "u_seabed_rel");
    s->loc_seabed_far = glGetUniformLocation(s->prog_seabed, "u_far");
    glGenVertexArrays(1, &s->vao_occ);
    glGenBuffers(1, &s->vbo_occ);
    glGenVertexArrays(1, &s->vao_empty);
    glBindVertexArray(s->vao_occ);
    glBindBuffer(GL_ARRAY_BUFFER, s->vbo_occ);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, (GLsizei)(3 * sizeof(float)), (const void *)0);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    if ((st = gr_gl_check("scene GL resources setup", err)) != GR_OK) goto fail;
    *out = s;
    return GR_OK;
fail:
    gr_scenegl_destroy(s);
    return st;
}

void gr_scenegl_destroy(gr_scenegl *s)
{
    if (!s) return;
    if (s->prog_shadow) glDeleteProgram(s->prog_shadow);
    if (s->prog_depth) glDeleteProgram(s->prog_depth);
    if (s->prog_seabed) glDeleteProgram(s->prog_seabed);
    if (s->vao_occ) glDeleteVertexArrays(1, &s->vao_occ);
    if (s->vbo_occ) glDeleteBuffers(1, &s->vbo_occ);
    if (s->vao_empty) glDeleteVertexArrays(1, &s->vao_empty);
    gr_target_release(&s->shadow);
    gr_target_release(&s->depth);
    free(s->mesh);
    free(s->upload);
    free(s);
}

/* ---- occluder mesh (world, double) ------------------------------------------------------ */

size_t gr_occluder_mesh_count(const gr_scene *scene)
{
    size_t need = 0;
    for (int i = 0; i < scene->n_occluders; i++)
        need += scene->occluders[i].type == GR_OCC_BOX ? 36 : (size_t)SPHERE_STACKS * SPHERE_SLICES * 6;
    return need;
}

void gr_occluder_mesh(const gr_scene *scene, double *o)
{
    size_t n = 0;
#define PUT(v) do { o[n * 3] = (v).x; o[n * 3 + 1] = (v).y; o[n * 3 + 2] = (v).z; n++; } while (0)
    for (int i = 0; i < scene->n_occluders; i++) {
        const gr_occluder *oc = &scene->occluders[i];
        gr_dvec3 c = gr_d3(oc->center_m[0], oc->center_m[1], oc->center_m[2]);
        if (oc->type == GR_OCC_BOX) {
            /* Yaw about +y, azimuth from +z toward +x (scene.h): local +z -> (sin a, 0, cos a),
             * local +x -> (cos a, 0, -sin a); as shafts.c. */
            double ya = oc->yaw_deg * GR_PI / 180.0;
            gr_dvec3 ax = gr_d3(cos(ya), 0, -sin(ya)), ay = gr_d3(0, 1, 0), az = gr_d3(sin(ya), 0, cos(ya));
            gr_dvec3 corner[8];
            for (int k = 0; k < 8; k++) {
                double sx = (k & 1) ? 0.5 : -0.5, sy = (k & 2) ? 0.5 : -0.5, sz = (k & 4) ? 0.5 : -0.5;
                gr_dvec3 p = gr_d3_madd(c, ax, sx * oc->size_m[0]);
                p = gr_d3_madd(p, ay, sy * oc->size_m[1]);
                corner[k] = gr_d3_madd(p, az, sz * oc->size_m[2]);
            }
            static const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                            {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
            for (int fi = 0; fi < 6; fi++) {
                const int *q = faces[fi];
                PUT(corner[q[0]]); PUT(corner[q[1]]); PUT(corner[q[2]]);
                PUT(corner[q[0]]); PUT(corner[q[2]]); PUT(corner[q[3]]);
            }
        } else {
            double rad = oc->radius_m;
            for (int st = 0; st < SPHERE_STACKS; st++) {
                double t0 = GR_PI * st / SPHERE_STACKS, t1 = GR_PI * (st + 1) / SPHERE_STACKS;
                for (int sl = 0; sl < SPHERE_SLICES; sl++) {
                    double p0 = 2.0 * GR_PI * sl / SPHERE_SLICES, p1 = 2.0 * GR_PI * (sl + 1) / SPHERE_SLICES;
                    gr_dvec3 q[4] = {
                        gr_d3_madd(c, gr_d3(sin(t0) * cos(p0), cos(t0), sin(t0) * sin(p0)), rad),
                        gr_d3_madd(c, gr_d3(sin(t1) * cos(p0), cos(t1), sin(t1) * sin(p0)), rad),
                        gr_d3_madd(c, gr_d3(sin(t1) * cos(p1), cos(t1), sin(t1) * sin(p1)), rad),
                        gr_d3_madd(c, gr_d3(sin(t0) * cos(p1), cos(t0), sin(t0) * sin(p1)), rad)};
                    PUT(q[0]); PUT(q[1]); PUT(q[2]);
                    PUT(q[0]); PUT(q[2]); PUT(q[3]);
                }
            }
        }
    }
#undef PUT
}

static gr_status build_mesh(gr_scenegl *s, const gr_scene *scene, gr_error *err)
{
    size_t need = gr_occluder_mesh_count(scene);
    if (need > s->mesh_cap) {
        double *nb = realloc(s->mesh, need * 3 * sizeof *nb);
        float *nu = realloc(s->upload, need * 3 * sizeof *nu);
        if (nb) s->mesh = nb;
        if (nu) s->upload = nu;
        if (!nb || !nu) return gr_fail(err, GR_E_NOMEM, "occluders: out of memory for %zu vertices", need);
        s->mesh_cap = need;
        s->upload_cap = need;
    }
    gr_occluder_mesh(scene, s->mesh);
    s->mesh_n = need;
    return GR_OK;
}

/* Uploads the mesh relative to origin (float after the double subtraction). */
static void upload_mesh(gr_scenegl *s, const double origin[3])
{
    for (size_t i = 0; i < s->mesh_n * 3; i++) s->upload[i] = (float)(s->mesh[i] - origin[i % 3]);
    glBindBuffer(GL_ARRAY_BUFFER, s->vbo_occ);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(s->mesh_n * 3 * sizeof(float)), s->mesh_n ? s->upload : NULL,
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* ---- shadow map ---------------------------------------------------------------------------- */

/* Light frame: e3 = refr_dir along the beam, e1, e2 across it. */
static void light_frame(const gr_frame *f, gr_dvec3 *e1, gr_dvec3 *e2, gr_dvec3 *e3)
{
    *e3 = gr_d3_norm(gr_d3(f->refr_dir[0], f->refr_dir[1], f->refr_dir[2]));
    gr_dvec3 a = fabs(e3->x) < 0.9 ? gr_d3(1, 0, 0) : gr_d3(0, 0, 1);
    *e1 = gr_d3_norm(gr_d3_cross(*e3, a));
    *e2 = gr_d3_cross(*e3, *e1);
}

void gr_scenegl_shadow_snap(const gr_frame *f, int size, double half_extent_m, const double center[3],
                            double out[3])
{
    gr_dvec3 e1, e2, e3;
    light_frame(f, &e1, &e2, &e3);
    const gr_dvec3 c = gr_d3(center[0], center[1], center[2]);
    /* the map spans [-h, h] across the beam in `size` texels: texel edges at u_c - h + i texel,
     * world-fixed when u_c = e1.c is a whole number of texels */
    const double texel = 2.0 * half_extent_m / (double)size;
    const double u = gr_d3_dot(e1, c), v = gr_d3_dot(e2, c);
    const double du = texel * floor(u / texel + 0.5) - u, dv = texel * floor(v / texel + 0.5) - v;
    const gr_dvec3 o = gr_d3_add(c, gr_d3_add(gr_d3_scale(e1, du), gr_d3_scale(e2, dv)));
    out[0] = o.x, out[1] = o.y, out[2] = o.z;
}

gr_status gr_scenegl_shadow_map(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int size,
                                const double center[3], double half_extent_m, unsigned *texture,
                                double light_vp[16], gr_error *err)
{
    gr_status st;
    *texture = 0;
    if (size < 1 || size > 16384) return gr_fail(err, GR_E_INPUT, "shadow map size %d: must be in [1, 16384]", size);
    if (!(half_extent_m > 0 && isfinite(half_extent_m)))
        return gr_fail(err, GR_E_INPUT, "shadow map half extent %g m: must be finite and > 0", half_extent_m);
    if ((st = build_mesh(s, scene, err)) != GR_OK) return st;
    if ((st = gr_target_ensure(&s->shadow, GL_DEPTH_COMPONENT32F, size, size, GR_TARGET_DEPTH, "occluder shadow map",
                               err)) != GR_OK)
        return st;
    gr_dvec3 e1, e2, e3;
    light_frame(f, &e1, &e2, &e3);
    double zmin = 0.0, zmax = 0.0;
    for (size_t i = 0; i < s->mesh_n; i++) {
        const double *p = s->mesh + i * 3;
        double z = e3.x * (p[0] - center[0]) + e3.y * (p[1] - center[1]) + e3.z * (p[2] - center[2]);
        if (i == 0 || z < zmin) zmin = z;
        if (i == 0 || z > zmax) zmax = z;
    }
    double znear = zmin - 1.0, zfar = zmax + 1.0;
    double r = half_extent_m, dz = zfar - znear;
    /* Relative (to centre) -> clip, column-major. */
    double rel[16] = {e1.x / r, e2.x / r, 2.0 * e3.x / dz, 0,
                      e1.y / r, e2.y / r, 2.0 * e3.y / dz, 0,
                      e1.z / r, e2.z / r, 2.0 * e3.z / dz, 0,
                      0, 0, -(zfar + znear) / dz, 1};
    double tr[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -center[0], -center[1], -center[2], 1};
    gr_mat4_mul(rel, tr, light_vp);

    glBindFramebuffer(GL_FRAMEBUFFER, s->shadow.fbo);
    glViewport(0, 0, size, size);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    if (s->mesh_n > 0) {
        float m[16];
        upload_mesh(s, center);
        gr_frame_matf(rel, m);
        glUseProgram(s->prog_shadow);
        glUniformMatrix4fv(s->loc_shadow_mvp, 1, GL_FALSE, m);
        glBindVertexArray(s->vao_occ);
        glDrawArrays(GL_TRIANGLES, 0, (GLsizei)s->mesh_n);
    }
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if ((st = gr_gl_check("occluder shadow map", err)) != GR_OK) return st;
    *texture = s->shadow.tex;
    return GR_OK;
}

/* ---- eye depth -------------------------------------------------------------------------------- */

gr_status gr_scenegl_eye_depth(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int width, int height,
                               unsigned *texture, gr_error *err)
{
    gr_status st;
    *texture = 0;
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return gr_fail(err, GR_E_INPUT, "eye depth target %dx%d: must be in [1, 16384]", width, height);
    if ((st = build_mesh(s, scene, err)) != GR_OK) return st;
    if ((st = gr_target_ensure(&s->depth, GL_R32F, width, height, 0, "eye depth target", err)) != GR_OK) return st;
    double vp_rot[16], inv_rot[16];
    gr_frame_view_proj_rot(f, vp_rot);
    if (gr_mat4_inverse(vp_rot, inv_rot) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    float m[16];
    glBindFramebuffer(GL_FRAMEBUFFER, s->depth.fbo);
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DITHER);
    const float far_m = (float)GR_FRAME_FAR_M;
    glClearColor(far_m, far_m, far_m, far_m);
    glClear(GL_COLOR_BUFFER_BIT);
    glClearColor(0, 0, 0, 0);
    glEnable(GL_BLEND);
    glBlendEquation(GL_MIN); /* nearest surface wins; order-independent, so deterministic */
    glBlendFunc(GL_ONE, GL_ONE);
    if (s->mesh_n > 0) {
        upload_mesh(s, f->eye);
        gr_frame_matf(vp_rot, m);
        glUseProgram(s->prog_depth);
        glUniformMatrix4fv(s->loc_depth_mvp, 1, GL_FALSE, m);
        glBindVertexArray(s->vao_occ);
        glDrawArrays(GL_TRIANGLES, 0, (GLsizei)s->mesh_n);
    }
    if (scene->has_seabed) {
        gr_frame_matf(inv_rot, m);
        glUseProgram(s->prog_seabed);
        glUniformMatrix4fv(s->loc_seabed_inv, 1, GL_FALSE, m);
        glUniform1f(s->loc_seabed_rel, (float)(f->seabed_y - f->eye[1]));
        glUniform1f(s->loc_seabed_far, far_m);
        glBindVertexArray(s->vao_empty);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if ((st = gr_gl_check("eye depth", err)) != GR_OK) return st;
    *texture = s->depth.tex;
    return GR_OK;
}
