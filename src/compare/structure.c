/* Beam-structure metrics (see structure.h; derivation in docs/metrics.md "Beam structure"). */
#include "compare/structure.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/blur.h"
#include "compare/channels.h"
#include "core/optics.h"
#include "core/vec.h"

#define PI 3.14159265358979323846

gr_status gr_structure_vanishing_point(const gr_camera *cam, const double dir[3], double *x, double *y,
                                       gr_error *err)
{
    if (!cam || !dir || !x || !y) return gr_fail(err, GR_E_INPUT, "vanishing point: NULL argument");
    double d[3] = {dir[0], dir[1], dir[2]};
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0)) return gr_fail(err, GR_E_INPUT, "vanishing point: zero direction");
    double df = (d[0] * cam->forward[0] + d[1] * cam->forward[1] + d[2] * cam->forward[2]) / len;
    /* a line has two senses; the vanishing point is where the sense in front of the camera
     * projects */
    const double sgn = df < 0.0 ? -1.0 : 1.0;
    df *= sgn;
    if (df < 1e-6)
        return gr_fail(err, GR_E_INPUT, "vanishing point: the lines are parallel to the image plane (no finite point)");
    const double dr = sgn * (d[0] * cam->right[0] + d[1] * cam->right[1] + d[2] * cam->right[2]) / len;
    const double du = sgn * (d[0] * cam->up[0] + d[1] * cam->up[1] + d[2] * cam->up[2]) / len;
    /* invert the camera model of scene.h: ray = f + h r - v u with h = (2 X / W - 1) t a,
     * v = (2 Y / H - 1) t, X, Y image coordinates (pixel centre at + 0.5) */
    const double t = tan(0.5 * cam->fov_deg * PI / 180.0), a = (double)cam->width / (double)cam->height;
    const double h = dr / df, v = -du / df;
    *x = 0.5 * (double)cam->width * (h / (t * a) + 1.0);
    *y = 0.5 * (double)cam->height * (v / t + 1.0);
    return GR_OK;
}

gr_status gr_structure_scene_vp(const gr_scene *s, int width, int height, double *x, double *y, gr_error *err)
{
    if (!s || width < 1 || height < 1) return gr_fail(err, GR_E_INPUT, "vanishing point: bad scene or size");
    gr_camera cam = s->camera;
    cam.width = width, cam.height = height;
    /* the refracted sun's rays T (seed eq. 5.5.1 at the flat rest surface, normal +y, eta = 1/n) */
    const gr_dvec3 T = gr_refract_d(gr_d3_norm(gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2])),
                                    gr_d3(0.0, 1.0, 0.0), 1.0 / s->medium.ior);
    if (!(gr_d3_len(T) > 0.0)) return gr_fail(err, GR_E_INPUT, "vanishing point: the sun does not refract into the water");
    const double dir[3] = {T.x, T.y, T.z};
    return gr_structure_vanishing_point(&cam, dir, x, y, err);
}

