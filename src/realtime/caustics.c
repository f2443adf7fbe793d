/* Seed 002's caustic texture on the GPU (caustics.h; docs/volume-techniques.md). */
#include "realtime/caustics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "gl/glctx.h"
#include "realtime/shaders.h"
#include "realtime/volume.h"

/* The reuse cache (gr_caustics_set_reuse): stacks already built, each the sampled levels of a
 * build (level 1 up, copied to levels 0 up of its own texture) under the inputs that made it. */
#define CACHE_SLOTS 32
#define CACHE_BYTES (1024LL * 1024 * 1024)

typedef struct build_key {
    gr_caustics_params p;
    double origin[2], sun_dir[3], to_sun[3], ior;
    float wa[GR_MAX_WAVES * 4], wamp[GR_MAX_WAVES];
    int n_waves;
} build_key;

typedef struct cache_slot {
    build_key key;
    GLuint tex;
    long long bytes, triangles;
    unsigned long long used; /* the build counter when last used (least recently used goes) */
    gr_pass_cost cost;       /* the build's, with the pass's queried primitives once noted */
} cache_slot;

struct gr_caustics {
    GLuint prog, vao, fbo, tex;
    GLuint ibo, q_samples;   /* the grid's index buffer (for ibo_grid), the fragments' query */
    int ibo_grid;
    int tex_size, tex_layers;
    gr_pass_cost cost;       /* of the last build */
    GLint l_grid, l_L, l_nw, l_wa, l_wamp, l_sun, l_ior, l_fresnel, l_gL, l_plane, l_to_sun, l_texel;
    double origin[2];
    long long triangles;
    int reuse;               /* gr_caustics_set_reuse */
    cache_slot slot[CACHE_SLOTS];
    int n_slots;
    long long cache_bytes;
    unsigned long long clock;
    const cache_slot *active; /* the slot the last build took its stack from; NULL: c->tex */
    cache_slot *stored;       /* the slot the last build (drawn) was kept in; NULL: none */
};

/* ---- caustics ------------------------------------------------------------------------------ */

void gr_caustics_depths(int n, double first_m, double last_m, double *out)
{
    for (int i = 0; i < n; i++)
        out[i] = n == 1 ? first_m : first_m * pow(last_m / first_m, (double)i / (double)(n - 1));
}

gr_status gr_caustics_create(const char *shader_dir, gr_caustics **out, gr_error *err)
{
    *out = NULL;
    gr_caustics *c = calloc(1, sizeof *c);
    if (!c) return gr_fail(err, GR_E_NOMEM, "caustics: out of memory");
    const gr_shader_stage st3[3] = {{GL_VERTEX_SHADER, {"volume_version.glsl", "volume_surface.glsl", "caustics.vert.glsl", NULL}},
                                 {GL_GEOMETRY_SHADER, {"caustics.geom.glsl", NULL, NULL, NULL}},
                                 {GL_FRAGMENT_SHADER, {"caustics.frag.glsl", NULL, NULL, NULL}}};
    gr_status st = gr_shader_program_stages(shader_dir, st3, 3, NULL, 0, &c->prog, NULL, err);
    if (st != GR_OK) {
        free(c);
        return st;
    }
    GLuint p = c->prog;
    c->l_grid = glGetUniformLocation(p, "u_grid");
    c->l_L = glGetUniformLocation(p, "u_L");
    c->l_nw = glGetUniformLocation(p, "u_n_waves");
    c->l_wa = glGetUniformLocation(p, "u_wa");
    c->l_wamp = glGetUniformLocation(p, "u_wamp");
    c->l_sun = glGetUniformLocation(p, "u_sun_dir");
    c->l_ior = glGetUniformLocation(p, "u_ior");
    c->l_fresnel = glGetUniformLocation(p, "u_fresnel");
    c->l_plane = glGetUniformLocation(p, "u_plane_y");
    c->l_to_sun = glGetUniformLocation(p, "u_to_sun");
    c->l_texel = glGetUniformLocation(p, "u_texel");
    glGenVertexArrays(1, &c->vao);
    glGenFramebuffers(1, &c->fbo);
    glGenQueries(1, &c->q_samples);
    gr_pass_cost_clear(&c->cost);
    *out = c;
    return gr_gl_check("caustics setup", err);
}

