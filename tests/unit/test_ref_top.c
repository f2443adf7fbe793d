/* The lit region's top (docs/reference.md 2.2, "The region's top"): where no camera ray rises
 * to the surface, the beams' slabs stop above the highest point a ray reaches, and the render
 * must be the one whose slabs run up to the surface (gr_ref_options.full_column), byte for
 * byte: a lookup above the top would find no slab there and lose light.
 *  (a) the default scene looking 40 degrees down (every ray descends): the top is the camera's
 *      height and a margin, the plain set has fewer primitives, the bytes are the same in every
 *      channel (the bias probe's included);
 *  (b) murky water seen level from 20 m deep: the rays rising at up to 20 degrees end at the
 *      cutoff, metres below the surface. The top lies above every ray's end, found from the
 *      render's own ray_length channel (an independent figure: each pixel's mean ray length,
 *      its centre's direction), and within the margin of it; the bytes are the same;
 *  (c) the default view (its frustum holds straight up): no top, the same render as before.
 * 48 x 27 pixels, 2 passes in 2 batches, surface_res 128, at most 32 steps: about 4 s on 2 cores. */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include <string.h>

typedef struct view_run {
    gr_ref_result res;
    gr_ref_info info;
} view_run;

/* render: 0 for the region only (out->res left empty) */
static void run(const char *path, const char *const *ov, int nov, int full, int aovs, int render, view_run *out)
{
    gr_scene *s = ref_scene_file(path, ov, nov);
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.progress = 0;
    o.full_column = full;
    o.aovs = aovs;
    gr_error err = {GR_OK, ""};
    gr_ref_renderer *r = NULL;
    if (gr_ref_create(s, &o, &r, &err) != GR_OK) {
        fprintf(stderr, "create failed: %s\n", err.msg);
        exit(1);
    }
    gr_ref_get_info(r, &out->info);
    memset(&out->res, 0, sizeof out->res);
    if (render && gr_ref_render(r, &out->res, &err) != GR_OK) {
        fprintf(stderr, "render failed: %s\n", err.msg);
        exit(1);
    }
    gr_ref_destroy(r);
    free(s);
}

static double meta_num(const gr_ref_result *r, const char *key)
{
    const gr_meta_item *it = gr_meta_get(&r->meta, key);
    return it && it->type != GR_META_STRING ? it->num : NAN;
}

/* every channel of every pixel equal (NaN never equal) */
static int same_bytes(const gr_image *a, const gr_image *b)
{
    if (a->width != b->width || a->height != b->height || a->nchannels != b->nchannels) return 0;
    size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->nchannels;
    for (size_t i = 0; i < n; i++)
        if (!(a->pixels[i] == b->pixels[i])) return 0;
    return 1;
}