/* The options with defaults filled in, checked. */
static gr_status resolve(const gr_structure_options *in, int w, int h, gr_structure_options *o, gr_error *err)
{
    const gr_structure_options zero = {0};
    *o = in ? *in : zero;
    if (!isfinite(o->vp_x) || !isfinite(o->vp_y))
        return gr_fail(err, GR_E_INPUT, "structure: the vanishing point is not finite");
    if (o->sigma_fine_px == 0.0) o->sigma_fine_px = fmax(0.5, (double)h / 180.0);
    if (o->sigma_coarse_px == 0.0) o->sigma_coarse_px = 4.0 * o->sigma_fine_px;
    if (o->eps_rel == 0.0) o->eps_rel = 0.01;
    if (o->n_annuli == 0) o->n_annuli = 4;
    if (o->n_theta == 0) o->n_theta = 1024;
    if (o->m_max == 0) o->m_max = 256;
    if (o->m_min == 0) o->m_min = 2;
    if (o->radial && !(o->radial_bin > 0.0 && isfinite(o->radial_bin)))
        return gr_fail(err, GR_E_INPUT, "structure: radial_bin %g is not > 0", o->radial_bin);
    if (o->r_min_px == 0.0) {
        /* 0.1 height, or where the image begins when the vanishing point lies outside it */
        const double cx = fmin(fmax(o->vp_x, 0.0), (double)w), cy = fmin(fmax(o->vp_y, 0.0), (double)h);
        o->r_min_px = fmax(0.1 * (double)h, hypot(cx - o->vp_x, cy - o->vp_y));
    }
    if (o->r_max_px == 0.0) {
        for (int c = 0; c < 4; c++) {
            const double dx = (c & 1 ? (double)w : 0.0) - o->vp_x, dy = (c & 2 ? (double)h : 0.0) - o->vp_y;
            o->r_max_px = fmax(o->r_max_px, hypot(dx, dy));
        }
    }
    if (!(o->sigma_fine_px > 0.0) || !(o->sigma_coarse_px > o->sigma_fine_px) || !isfinite(o->sigma_coarse_px))
        return gr_fail(err, GR_E_INPUT, "structure: need 0 < sigma_fine (%g) < sigma_coarse (%g)", o->sigma_fine_px,
                       o->sigma_coarse_px);
    if (!(o->eps_rel > 0.0) || !isfinite(o->eps_rel))
        return gr_fail(err, GR_E_INPUT, "structure: eps_rel %g is not > 0", o->eps_rel);
    if (o->n_annuli < 1 || o->n_annuli > GR_STRUCT_MAX_ANNULI)
        return gr_fail(err, GR_E_INPUT, "structure: n_annuli %d not in 1..%d", o->n_annuli, GR_STRUCT_MAX_ANNULI);
    if (o->m_max < 1 || o->m_max > GR_STRUCT_MAX_M || o->m_min < 1 || o->m_min > o->m_max)
        return gr_fail(err, GR_E_INPUT, "structure: need 1 <= m_min (%d) <= m_max (%d) <= %d", o->m_min, o->m_max,
                       GR_STRUCT_MAX_M);
    if (o->n_theta < 2 * o->m_max + 2)
        return gr_fail(err, GR_E_INPUT, "structure: n_theta %d below the Nyquist rate of m_max %d", o->n_theta, o->m_max);
    if (!(o->r_min_px >= 0.0) || !(o->r_max_px > o->r_min_px) || !isfinite(o->r_max_px))
        return gr_fail(err, GR_E_INPUT, "structure: need 0 <= r_min (%g) < r_max (%g)", o->r_min_px, o->r_max_px);
    return GR_OK;
}

/* Bilinear sample of a planar field at image coordinates (x, y); *ok = 0 outside the square
 * of pixel centres or when a contributing pixel is unscored. */
static double sample(const double *f, const unsigned char *scored, int w, int h, double x, double y, int *ok)
{
    const double fx = x - 0.5, fy = y - 0.5;
    if (!(fx >= 0.0) || !(fy >= 0.0) || fx > (double)(w - 1) || fy > (double)(h - 1)) {
        *ok = 0;
        return 0.0;
    }
    int x0 = (int)fx, y0 = (int)fy;
    if (x0 > w - 2) x0 = w > 1 ? w - 2 : 0;
    if (y0 > h - 2) y0 = h > 1 ? h - 2 : 0;
    const int x1 = w > 1 ? x0 + 1 : x0, y1 = h > 1 ? y0 + 1 : y0;
    const double tx = fx - x0, ty = fy - y0;
    const size_t i00 = (size_t)y0 * (size_t)w + (size_t)x0, i01 = (size_t)y0 * (size_t)w + (size_t)x1;
    const size_t i10 = (size_t)y1 * (size_t)w + (size_t)x0, i11 = (size_t)y1 * (size_t)w + (size_t)x1;
    if (scored && (!scored[i00] || !scored[i01] || !scored[i10] || !scored[i11])) {
        *ok = 0;
        return 0.0;
    }
    return (1 - ty) * ((1 - tx) * f[i00] + tx * f[i01]) + ty * ((1 - tx) * f[i10] + tx * f[i11]);
}

/* The angular profile of the smoothed de-glowed field s on the annulus [r0, r1] (radii in 1-px
 * steps): at theta_j = 2 pi j / n_theta, f[j] = mean over the radii that sample inside the
 * image (and scored pixels) of s - 1; valid[j] = 1 when at least half the radii do. s has ring
 * mean 1 (the radial profile is divided out), so f is the relative fluctuation around the
 * vanishing point; a radial streak is constant along r and survives the average. */