void gr_caustics_destroy(gr_caustics *c)
{
    if (!c) return;
    if (c->prog) glDeleteProgram(c->prog);
    if (c->vao) glDeleteVertexArrays(1, &c->vao);
    if (c->fbo) glDeleteFramebuffers(1, &c->fbo);
    if (c->tex) glDeleteTextures(1, &c->tex);
    for (int i = 0; i < c->n_slots; i++) glDeleteTextures(1, &c->slot[i].tex);
    if (c->ibo) glDeleteBuffers(1, &c->ibo);
    if (c->q_samples) glDeleteQueries(1, &c->q_samples);
    free(c);
}

unsigned gr_caustics_texture(const gr_caustics *c) { return c->active ? c->active->tex : c->tex; }
int gr_caustics_base_level(const gr_caustics *c) { return c->active ? 0 : 1; }
void gr_caustics_set_reuse(gr_caustics *c, int on) { c->reuse = on != 0; }
long long gr_caustics_triangles(const gr_caustics *c) { return c->triangles; }
void gr_caustics_origin(const gr_caustics *c, double origin[2])
{
    origin[0] = c->origin[0];
    origin[1] = c->origin[1];
}

/* The grid's triangles as indices of its (grid + 1)^2 vertices, cell by cell in the order the
 * vertex shader's gl_VertexID / 6 used to give them (same triangles, same vertex order, so the
 * same sums): (0,0) (1,0) (1,1), (0,0) (1,1) (0,1). */
static gr_status ensure_indices(gr_caustics *c, int grid, gr_error *err)
{
    if (c->ibo && c->ibo_grid == grid) return GR_OK;
    size_t n = (size_t)grid * (size_t)grid * 6;
    GLuint *idx = malloc(n * sizeof *idx);
    if (!idx) return gr_fail(err, GR_E_NOMEM, "caustics.grid = %d: out of memory for the index buffer", grid);
    static const int corner[6][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
    const GLuint row = (GLuint)grid + 1;
    size_t k = 0;
    for (int j = 0; j < grid; j++)
        for (int i = 0; i < grid; i++)
            for (int v = 0; v < 6; v++) idx[k++] = (GLuint)(i + corner[v][0]) + (GLuint)(j + corner[v][1]) * row;
    if (!c->ibo) glGenBuffers(1, &c->ibo);
    glBindVertexArray(c->vao);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, c->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(n * sizeof *idx), idx, GL_STATIC_DRAW);
    glBindVertexArray(0);
    free(idx);
    c->ibo_grid = grid;
    return gr_gl_check("caustics.grid: index buffer", err);
}

void gr_caustics_cost(const gr_caustics *c, gr_pass_cost *out) { *out = c->cost; }

void gr_caustics_note_primitives(gr_caustics *c, long long primitives)
{
    if (!c->stored || primitives < 0) return;
    c->stored->cost.v[GR_COST_PRIMITIVES] = primitives;
    c->stored->cost.queried |= 1u << GR_COST_PRIMITIVES;
}

/* A stack built from the same inputs: c takes it (texture, cost, triangles); 1 if found. */
static int cache_find(gr_caustics *c, const build_key *key)
{
    for (int i = 0; i < c->n_slots; i++) {
        cache_slot *s = &c->slot[i];
        if (memcmp(&s->key, key, sizeof *key) != 0) continue;
        s->used = ++c->clock;
        c->active = s;
        c->cost = s->cost;
        c->triangles = s->triangles;
        return 1;
    }
    return 0;
}

/* Keeps the stack just built in c->tex under key: its sampled levels (1 up) copied to a
 * texture of their own (levels 0 up, the same sampler state), the least recently used slots
 * deleted while the cache would pass CACHE_BYTES or CACHE_SLOTS. A stack larger than the
 * whole cache is not kept. */
