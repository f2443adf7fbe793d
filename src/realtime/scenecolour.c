/* The scene colour: the light pass, then the lit surfaces (scenecolour.h). */
#include "realtime/scenecolour.h"

#include <string.h>

#include "gl/gl.h"
#include "gl/glctx.h"
#include "realtime/shaders.h"

gr_status gr_scene_colour_init(gr_scene_colour *sc, const char *shader_dir, gr_error *err)
{
    static const gr_shader_stage lit[2] = {
        {GL_VERTEX_SHADER, {"volume_screen.vert.glsl", NULL}},
        {GL_FRAGMENT_SHADER,
         {"volume_version.glsl", "volume_fragment.glsl", "caustic_stack.glsl", "volume_common.glsl",
          "scene_colour.frag.glsl", NULL}}};
    memset(sc, 0, sizeof *sc);
    gr_status st = gr_light_pass_init(&sc->light, shader_dir, err);
    if (st == GR_OK) st = gr_shader_program_stages(shader_dir, lit, 2, NULL, 0, &sc->prog, NULL, err);
    if (st != GR_OK) return st;
    GLuint p = sc->prog;
    gr_vol_locations(p, &sc->locs);
    sc->inv_vp_rot = glGetUniformLocation(p, "u_inv_vp_rot");
    sc->eye_depth = glGetUniformLocation(p, "u_eye_depth");
    sc->size = glGetUniformLocation(p, "u_size");
    sc->far = glGetUniformLocation(p, "u_far");
    sc->seabed = glGetUniformLocation(p, "u_seabed");
    sc->albedo = glGetUniformLocation(p, "u_albedo");
    sc->inv_unit = glGetUniformLocation(p, "u_inv_unit");
    sc->normal_offset = glGetUniformLocation(p, "u_normal_offset");
    glGenVertexArrays(1, &sc->vao);
    return gr_gl_check("scene colour setup", err);
}

void gr_scene_colour_free(gr_scene_colour *sc)
{
    if (!sc) return;
    gr_light_pass_free(&sc->light);
    if (sc->prog) glDeleteProgram(sc->prog);
    if (sc->vao) glDeleteVertexArrays(1, &sc->vao);
    memset(sc, 0, sizeof *sc);
}

void gr_scene_colour_radiance(const gr_frame *f, const gr_scene_colour_params *p, double out[3])
{
    gr_light_radiance(f, p->radius_deg, out);
}

gr_status gr_scene_colour_draw(gr_scene_colour *sc, const gr_scene *scene, const gr_vol_inputs *in,
                               const gr_scene_colour_params *p, const gr_target *t, unsigned depth_tex, const char *who,
                               gr_error *err)
{
    const gr_frame *f = in->f;
    /* 1. the surface-first pixels: the light pass itself (alpha 1 there, 0 elsewhere) */
    const gr_light_params lp = {.radius_deg = p->radius_deg, .threshold = 0, .occluders = 1, .dither8 = 0};
    gr_status st = gr_light_pass_draw(&sc->light, scene, f, &lp, t, depth_tex, who, err);
    if (st != GR_OK) return st;
    /* 2. the lit surfaces, added only where the light pass's alpha is 0 */
    double vp_rot[16], inv_rot[16], unit[3];
    float m[16];
    gr_frame_view_proj_rot(f, vp_rot);
    if (gr_mat4_inverse(vp_rot, inv_rot) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    gr_scene_colour_radiance(f, p, unit);
    glUseProgram(sc->prog);
    gr_vol_set(&sc->locs, in);
    gr_frame_matf(inv_rot, m);
    glUniformMatrix4fv(sc->inv_vp_rot, 1, GL_FALSE, m);
    glUniform1i(sc->eye_depth, 1);
    glUniform2f(sc->size, (float)t->w, (float)t->h);
    glUniform1f(sc->far, (float)GR_FRAME_FAR_M);
    glUniform1f(sc->seabed, (float)(f->seabed_y - f->eye[1]));
    glUniform3f(sc->albedo, (float)p->albedo[0], (float)p->albedo[1], (float)p->albedo[2]);
    glUniform3f(sc->inv_unit, unit[0] > 0 ? (float)(1.0 / unit[0]) : 0.0f, unit[1] > 0 ? (float)(1.0 / unit[1]) : 0.0f,
                unit[2] > 0 ? (float)(1.0 / unit[2]) : 0.0f);
    /* normal-offset shadows: 1.5 texels off the surface, so that a lit face's own texel does
     * not shadow it (the map's depth slope across a texel, docs "Scene colour") */
    glUniform1f(sc->normal_offset, (float)(1.5 * p->shadow_texel_m + 0.01));
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, depth_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->w, t->h);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFuncSeparate(GL_ONE_MINUS_DST_ALPHA, GL_ONE, GL_ZERO, GL_ONE);
    glBindVertexArray(sc->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    for (int u = 1; u <= 3; u++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)u);
        glBindTexture(GL_TEXTURE_2D, 0);
        glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    }
    glActiveTexture(GL_TEXTURE0);
    glUseProgram(0);
    return gr_gl_check("scene colour", err);
}