static void arc_profile(const double *s, const unsigned char *scored, int w, int h, const gr_structure_options *o,
                        double r0, double r1, double *f, unsigned char *valid)
{
    const int nt = o->n_theta;
    int nr = (int)floor(r1 - r0);
    if (nr < 1) nr = 1;
    const double dr = (r1 - r0) / nr;
    for (int j = 0; j < nt; j++) {
        const double th = 2.0 * PI * j / nt, c = cos(th), sn = sin(th);
        double acc = 0.0;
        int nin = 0;
        for (int k = 0; k < nr; k++) {
            const double r = r0 + (k + 0.5) * dr;
            int ok = 1;
            const double v = sample(s, scored, w, h, o->vp_x + r * c, o->vp_y + r * sn, &ok);
            if (ok) acc += v - 1.0, nin++;
        }
        valid[j] = (unsigned char)(2 * nin >= nr && nin > 0);
        f[j] = valid[j] ? acc / nin : 0.0;
    }
}

/* Angular spectrum of one annulus of the smoothed de-glowed field s. Returns the arc analysed
 * in degrees (0: unusable) and fills P[0..m_max]. buf: 4 n_theta doubles. */
static double annulus_spectrum(const double *s, const unsigned char *scored, int w, int h,
                               const gr_structure_options *o, double r0, double r1, double *P, double *buf,
                               unsigned char *valid)
{
    const int nt = o->n_theta;
    double *f = buf, *wt = buf + nt;
    arc_profile(s, scored, w, h, o, r0, r1, f, valid);
    /* the longest circular run of valid angles */
    int nvalid = 0;
    for (int j = 0; j < nt; j++) nvalid += valid[j];
    int start = 0, len = 0;
    if (nvalid == nt) {
        len = nt;
    } else if (nvalid > 0) {
        for (int j = 0; j < nt; j++) {
            if (!valid[j] || valid[(j + nt - 1) % nt]) continue; /* runs start after an invalid angle */
            int l = 0;
            while (l < nt && valid[(j + l) % nt]) l++;
            if (l > len) len = l, start = j;
        }
    }
    memset(P, 0, (size_t)(o->m_max + 1) * sizeof(double));
    /* an arc must hold 32 samples (11 degrees at the default 1024 per turn) */
    if (len < 32) return 0.0;
    /* window: none on a full turn (periodic); Hann on a partial arc (limits leakage from the
     * arc's ends); the weighted mean is removed first */
    double sw = 0.0, swf = 0.0;
    for (int l = 0; l < len; l++) {
        wt[l] = len == nt ? 1.0 : pow(sin(PI * (l + 0.5) / len), 2.0);
        sw += wt[l], swf += wt[l] * f[(start + l) % nt];
    }
    /* e^{-i m theta_j} = e^{-i 2 pi ((m j) mod N) / N}: one table of N cosines and sines */
    double *ct = buf + 2 * (size_t)nt, *st = buf + 3 * (size_t)nt;
    for (int j = 0; j < nt; j++) ct[j] = cos(2.0 * PI * j / nt), st[j] = sin(2.0 * PI * j / nt);
    for (int l = 0; l < len; l++) wt[l] *= f[(start + l) % nt] - swf / sw; /* wt now holds w (f - mean) */
    for (int m = 1; m <= o->m_max; m++) {
        double re = 0.0, im = 0.0;
        for (int l = 0; l < len; l++) {
            const int k = (int)(((long long)m * ((start + l) % nt)) % nt);
            re += wt[l] * ct[k];
            im -= wt[l] * st[k];
        }
        P[m] = 2.0 * (re * re + im * im) / (sw * sw);
    }
    return 360.0 * len / nt;
}

/* Luminance, the fine and coarse blurs (normalized convolution over scored pixels), and the
 * band-pass contrast field. */