static void release(view_run *v) { gr_ref_result_free(&v->res); }

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char scene[4096];
    snprintf(scene, sizeof scene, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    /* the slabs' bounds do not depend on the cells: 128 of them make the builds 4x cheaper */
    const char *base[] = {"camera.width=48", "camera.height=27", "reference.sun_samples=2", "reference.batches=2",
                          "reference.surface_res=128", "reference.steps=32"};

    /* (a) looking down */
    {
        const char *ov[] = {base[0], base[1], base[2], base[3], base[4], base[5], "camera.pitch_deg=-40"};
        view_run top, full;
        run(scene, ov, 7, 0, 0, 1, &top);
        run(scene, ov, 7, 1, 0, 1, &full);
        printf("(a) y_top %.3f (camera at -8), plain prims %.0f vs %.0f\n", top.info.y_top,
               meta_num(&top.res, "godrays:beam_prims"), meta_num(&full.res, "godrays:beam_prims"));
        CHECK_MSG(isinf(full.info.y_top), "(a) full_column: no top");
        CHECK_MSG(top.info.y_top > -8.0 && top.info.y_top < -8.0 + 0.05 + 0.01 * (-8.0 - top.info.region[4]) + 1e-6,
                  "(a) the top %.4f is the camera's height (-8) and its margin", top.info.y_top);
        CHECK_MSG(meta_num(&top.res, "godrays:beam_prims") < 0.85 * meta_num(&full.res, "godrays:beam_prims"),
                  "(a) fewer primitives under the top");
        CHECK_MSG(same_bytes(top.res.image, full.res.image), "(a) the same bytes as the full column");
        CHECK_MSG(gr_image_channel(top.res.image, "bias.R") >= 0, "(a) the bias probe ran");
        release(&top);
        release(&full);
    }

    /* (b) murky water, level, 20 m deep: rising rays end at the cutoff */
    {
        const char *ov[] = {base[0], base[1], base[2], base[3], base[4], base[5], "camera.pitch_deg=0", "camera.fov_deg=40",
                            "camera.position_m=[0,-20,0]", "seabed.depth_m=60", "medium.absorption_per_m=[1.5,1.0,0.8]",
                            "reference.bias_probe=false"};
        view_run top, full;
        run(scene, ov, 12, 0, 1, 1, &top);
        run(scene, ov, 12, 1, 1, 1, &full);
        /* the highest ray end by the render's own ray lengths: pixel (x, y)'s centre direction */
        gr_scene *s = ref_scene_file(scene, ov, 12);
        const gr_camera *c = &s->camera;
        double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), ta = tf * c->width / c->height, hi = -INFINITY;
        const gr_image *im = top.res.image;
        int lc = gr_image_channel(im, "ray_length");
        CHECK_MSG(lc >= 0, "(b) ray_length channel");
        for (int y = 0; lc >= 0 && y < im->height; y++)
            for (int x = 0; x < im->width; x++) {
                double a = (2.0 * (x + 0.5) / c->width - 1.0) * ta, b = (1.0 - 2.0 * (y + 0.5) / c->height) * tf;
                double dy = c->forward[1] + a * c->right[1] + b * c->up[1];
                double n = sqrt(pow(c->forward[0] + a * c->right[0] + b * c->up[0], 2) + dy * dy +
                                pow(c->forward[2] + a * c->right[2] + b * c->up[2], 2));
                double len = im->pixels[((size_t)y * im->width + x) * im->nchannels + lc];
                hi = fmax(hi, -20.0 + len * dy / n);
            }
        double col = hi - top.info.region[4];
        printf("(b) y_top %.3f, highest ray end (pixel centres) %.3f, plain prims %.0f vs %.0f\n", top.info.y_top, hi,
               meta_num(&top.res, "godrays:beam_prims"), meta_num(&full.res, "godrays:beam_prims"));
        CHECK_MSG(hi > -19.0 && hi < -5.0, "(b) rays rise, and end below the surface (%.3f)", hi);
        CHECK_MSG(top.info.y_top >= hi, "(b) the top %.3f lies above the highest ray end %.3f", top.info.y_top, hi);
        /* the pixel centres' rays stop short of the frustum's edge by half a pixel (0.75 deg) */
        CHECK_MSG(top.info.y_top <= hi + 0.05 + 0.01 * col + 0.06 * col, "(b) the top %.3f within its margin of %.3f",
                  top.info.y_top, hi);
        CHECK_MSG(meta_num(&top.res, "godrays:beam_prims") < 0.9 * meta_num(&full.res, "godrays:beam_prims"),
                  "(b) fewer primitives under the top");
        CHECK_MSG(same_bytes(top.res.image, full.res.image), "(b) the same bytes as the full column");
        free(s);
        release(&top);
        release(&full);
    }

    /* (c) the default view holds straight up: no top */
    {
        const char *ov[] = {base[0], base[1], base[2], base[3], base[4], base[5], "reference.bias_probe=false"};
        view_run top;
        run(scene, ov, 7, 0, 0, 0, &top);
        CHECK_MSG(isinf(top.info.y_top), "(c) the default view: no top (%.3f)", top.info.y_top);
    }
    CHECK_DONE();
}