static gr_status cache_store(gr_caustics *c, const build_key *key, gr_error *err)
{
    const int S2 = 2 * key->p.size, layers = key->p.n_depths;
    int levels = 0;
    long long bytes = 0;
    for (int l = 1; (S2 >> l) >= 1; l++, levels++) bytes += 4LL * (S2 >> l) * (S2 >> l) * layers;
    if (bytes > CACHE_BYTES || levels < 1) return GR_OK;
    while (c->n_slots > 0 && (c->n_slots == CACHE_SLOTS || c->cache_bytes + bytes > CACHE_BYTES)) {
        int lru = 0;
        for (int i = 1; i < c->n_slots; i++)
            if (c->slot[i].used < c->slot[lru].used) lru = i;
        glDeleteTextures(1, &c->slot[lru].tex);
        c->cache_bytes -= c->slot[lru].bytes;
        c->slot[lru] = c->slot[--c->n_slots];
    }
    cache_slot *s = &c->slot[c->n_slots];
    memset(s, 0, sizeof *s);
    glGenTextures(1, &s->tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, s->tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, levels, GL_R32F, S2 >> 1, S2 >> 1, layers);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    for (int l = 0; l < levels; l++)
        glCopyImageSubData(c->tex, GL_TEXTURE_2D_ARRAY, l + 1, 0, 0, 0, s->tex, GL_TEXTURE_2D_ARRAY, l, 0, 0, 0,
                           S2 >> (l + 1), S2 >> (l + 1), layers);
    gr_status st = gr_gl_check("caustic stack: keeping it for reuse", err);
    if (st != GR_OK) {
        glDeleteTextures(1, &s->tex);
        return st;
    }
    s->key = *key;
    s->bytes = bytes;
    s->used = ++c->clock;
    s->cost = c->cost;
    s->triangles = c->triangles;
    c->cache_bytes += bytes;
    c->n_slots++;
    c->stored = s;
    return GR_OK;
}