static gr_status fields(const gr_image *img, const gr_structure_options *o, double *y, double *gf, double *gc,
                        double *mean_y, double *eps, gr_error *err)
{
    const int w = img->width, h = img->height;
    const size_t n = (size_t)w * (size_t)h;
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    double *wt = NULL;
    if (o->scored) {
        wt = malloc(n * sizeof(double));
        if (!wt) return gr_fail(err, GR_E_NOMEM, "structure: out of memory");
        for (size_t p = 0; p < n; p++) wt[p] = o->scored[p] ? 1.0 : 0.0;
    }
    double sum = 0.0;
    long long cnt = 0;
    for (size_t p = 0; p < n; p++) {
        const float *px = img->pixels + p * (size_t)img->nchannels;
        y[p] = GR_LUM_R * px[rgb[0]] + GR_LUM_G * px[rgb[1]] + GR_LUM_B * px[rgb[2]];
        if (!o->scored || o->scored[p]) sum += y[p], cnt++;
    }
    *mean_y = cnt ? sum / (double)cnt : 0.0;
    /* De-glow: divide Y by its own radial profile, the mean over scored pixels of each ring of
     * the radial coordinate q (the distance to the vanishing point in px, or the caller's field
     * such as the angle to the sun), linearly interpolated in q between the rings' mean q. What
     * remains is the structure that no function of q (a glow around the sun) can explain; the
     * glow itself is measured by the radial profile chart (report/profile). Interpolating
     * matters: a step profile leaves a sawtooth on a steep core that any two images with the
     * same core share. */
    const double bin = o->radial ? o->radial_bin : 1.0;
    double qmax = 0.0;
    for (int py = 0; py < h; py++)
        for (int px = 0; px < w; px++) {
            const size_t p = (size_t)py * (size_t)w + (size_t)px;
            const double q = o->radial ? o->radial[p] : hypot(px + 0.5 - o->vp_x, py + 0.5 - o->vp_y);
            if (q > qmax) qmax = q;
        }
    const int nring = (int)(qmax / bin) + 2;
    double *ring = calloc(3 * (size_t)nring, sizeof(double)); /* sum y, count, sum q */
    if (!ring) {
        free(wt);
        return gr_fail(err, GR_E_NOMEM, "structure: out of memory");
    }
    for (int py = 0; py < h; py++)
        for (int px = 0; px < w; px++) {
            const size_t p = (size_t)py * (size_t)w + (size_t)px;
            if (o->scored && !o->scored[p]) continue;
            const double q = o->radial ? o->radial[p] : hypot(px + 0.5 - o->vp_x, py + 0.5 - o->vp_y);
            const int k = (int)(fmax(q, 0.0) / bin);
            ring[3 * k] += y[p], ring[3 * k + 1] += 1.0, ring[3 * k + 2] += q;
        }
    const double floor_y = 1e-3 * fabs(*mean_y) + 1e-30;
    for (int py = 0; py < h; py++)
        for (int px = 0; px < w; px++) {
            const size_t p = (size_t)py * (size_t)w + (size_t)px;
            const double q = o->radial ? o->radial[p] : hypot(px + 0.5 - o->vp_x, py + 0.5 - o->vp_y);
            const int k = (int)(fmax(q, 0.0) / bin);
            double rm = 0.0;
            if (ring[3 * k + 1] > 0) {
                const double ck = ring[3 * k + 2] / ring[3 * k + 1], mk = ring[3 * k] / ring[3 * k + 1];
                const int j = q < ck ? k - 1 : k + 1;
                rm = mk;
                if (j >= 0 && j < nring && ring[3 * j + 1] > 0) {
                    const double cj = ring[3 * j + 2] / ring[3 * j + 1], mj = ring[3 * j] / ring[3 * j + 1];
                    if (cj != ck) rm = mk + (mj - mk) * (q - ck) / (cj - ck);
                }
            }
            y[p] = y[p] / (fmax(rm, 0.0) + floor_y);
        }
    free(ring);
    const double *src[1] = {y};
    double *dst[1] = {gf};
    gr_status st = gr_blur_fields(src, 1, wt, w, h, o->sigma_fine_px, gr_blur_radius(o->sigma_fine_px), dst, NULL, err);
    dst[0] = gc;
    if (st == GR_OK)
        st = gr_blur_fields(src, 1, wt, w, h, o->sigma_coarse_px, gr_blur_radius(o->sigma_coarse_px), dst, NULL, err);
    free(wt);
    if (st != GR_OK) return st;
    double sc = 0.0;
    for (size_t p = 0; p < n; p++)
        if (!o->scored || o->scored[p]) sc += gc[p];
    *eps = o->eps_rel * fmax(cnt ? sc / (double)cnt : 0.0, 0.0);
    if (!(*eps > 0.0)) *eps = 1e-30;
    return GR_OK;
}

