/* Radial profiles (see profile.h). */
#include "report/profile.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/metrics.h"
#include "core/optics.h"
#include "core/vec.h"

void gr_profile_sun_view_dir(const gr_scene *s, double out[3])
{
    /* Seed eq. 5.5.1 at the rest surface: normal +y on the incident (air) side, eta = 1 / n. */
    const gr_dvec3 I = gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]);
    gr_dvec3 T = gr_refract_d(gr_d3_norm(I), gr_d3(0.0, 1.0, 0.0), 1.0 / s->medium.ior);
    if (gr_d3_len(T) == 0.0) T = gr_d3(0.0, -1.0, 0.0); /* cannot happen from air into water */
    T = gr_d3_norm(T);
    out[0] = -T.x;
    out[1] = -T.y;
    out[2] = -T.z;
}

void gr_profile_angles(const gr_camera *cam, const double dir[3], float *angles_deg)
{
    const double th = tan(0.5 * cam->fov_deg * GR_PI / 180.0);
    const double aspect = (double)cam->width / (double)cam->height;
    const gr_dvec3 f = gr_d3(cam->forward[0], cam->forward[1], cam->forward[2]);
    const gr_dvec3 r = gr_d3(cam->right[0], cam->right[1], cam->right[2]);
    const gr_dvec3 u = gr_d3(cam->up[0], cam->up[1], cam->up[2]);
    const gr_dvec3 d = gr_d3_norm(gr_d3(dir[0], dir[1], dir[2]));
    for (int py = 0; py < cam->height; py++) {
        const double v = (2.0 * (py + 0.5) / cam->height - 1.0) * th;
        for (int px = 0; px < cam->width; px++) {
            const double h = (2.0 * (px + 0.5) / cam->width - 1.0) * th * aspect;
            const gr_dvec3 w = gr_d3_norm(gr_d3_madd(gr_d3_madd(f, r, h), u, -v));
            /* atan2(|w x d|, w . d) keeps full precision near 0 and 180 degrees, where acos
             * of the dot product loses half the digits. */
            const double a = atan2(gr_d3_len(gr_d3_cross(w, d)), gr_d3_dot(w, d));
            angles_deg[(size_t)py * (size_t)cam->width + (size_t)px] = (float)(a * 180.0 / GR_PI);
        }
    }
}

void gr_radial_profile_free(gr_radial_profile *p)
{
    if (!p) return;
    free(p->center_deg);
    free(p->count);
    for (int c = 0; c < GR_PROFILE_NCH; c++) {
        free(p->mean[c]);
        free(p->stderr_bound[c]);
    }
    memset(p, 0, sizeof *p);
}

gr_status gr_radial_profile_compute(const gr_image *img, const float *angles_deg, const unsigned char *scored,
                                    int nbins, double bin_deg, double scale, gr_radial_profile *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    if (!img || !img->pixels || !angles_deg)
        return gr_fail(err, GR_E_INPUT, "radial profile: no image or no angles");
    if (nbins < 1 || nbins > 1000000 || !(bin_deg > 0.0) || !isfinite(bin_deg) || !isfinite(scale))
        return gr_fail(err, GR_E_INPUT, "radial profile: bad bins (%d bins of %g deg) or scale %g", nbins, bin_deg,
                       scale);
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    const char *const se_names[3] = {"stderr.R", "stderr.G", "stderr.B"};
    int se[3], have_se = 1;
    for (int c = 0; c < 3; c++) {
        se[c] = gr_image_channel(img, se_names[c]);
        if (se[c] < 0) have_se = 0;
    }
    const size_t nb = (size_t)nbins;
    out->nbins = nbins;
    out->bin_deg = bin_deg;
    out->center_deg = malloc(nb * sizeof(double));
    out->count = calloc(nb, sizeof(long long));
    int ok = out->center_deg && out->count;
    for (int c = 0; c < GR_PROFILE_NCH; c++) {
        out->mean[c] = calloc(nb, sizeof(double));
        ok = ok && out->mean[c];
        if (have_se) {
            out->stderr_bound[c] = calloc(nb, sizeof(double));
            ok = ok && out->stderr_bound[c];
        }
    }
    if (!ok) {
        gr_radial_profile_free(out);
        return gr_fail(err, GR_E_NOMEM, "radial profile: out of memory for %d bins", nbins);
    }
    static const double wy[3] = {GR_LUM_R, GR_LUM_G, GR_LUM_B};
    const size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < n; p++) {
        if (scored && !scored[p]) continue;
        const double a = angles_deg[p];
        if (!(a >= 0.0)) continue;
        const double fb = a / bin_deg;
        if (fb >= (double)nbins) continue;
        const size_t b = (size_t)fb;
        const float *px = img->pixels + p * (size_t)img->nchannels;
        double y = 0.0, sy = 0.0;
        for (int c = 0; c < 3; c++) {
            const double v = scale * (double)px[rgb[c]];
            out->mean[c][b] += v;
            y += wy[c] * v;
            if (have_se) {
                const double s = fabs(scale) * (double)px[se[c]];
                out->stderr_bound[c][b] += s;
                sy += wy[c] * s; /* linear sum: valid for correlated channels (docs/metrics.md) */
            }
        }
        out->mean[GR_PROFILE_Y][b] += y;
        if (have_se) out->stderr_bound[GR_PROFILE_Y][b] += sy;
        out->count[b]++;
    }
    for (size_t b = 0; b < nb; b++) {
        out->center_deg[b] = ((double)b + 0.5) * bin_deg;
        for (int c = 0; c < GR_PROFILE_NCH; c++) {
            if (out->count[b] > 0) {
                out->mean[c][b] /= (double)out->count[b];
                if (have_se) out->stderr_bound[c][b] /= (double)out->count[b];
            } else {
                out->mean[c][b] = NAN;
                if (have_se) out->stderr_bound[c][b] = NAN;
            }
        }
    }
    return GR_OK;
}

double gr_profile_bin_width(double max_deg, int target_bins)
{
    if (!(max_deg > 0.0) || !isfinite(max_deg) || target_bins < 1) return 1.0;
    const double raw = max_deg / target_bins;
    const double p = pow(10.0, floor(log10(raw)));
    static const double steps[3] = {1.0, 2.0, 5.0};
    for (int i = 0; i < 3; i++)
        if (steps[i] * p >= raw) return steps[i] * p;
    return 10.0 * p;
}

int gr_profile_structure_options(const gr_scene *s, float *angles_deg, gr_structure_options *so)
{
    const gr_camera *cam = &s->camera;
    memset(so, 0, sizeof *so);
    gr_error e = {GR_OK, ""};
    if (gr_structure_scene_vp(s, cam->width, cam->height, &so->vp_x, &so->vp_y, &e) != GR_OK) {
        memset(so, 0, sizeof *so);
        return 0;
    }
    double dir[3];
    gr_profile_sun_view_dir(s, dir);
    gr_profile_angles(cam, dir, angles_deg);
    so->radial = angles_deg;
    so->radial_bin = cam->fov_deg / cam->height;
    return 1;
}