gr_status gr_caustics_build(gr_caustics *c, const gr_scene *scene, const gr_frame *f, const gr_caustics_params *p,
                            gr_error *err)
{
    if (p->n_depths < 1 || p->n_depths > GR_CAUSTICS_MAX_DEPTHS || p->size < 1 || p->grid < 1 || !(p->patch_m > 0))
        return gr_fail(err, GR_E_INPUT, "caustics: bad parameters (size %d, grid %d, %d depths, patch %g m)", p->size,
                       p->grid, p->n_depths, p->patch_m);
    int S2 = 2 * p->size;
    if (!c->tex || c->tex_size != p->size || c->tex_layers != p->n_depths) {
        if (c->tex) glDeleteTextures(1, &c->tex);
        glGenTextures(1, &c->tex);
        glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
        /* the whole mip chain: level 1 is the 2x2 supersampled texture, the coarser ones
         * filter distant lookups (fragment shaders; compute shaders read level 1) */
        int levels = 1;
        while ((S2 >> levels) >= 1) levels++;
        glTexStorage3D(GL_TEXTURE_2D_ARRAY, levels, GL_R32F, S2, S2, p->n_depths);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
        c->tex_size = p->size;
        c->tex_layers = p->n_depths;
        gr_status st = gr_gl_check("caustics.texture_size: caustic texture", err);
        if (st != GR_OK) return st;
    }
    gr_status ist = ensure_indices(c, p->grid, err);
    if (ist != GR_OK) return ist;
    double L = p->patch_m;
    c->origin[0] = floor(f->eye[0] / L) * L;
    c->origin[1] = floor(f->eye[2] / L) * L;
    c->active = NULL;
    c->stored = NULL;
    /* everything the build's uniforms are made of, zero-padded so that memcmp compares it */
    build_key key;
    memset(&key, 0, sizeof key);
    float *wa = key.wa, *wamp = key.wamp;
    gr_vol_waves(scene, f, c->origin[0], c->origin[1], wa, wamp);
    if (c->reuse) {
        /* field by field: the padding of *p is indeterminate, key's is zero */
        key.p.size = p->size;
        key.p.grid = p->grid;
        key.p.patch_m = p->patch_m;
        key.p.n_depths = p->n_depths;
        for (int d = 0; d < p->n_depths; d++) key.p.depths_m[d] = p->depths_m[d];
        key.p.fresnel = p->fresnel;
        key.n_waves = scene->water.n_waves;
        for (int k = 0; k < 3; k++) key.sun_dir[k] = f->sun_dir[k], key.to_sun[k] = f->to_sun[k];
        key.ior = f->ior;
        key.origin[0] = c->origin[0];
        key.origin[1] = c->origin[1];
        if (cache_find(c, &key)) return GR_OK;
    }
    glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BASE_LEVEL, 0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    glUseProgram(c->prog);
    glUniform1i(c->l_grid, p->grid);
    glUniform1f(c->l_L, (float)L);
    glUniform1i(c->l_nw, scene->water.n_waves);
    glUniform4fv(c->l_wa, GR_MAX_WAVES, wa);
    glUniform1fv(c->l_wamp, GR_MAX_WAVES, wamp);
    glUniform3f(c->l_sun, (float)f->sun_dir[0], (float)f->sun_dir[1], (float)f->sun_dir[2]);
    glUniform3f(c->l_to_sun, (float)f->to_sun[0], (float)f->to_sun[1], (float)f->to_sun[2]);
    glUniform1f(c->l_ior, (float)f->ior);
    glUniform1i(c->l_fresnel, p->fresnel);
    glUniform1f(c->l_texel, (float)(L / S2));
    glBindVertexArray(c->vao);
    glBindFramebuffer(GL_FRAMEBUFFER, c->fbo);
    glViewport(0, 0, S2, S2);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glClearColor(0, 0, 0, 0);
    glBeginQuery(GL_SAMPLES_PASSED, c->q_samples);
    for (int d = 0; d < p->n_depths; d++) {
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, c->tex, 0, d);
        glClear(GL_COLOR_BUFFER_BIT);
        glUniform1f(c->l_plane, (float)-p->depths_m[d]);
        glDrawElements(GL_TRIANGLES, p->grid * p->grid * 6, GL_UNSIGNED_INT, (const void *)0);
    }
    glEndQuery(GL_SAMPLES_PASSED);
    c->triangles = 2LL * p->grid * p->grid * p->n_depths;
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    /* 2x2 supersampling: level 1 is the box filter of level 0; sample from it. */
    glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
    glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BASE_LEVEL, 1);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    /* Cost (technique.h): fragments queried; 6 indices a cell a plane; each plane's level 0
     * cleared and blended per fragment (R32F), then every coarser level written from 4 taps
     * of the finer one (glGenerateMipmap's box filter). */
    const long long layers = p->n_depths, s0 = (long long)S2 * S2;
    long long mip_texels = 0;
    for (int l = 1; (S2 >> l) >= 1; l++) mip_texels += (long long)(S2 >> l) * (S2 >> l);
    gr_pass_cost_clear(&c->cost);
    c->cost.v[GR_COST_FRAGMENTS] = gr_gl_query_result(c->q_samples);
    c->cost.queried = 1u << GR_COST_FRAGMENTS;
    c->cost.v[GR_COST_VERTICES] = 6LL * p->grid * p->grid * layers;
    c->cost.v[GR_COST_TAPS] = 4 * mip_texels * layers;
    c->cost.v[GR_COST_BYTES] = (s0 + mip_texels) * 4 * layers + c->cost.v[GR_COST_FRAGMENTS] * 4;
    c->cost.v[GR_COST_INVOCATIONS] = 0;
    gr_status st = gr_gl_check("caustic texture build", err);
    if (st == GR_OK && c->reuse) st = cache_store(c, &key, err);
    return st;
}

gr_status gr_caustics_read(gr_caustics *c, int layer, gr_image **out, gr_error *err)
{
    *out = NULL;
    /* a reused stack's size and layers are its own key's (c->tex may hold another build) */
    const int layers = c->active ? c->active->key.p.n_depths : c->tex_layers;
    if (!c->tex || layer < 0 || layer >= layers) return gr_fail(err, GR_E_USAGE, "caustics: no layer %d to read", layer);
    int n = c->active ? c->active->key.p.size : c->tex_size;
    static const char *const names[1] = {"Y"};
    gr_image *img = gr_image_create(n, n, 1, names);
    if (!img) return gr_fail(err, GR_E_NOMEM, "caustics: out of memory");
    glBindFramebuffer(GL_FRAMEBUFFER, c->fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, gr_caustics_texture(c), gr_caustics_base_level(c),
                              layer);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, n, n, GL_RED, GL_FLOAT, img->pixels);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, c->tex, 0, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    gr_status st = gr_gl_check("caustic texture readback", err);
    if (st != GR_OK) {
        gr_image_destroy(img);
        return st;
    }
    *out = img;
    return GR_OK;
}