/* One image: fills out and the contrast field c[n]. */
static gr_status one_image(const gr_image *img, const gr_structure_options *o, gr_structure_image *out, double *c,
                           gr_error *err)
{
    const int w = img->width, h = img->height;
    const size_t n = (size_t)w * (size_t)h;
    memset(out, 0, sizeof *out);
    double *y = malloc(n * sizeof(double)), *gf = malloc(n * sizeof(double)), *gc = malloc(n * sizeof(double));
    double *buf = malloc(4 * (size_t)o->n_theta * sizeof(double));
    unsigned char *valid = malloc((size_t)o->n_theta);
    gr_status st = GR_OK;
    if (!y || !gf || !gc || !buf || !valid) {
        st = gr_fail(err, GR_E_NOMEM, "structure: out of memory for a %d x %d image", w, h);
        goto done;
    }
    double eps = 1e-30;
    st = fields(img, o, y, gf, gc, &out->mean_y, &eps, err);
    if (st != GR_OK) goto done;
    /* C = (G_f * Y - G_c * Y) / (G_c * Y + eps): the band-limited contrast (Peli 1990) */
    double s2 = 0.0;
    long long cnt = 0;
    for (size_t p = 0; p < n; p++) {
        const double den = fmax(gc[p], 0.0) + eps;
        c[p] = (gf[p] - gc[p]) / den;
        if (!o->scored || o->scored[p]) s2 += c[p] * c[p], cnt++;
    }
    out->streak_contrast = cnt ? sqrt(s2 / (double)cnt) : 0.0;
    /* angular spectra of the finely smoothed luminance (the fine blur limits aliasing of
     * pixel noise into the angular samples) */
    out->n_annuli = o->n_annuli, out->m_max = o->m_max, out->m_min = o->m_min;
    double mean_p[GR_STRUCT_MAX_M + 1] = {0};
    for (int a = 0; a < o->n_annuli; a++) {
        out->r0[a] = o->r_min_px + (o->r_max_px - o->r_min_px) * a / o->n_annuli;
        out->r1[a] = o->r_min_px + (o->r_max_px - o->r_min_px) * (a + 1) / o->n_annuli;
        out->arc_deg[a] = annulus_spectrum(gf, o->scored, w, h, o, out->r0[a], out->r1[a], out->spectrum[a], buf, valid);
        if (out->arc_deg[a] > 0.0) {
            out->n_usable++;
            for (int m = o->m_min; m <= o->m_max; m++) {
                out->angular_power += out->spectrum[a][m];
                mean_p[m] += out->spectrum[a][m];
            }
        }
    }
    if (out->n_usable) out->angular_power /= out->n_usable;
    out->peak_m = o->m_min;
    for (int m = o->m_min; m <= o->m_max; m++)
        if (mean_p[m] > mean_p[out->peak_m]) out->peak_m = m;
done:
    free(y), free(gf), free(gc), free(buf), free(valid);
    return st;
}

static gr_status check_img(const gr_image *img, const char *role, gr_error *err)
{
    if (!img || !img->pixels || img->width < 1 || img->height < 1)
        return gr_fail(err, GR_E_INPUT, "structure: no %s image", role);
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->nchannels;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(img->pixels[i]))
            return gr_fail(err, GR_E_INPUT, "structure: the %s image has a non-finite sample", role);
    return GR_OK;
}

gr_status gr_structure_angular_profile(const gr_image *img, const gr_structure_options *opt, double r0, double r1,
                                       double *f, unsigned char *valid, gr_error *err)
{
    if (!f || !valid) return gr_fail(err, GR_E_INPUT, "structure: NULL profile arrays");
    gr_status st = check_img(img, "input", err);
    gr_structure_options o;
    if (st == GR_OK) st = resolve(opt, img->width, img->height, &o, err);
    if (st != GR_OK) return st;
    if (!(r0 >= 0.0) || !(r1 > r0) || !isfinite(r1)) return gr_fail(err, GR_E_INPUT, "structure: need 0 <= r0 < r1");
    const int w = img->width, h = img->height;
    const size_t n = (size_t)w * (size_t)h;
    double *y = malloc(n * sizeof(double)), *gf = malloc(n * sizeof(double)), *gc = malloc(n * sizeof(double));
    if (!y || !gf || !gc) {
        st = gr_fail(err, GR_E_NOMEM, "structure: out of memory");
        goto done;
    }
    double mean_y, eps;
    st = fields(img, &o, y, gf, gc, &mean_y, &eps, err);
    if (st != GR_OK) goto done;
    arc_profile(gf, o.scored, w, h, &o, r0, r1, f, valid);
done:
    free(y), free(gf), free(gc);
    return st;
}

gr_status gr_structure_image_compute(const gr_image *img, const gr_structure_options *opt, gr_structure_image *out,
                                     float *contrast, gr_error *err)
{
    if (!out) return gr_fail(err, GR_E_INPUT, "structure: NULL result");
    gr_status st = check_img(img, "input", err);
    gr_structure_options o;
    if (st == GR_OK) st = resolve(opt, img->width, img->height, &o, err);
    if (st != GR_OK) return st;
    const size_t n = (size_t)img->width * (size_t)img->height;
    double *c = malloc(n * sizeof(double));
    if (!c) return gr_fail(err, GR_E_NOMEM, "structure: out of memory");
    st = one_image(img, &o, out, c, err);
    if (st == GR_OK && contrast)
        for (size_t p = 0; p < n; p++) contrast[p] = (float)c[p];
    free(c);
    return st;
}

/* The reference's half (structure.h): its resolved options over copies of what they point at,
 * its R, G, B (to recognize it), its per-image measures and its band-pass contrast. */
struct gr_structure_ref {
    gr_structure_options o;
    int w, h;
    float *rgb;
    unsigned char *scored;
    float *radial;
    gr_structure_image im;
    double *c;
};

void gr_structure_ref_destroy(gr_structure_ref *r)
{
    if (!r) return;
    free(r->rgb);
    free(r->scored);
    free(r->radial);
    free(r->c);
    free(r);
}

static void copy_rgb(const gr_image *img, float *out)
{
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    const size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < n; p++)
        for (int k = 0; k < 3; k++) out[3 * p + k] = img->pixels[p * (size_t)img->nchannels + (size_t)rgb[k]];
}

gr_status gr_structure_ref_create(const gr_image *ref, const gr_structure_options *opt, gr_structure_ref **out,
                                  gr_error *err)
{
    *out = NULL;
    gr_status st = check_img(ref, "reference", err);
    gr_structure_options o;
    if (st == GR_OK) st = resolve(opt, ref->width, ref->height, &o, err);
    if (st != GR_OK) return st;
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    gr_structure_ref *r = calloc(1, sizeof *r);
    if (r) {
        r->rgb = malloc(3 * n * sizeof *r->rgb);
        r->c = malloc(n * sizeof *r->c);
        if (o.scored && (r->scored = malloc(n))) memcpy(r->scored, o.scored, n);
        if (o.radial && (r->radial = malloc(n * sizeof *r->radial))) memcpy(r->radial, o.radial, n * sizeof *r->radial);
    }
    if (!r || !r->rgb || !r->c || (o.scored && !r->scored) || (o.radial && !r->radial)) {
        gr_structure_ref_destroy(r);
        return gr_fail(err, GR_E_NOMEM, "structure: out of memory");
    }
    o.scored = r->scored;
    o.radial = r->radial;
    r->o = o;
    r->w = ref->width;
    r->h = ref->height;
    copy_rgb(ref, r->rgb);
    if ((st = one_image(ref, &r->o, &r->im, r->c, err)) != GR_OK) {
        gr_structure_ref_destroy(r);
        return st;
    }
    *out = r;
    return GR_OK;
}

int gr_structure_ref_matches(const gr_structure_ref *r, const gr_image *ref, const gr_structure_options *opt)
{
    gr_structure_options o;
    gr_error e;
    if (!r || check_img(ref, "reference", &e) != GR_OK || ref->width != r->w || ref->height != r->h ||
        resolve(opt, ref->width, ref->height, &o, &e) != GR_OK)
        return 0;
    const gr_structure_options *a = &r->o;
    if (a->vp_x != o.vp_x || a->vp_y != o.vp_y || a->sigma_fine_px != o.sigma_fine_px ||
        a->sigma_coarse_px != o.sigma_coarse_px || a->eps_rel != o.eps_rel || a->n_annuli != o.n_annuli ||
        a->r_min_px != o.r_min_px || a->r_max_px != o.r_max_px || a->n_theta != o.n_theta || a->m_max != o.m_max ||
        a->m_min != o.m_min || a->radial_bin != o.radial_bin || !a->scored != !o.scored || !a->radial != !o.radial)
        return 0;
    const size_t n = (size_t)r->w * (size_t)r->h;
    if (o.scored && memcmp(a->scored, o.scored, n) != 0) return 0;
    if (o.radial && memcmp(a->radial, o.radial, n * sizeof *o.radial) != 0) return 0;
    float *rgb = malloc(3 * n * sizeof *rgb);
    if (!rgb) return 0;
    copy_rgb(ref, rgb);
    const int same = memcmp(rgb, r->rgb, 3 * n * sizeof *rgb) == 0;
    free(rgb);
    return same;
}

gr_status gr_structure_compare_ref(const gr_structure_ref *r, const gr_image *test, gr_structure_compare *out,
                                   gr_error *err)
{
    if (!out || !r) return gr_fail(err, GR_E_INPUT, "structure: NULL result or reference");
    gr_status st = check_img(test, "test", err);
    if (st != GR_OK) return st;
    if (r->w != test->width || r->h != test->height)
        return gr_fail(err, GR_E_INPUT, "structure: size mismatch: reference %d x %d, test %d x %d", r->w, r->h,
                       test->width, test->height);
    const gr_structure_options o = r->o;
    memset(out, 0, sizeof *out);
    const size_t n = (size_t)r->w * (size_t)r->h;
    const double *cr = r->c;
    double *ct = malloc(n * sizeof(double));
    if (!ct) return gr_fail(err, GR_E_NOMEM, "structure: out of memory");
    out->ref = r->im;
    st = one_image(test, &o, &out->test, ct, err);
    if (st == GR_OK) {
        /* Pearson correlation over scored pixels, sums in double */
        double sr = 0, stt = 0, srr = 0, stt2 = 0, srt = 0;
        long long cnt = 0;
        for (size_t p = 0; p < n; p++) {
            if (o.scored && !o.scored[p]) continue;
            sr += cr[p], stt += ct[p], srr += cr[p] * cr[p], stt2 += ct[p] * ct[p], srt += cr[p] * ct[p];
            cnt++;
        }
        if (cnt > 1) {
            const double N = (double)cnt, vr = srr - sr * sr / N, vt = stt2 - stt * stt / N, cv = srt - sr * stt / N;
            /* a field whose variance is at rounding level (a featureless image) has no pattern to
             * correlate: 0 */
            const double tiny = 1e-20 * N;
            out->bandpass_corr = vr > tiny && vt > tiny ? cv / sqrt(vr * vt) : 0.0;
        }
        const double ca = out->ref.streak_contrast, cb = out->test.streak_contrast;
        out->contrast_ratio = ca > 0.0 ? cb / ca : 0.0;
        out->contrast_log_err = ca > 0.0 && cb > 0.0 ? fabs(log(cb / ca)) : (ca == cb ? 0.0 : 50.0);
        out->power_ratio = out->ref.angular_power > 0.0 ? out->test.angular_power / out->ref.angular_power : 0.0;
        /* log-spectral distance over annuli usable in both */
        double mp = 0.0;
        int k = 0;
        for (int a = 0; a < o.n_annuli; a++)
            if (out->ref.arc_deg[a] > 0.0 && out->test.arc_deg[a] > 0.0)
                for (int m = o.m_min; m <= o.m_max; m++) mp += out->ref.spectrum[a][m], k++;
        if (k > 0) {
            const double f = fmax(0.01 * mp / k, 1e-30);
            double s = 0.0;
            for (int a = 0; a < o.n_annuli; a++)
                if (out->ref.arc_deg[a] > 0.0 && out->test.arc_deg[a] > 0.0)
                    for (int m = o.m_min; m <= o.m_max; m++) {
                        const double d = log10((out->test.spectrum[a][m] + f) / (out->ref.spectrum[a][m] + f));
                        s += d * d;
                    }
            out->spectrum_log_dist = sqrt(s / k);
        }
    }
    free(ct);
    return st;
}

gr_status gr_structure_compare_images(const gr_image *ref, const gr_image *test, const gr_structure_options *opt,
                                      gr_structure_compare *out, gr_error *err)
{
    if (!out) return gr_fail(err, GR_E_INPUT, "structure: NULL result");
    gr_structure_ref *r = NULL; /* create checks the reference, compare_ref the test and sizes */
    gr_status st = gr_structure_ref_create(ref, opt, &r, err);
    if (st == GR_OK) st = gr_structure_compare_ref(r, test, out, err);
    gr_structure_ref_destroy(r);
    return st;
}
