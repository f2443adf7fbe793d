/* LDR-FLIP and HDR-FLIP (see flip.h; derivation in docs/metrics.md "FLIP"). */
#include "compare/flip.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/clones.h"
#include "common/parallel.h"
#include "compare/channels.h"
#include "image/oiio.h"

#define PI 3.14159265358979323846

/* Linear sRGB (Rec. 709 primaries, D65) to CIE XYZ (IEC 61966-2-1). */
static const double M_RGB2XYZ[3][3] = {{0.4123907992659595, 0.3575843393838780, 0.1804807884018343},
                                       {0.2126390058715104, 0.7151686787677559, 0.0721923153607337},
                                       {0.0193308187155918, 0.1191947797946259, 0.9505321522496606}};
/* Its inverse. */
static const double M_XYZ2RGB[3][3] = {{3.2409699419045213, -1.5373831775700935, -0.4986107602930033},
                                       {-0.9692436362808798, 1.8759675015077206, 0.0415550574071756},
                                       {0.0556300796969936, -0.2039769588889765, 1.0569715142428784}};

/* FLIP constants (HPG 2020 paper, sections 3-4). */
#define QC 0.7          /* colour-difference exponent */
#define PC 0.4          /* breakpoint of the error redistribution, fraction of cmax */
#define PT 0.95         /* error value at the breakpoint */
#define QF 0.5          /* feature-difference exponent */
#define FEAT_W 0.082    /* feature width, degrees: sigma = 0.5 * w * ppd */
/* CSF sum-of-Gaussians parameters (a1, b1, a2, b2) per opponent channel: achromatic,
 * red-green, blue-yellow (after Johnson and Fairchild / Mullen, paper eq. 2). */
static const double CSF[3][4] = {{1.0, 0.0047, 0.0, 1e-5}, {1.0, 0.0053, 0.0, 1e-5}, {34.1, 0.04, 13.5, 0.025}};

const char *gr_flip_mode_name(gr_flip_mode m) { return m == GR_FLIP_HDR ? "hdr" : "ldr"; }
const char *gr_flip_tonemapper_name(gr_flip_tonemapper t) { return t == GR_FLIP_TM_REINHARD ? "reinhard" : "aces"; }

static void mat3(const double m[3][3], const double in[3], double out[3])
{
    for (int i = 0; i < 3; i++) out[i] = m[i][0] * in[0] + m[i][1] * in[1] + m[i][2] * in[2];
}

/* The reference white: XYZ of linear RGB (1, 1, 1), i.e. D65 with Y = 1. */
static void white_xyz(double w[3])
{
    const double one[3] = {1.0, 1.0, 1.0};
    mat3(M_RGB2XYZ, one, w);
}

/* CIELAB's f(t) (CIE 15:2004), delta = 6/29. */
static double lab_f(double t)
{
    const double d = 6.0 / 29.0;
    return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

/* Linear RGB (clamped to [0, 1] by the caller) to Hunt-adjusted CIELAB: (L, 0.01 L a, 0.01 L b). */
static void rgb_to_hunt_lab(const double rgb[3], const double wh[3], double out[3])
{
    double xyz[3];
    mat3(M_RGB2XYZ, rgb, xyz);
    const double fx = lab_f(xyz[0] / wh[0]), fy = lab_f(xyz[1] / wh[1]), fz = lab_f(xyz[2] / wh[2]);
    const double L = 116.0 * fy - 16.0, a = 500.0 * (fx - fy), b = 200.0 * (fy - fz);
    out[0] = L;
    out[1] = 0.01 * L * a; /* Hunt effect: chroma perceived grows with luminance */
    out[2] = 0.01 * L * b;
}

/* HyAB distance (Abasi et al. 2020): |dL| + Euclidean distance in (a, b). */
static double hyab(const double p[3], const double q[3])
{
    const double da = p[1] - q[1], db = p[2] - q[2];
    return fabs(p[0] - q[0]) + sqrt(da * da + db * db);
}

/* Correlation along x (dir 0) or y (dir 1) of a planar field with a 1-D kernel k[-r..r]
 * (k + r is the centre), edges clamped (the nearest in-image pixel is repeated). */
GR_CLONES_AVX2 static void conv1d(const double *src, double *dst, int w, int h, const double *k, int r, int dir)
{
    /* The same sums in the same order as the direct form s = sum_{i=-r..r} k[i + r] src(clamped),
     * arranged for speed: rows without clamping in their interior (x), whole rows at once (y). */
    if (dir == 0) {
        for (int y = 0; y < h; y++) {
            const double *row = src + (size_t)y * (size_t)w;
            double *out = dst + (size_t)y * (size_t)w;
            for (int x = 0; x < w; x++) {
                double s = 0.0;
                if (x >= r && x + r < w) {
                    const double *q = row + x - r;
                    for (int i = 0; i <= 2 * r; i++) s += k[i] * q[i];
                } else {
                    for (int i = -r; i <= r; i++) {
                        int xx = x + i;
                        xx = xx < 0 ? 0 : (xx >= w ? w - 1 : xx);
                        s += k[i + r] * row[xx];
                    }
                }
                out[x] = s;
            }
        }
    } else {
        for (int y = 0; y < h; y++) {
            double *out = dst + (size_t)y * (size_t)w;
            for (int x = 0; x < w; x++) out[x] = 0.0;
            for (int i = -r; i <= r; i++) {
                int yy = y + i;
                yy = yy < 0 ? 0 : (yy >= h ? h - 1 : yy);
                const double *row = src + (size_t)yy * (size_t)w, kk = k[i + r];
                for (int x = 0; x < w; x++) out[x] += kk * row[x];
            }
        }
    }
}

/* Separable filter kx (along x) then ky (along y); tmp is scratch of the same size. */
static void conv_sep(const double *src, double *dst, double *tmp, int w, int h, const double *kx, const double *ky,
                     int r)
{
    conv1d(src, tmp, w, h, kx, r, 0);
    conv1d(tmp, dst, w, h, ky, r, 1);
}

/* Working memory for one LDR-FLIP evaluation at one size. */
typedef struct flip_ws {
    int w, h;
    size_t n;
    int rc;                  /* CSF kernel radius */
    double *csf_g[3][2];     /* 1-D Gaussians g_k(i) = exp(-pi^2 (i / ppd)^2 / b_k), normalized per channel */
    double csf_wt[3][2];     /* weight of each separable term */
    int rf;                  /* feature kernel radius */
    double *fe, *fp, *fg;    /* 1-D edge, point and smoothing kernels */
    double *plane[3][2];     /* YCxCz planes of ref (0) and test (1) */
    double *filt[3][2];      /* CSF-filtered planes */
    double *tmp, *tmp2;
    double *feat[2][2][2];   /* [image][edge/point][x/y] responses */
    double cmax;
} flip_ws;

static void ws_free(flip_ws *s)
{
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 2; k++) free(s->csf_g[c][k]), free(s->plane[c][k]), free(s->filt[c][k]);
    free(s->fe), free(s->fp), free(s->fg), free(s->tmp), free(s->tmp2);
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) free(s->feat[i][j][k]);
    memset(s, 0, sizeof *s);
}

/* Normalizes the positive and the negative entries of k[0..n) separately to sums +1 and -1
 * (the paper's feature filters: a uniform region gives 0, a full-contrast step gives 1). */
static void norm_signs(double *k, int n)
{
    double sp = 0.0, sn = 0.0;
    for (int i = 0; i < n; i++) {
        if (k[i] > 0) sp += k[i];
        else sn -= k[i];
    }
    for (int i = 0; i < n; i++) {
        if (k[i] > 0) k[i] /= sp;
        else if (k[i] < 0) k[i] /= sn;
    }
}

/* images: which of the pair's planes to allocate (bit 0 the reference's, bit 1 the test's):
 * with a prepared reference only the test's, for the reference's half only its own. */
static gr_status ws_init(flip_ws *s, int w, int h, double ppd, unsigned images, gr_error *err)
{
    memset(s, 0, sizeof *s);
    s->w = w, s->h = h, s->n = (size_t)w * (size_t)h;
    /* CSF filters: the 2-D kernel sum_k a_k sqrt(pi / b_k) exp(-pi^2 |x|^2 / b_k), x in degrees,
     * normalized to sum 1; one radius for all, 3 standard deviations of the widest Gaussian
     * (b = 0.04: sigma = sqrt(b / (2 pi^2)) degrees). Each term is separable, so the 2-D sum
     * is applied as two separable passes weighted by their share of the kernel's total. */
    double bmax = 0.0;
    for (int c = 0; c < 3; c++) bmax = fmax(bmax, fmax(CSF[c][1], CSF[c][3]));
    s->rc = (int)ceil(3.0 * sqrt(bmax / (2.0 * PI * PI)) * ppd);
    const int nc = 2 * s->rc + 1;
    for (int c = 0; c < 3; c++) {
        double total = 0.0, sum1[2] = {0.0, 0.0};
        for (int k = 0; k < 2; k++) {
            s->csf_g[c][k] = malloc((size_t)nc * sizeof(double));
            if (!s->csf_g[c][k]) goto nomem;
            const double b = CSF[c][2 * k + 1];
            for (int i = -s->rc; i <= s->rc; i++) {
                const double x = (double)i / ppd;
                s->csf_g[c][k][i + s->rc] = exp(-PI * PI * x * x / b);
                sum1[k] += s->csf_g[c][k][i + s->rc];
            }
            s->csf_wt[c][k] = CSF[c][2 * k] * sqrt(PI / b);
            total += s->csf_wt[c][k] * sum1[k] * sum1[k];
        }
        /* Term k contributes wt_k g_k(i) g_k(j) / total = (wt_k S_k^2 / total) * (g_k / S_k)(i) (g_k / S_k)(j). */
        for (int k = 0; k < 2; k++) {
            for (int i = 0; i < nc; i++) s->csf_g[c][k][i] /= sum1[k];
            s->csf_wt[c][k] = s->csf_wt[c][k] * sum1[k] * sum1[k] / total;
        }
    }
    /* Feature filters: first and second derivatives of a Gaussian of sigma 0.5 w ppd pixels,
     * radius ceil(3 sigma); each sign's weights normalized separately (paper section 4.2). The
     * 2-D kernels -x g(x) g(y) and (x^2 / s^2 - 1) g(x) g(y) so normalized are the 1-D ones
     * along x times the normalized Gaussian along y. */
    const double sd = 0.5 * FEAT_W * ppd;
    s->rf = (int)ceil(3.0 * sd);
    const int nf = 2 * s->rf + 1;
    s->fe = malloc((size_t)nf * sizeof(double));
    s->fp = malloc((size_t)nf * sizeof(double));
    s->fg = malloc((size_t)nf * sizeof(double));
    if (!s->fe || !s->fp || !s->fg) goto nomem;
    double sg = 0.0;
    for (int i = -s->rf; i <= s->rf; i++) {
        const double x = (double)i, g = exp(-x * x / (2.0 * sd * sd));
        s->fg[i + s->rf] = g;
        s->fe[i + s->rf] = -x * g;
        s->fp[i + s->rf] = (x * x / (sd * sd) - 1.0) * g;
        sg += g;
    }
    for (int i = 0; i < nf; i++) s->fg[i] /= sg;
    norm_signs(s->fe, nf);
    norm_signs(s->fp, nf);
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 2; k++) {
            if (!(images & (1u << k))) continue;
            s->plane[c][k] = malloc(s->n * sizeof(double));
            s->filt[c][k] = malloc(s->n * sizeof(double));
            if (!s->plane[c][k] || !s->filt[c][k]) goto nomem;
        }
    s->tmp = malloc(s->n * sizeof(double));
    s->tmp2 = malloc(s->n * sizeof(double));
    if (!s->tmp || !s->tmp2) goto nomem;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++)
                if ((images & (1u << i)) && !(s->feat[i][j][k] = malloc(s->n * sizeof(double)))) goto nomem;
    /* cmax: the largest colour difference in the gamut, Hunt-adjusted HyAB between green and
     * blue, to the power q_c (paper section 4.1). */
    double wh[3], g[3], bl[3];
    white_xyz(wh);
    const double green[3] = {0.0, 1.0, 0.0}, blue[3] = {0.0, 0.0, 1.0};
    rgb_to_hunt_lab(green, wh, g);
    rgb_to_hunt_lab(blue, wh, bl);
    s->cmax = pow(hyab(g, bl), QC);
    return GR_OK;
nomem:
    ws_free(s);
    return gr_fail(err, GR_E_NOMEM, "FLIP: out of memory for a %d x %d image", w, h);
}

/* Steps 1-3 of LDR-FLIP for image im of the pair (0 the reference, 1 the test), linear RGB in
 * [0, 1] interleaved (rgb[3 n]): the opponent planes, their CSF-filtered planes and the feature
 * responses, into the workspace. */
static void flip_half(flip_ws *s, int im, const double *rgb)
{
    double wh[3];
    white_xyz(wh);
    const int w = s->w, h = s->h;
    /* 1. Opponent space YCxCz (Zhang and Wandell's S-CIELAB linearization of CIELAB):
     *    Y' = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn). */
    for (size_t p = 0; p < s->n; p++) {
        double xyz[3];
        mat3(M_RGB2XYZ, rgb + 3 * p, xyz);
        const double xn = xyz[0] / wh[0], yn = xyz[1] / wh[1], zn = xyz[2] / wh[2];
        s->plane[0][im][p] = 116.0 * yn - 16.0;
        s->plane[1][im][p] = 500.0 * (xn - yn);
        s->plane[2][im][p] = 200.0 * (yn - zn);
    }
    /* 2. Contrast sensitivity: each opponent channel filtered with its CSF's spatial kernel. */
    for (int c = 0; c < 3; c++) {
        conv_sep(s->plane[c][im], s->filt[c][im], s->tmp, w, h, s->csf_g[c][0], s->csf_g[c][0], s->rc);
        if (s->csf_wt[c][1] > 0.0) {
            conv_sep(s->plane[c][im], s->tmp2, s->tmp, w, h, s->csf_g[c][1], s->csf_g[c][1], s->rc);
            for (size_t p = 0; p < s->n; p++)
                s->filt[c][im][p] = s->csf_wt[c][0] * s->filt[c][im][p] + s->csf_wt[c][1] * s->tmp2[p];
        }
    }
    /* 3. Features on the unfiltered normalized luminance y = (Y' + 16) / 116 = Y / Yn. */
    for (size_t p = 0; p < s->n; p++) s->tmp2[p] = (s->plane[0][im][p] + 16.0) / 116.0;
    const double *k1[2] = {s->fe, s->fp};
    for (int f = 0; f < 2; f++) {
        conv_sep(s->tmp2, s->feat[im][f][0], s->tmp, w, h, k1[f], s->fg, s->rf);
        conv_sep(s->tmp2, s->feat[im][f][1], s->tmp, w, h, s->fg, k1[f], s->rf);
    }
}

/* What steps 4-5 read of image im at pixel p: the filtered colour back in linear RGB, clamped
 * to the display gamut, as Hunt-adjusted CIELAB, and the edge and point feature magnitudes. */
static void half_pixel(const flip_ws *s, int im, size_t p, const double wh[3], double lab[3], double mag[2])
{
    const double yn = (s->filt[0][im][p] + 16.0) / 116.0;
    const double xyz[3] = {wh[0] * (s->filt[1][im][p] / 500.0 + yn), wh[1] * yn, wh[2] * (yn - s->filt[2][im][p] / 200.0)};
    double c[3];
    mat3(M_XYZ2RGB, xyz, c);
    for (int k = 0; k < 3; k++) c[k] = c[k] < 0.0 ? 0.0 : (c[k] > 1.0 ? 1.0 : c[k]);
    rgb_to_hunt_lab(c, wh, lab);
    for (int f = 0; f < 2; f++) mag[f] = hypot(s->feat[im][f][0][p], s->feat[im][f][1][p]);
}

/* Steps 4-6 per pixel into out[n]: the test's half from the workspace (image 1); the
 * reference's from ref_px (5 doubles a pixel: Lab, edge and point magnitudes, as half_pixel
 * gives them) or, when NULL, from the workspace (image 0). */
static void flip_combine(const flip_ws *s, const double *ref_px, float *out)
{
    double wh[3];
    white_xyz(wh);
    const double bp = PC * s->cmax;
    for (size_t p = 0; p < s->n; p++) {
        double lab[2][3], mag[2][2];
        if (ref_px) {
            memcpy(lab[0], ref_px + 5 * p, sizeof lab[0]);
            memcpy(mag[0], ref_px + 5 * p + 3, sizeof mag[0]);
        } else {
            half_pixel(s, 0, p, wh, lab[0], mag[0]);
        }
        half_pixel(s, 1, p, wh, lab[1], mag[1]);
        /* 4. Colour error: HyAB^q_c, redistributed so that [0, p_c cmax] maps to [0, p_t]
         *    and [p_c cmax, cmax] to [p_t, 1] (paper eq. 4). */
        const double dc = pow(hyab(lab[0], lab[1]), QC);
        const double ec = dc < bp ? (PT / bp) * dc : PT + (dc - bp) / (s->cmax - bp) * (1.0 - PT);
        /* 5. Feature error: max of the edge and point magnitude differences, over sqrt(2)
         *    (the largest magnitude of two unit responses), to the power q_f (paper eq. 6). */
        const double df = fmax(fabs(mag[0][0] - mag[1][0]), fabs(mag[0][1] - mag[1][1]));
        const double ef = pow(df / sqrt(2.0), QF);
        /* 6. FLIP = colour error ^ (1 - feature error) (paper eq. 7). */
        double e = pow(ec, 1.0 - ef);
        if (!(e >= 0.0)) e = 0.0;
        if (e > 1.0) e = 1.0;
        out[p] = (float)e;
    }
}

/* Tone mappers as (c0 x^2 + c1 x + c2) / (c3 x^2 + c4 x + c5) (HDR-FLIP paper, section 3). */
static void tm_coeffs(gr_flip_tonemapper tm, double c[6])
{
    if (tm == GR_FLIP_TM_REINHARD) {
        const double r[6] = {0.0, 1.0, 0.0, 0.0, 1.0, 1.0};
        memcpy(c, r, sizeof r);
    } else {
        /* Narkowicz: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) of 0.6 x */
        const double a[6] = {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};
        memcpy(c, a, sizeof a);
    }
}

static double tonemap(const double c[6], double x)
{
    const double v = (c[0] * x * x + c[1] * x + c[2]) / (c[3] * x * x + c[4] * x + c[5]);
    return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double lum(const gr_image *img, const int rgb[3], size_t p)
{
    const float *px = img->pixels + p * (size_t)img->nchannels;
    return GR_LUM_R * px[rgb[0]] + GR_LUM_G * px[rgb[1]] + GR_LUM_B * px[rgb[2]];
}

/* luminance of the negative-clamped colour (what the tone mappers see) */
static double lum_pos(const gr_image *img, const int rgb[3], size_t p)
{
    const float *px = img->pixels + p * (size_t)img->nchannels;
    return GR_LUM_R * fmax(0.0, px[rgb[0]]) + GR_LUM_G * fmax(0.0, px[rgb[1]]) + GR_LUM_B * fmax(0.0, px[rgb[2]]);
}

gr_status gr_flip_exposures(const gr_image *ref, gr_flip_tonemapper tm, double *start, double *stop, int *count,
                            gr_error *err)
{
    if (!ref || !start || !stop || !count) return gr_fail(err, GR_E_INPUT, "FLIP exposures: NULL argument");
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    double *y = malloc(n * sizeof(double));
    if (!y) return gr_fail(err, GR_E_NOMEM, "FLIP exposures: out of memory");
    int rgb[3];
    gr_metrics_pick_rgb(ref, rgb);
    for (size_t p = 0; p < n; p++) y[p] = lum(ref, rgb, p);
    qsort(y, n, sizeof(double), cmp_double);
    /* the median as the upper middle element for an even count (the rank n/2, 0-based) */
    const double ymax = y[n - 1], ymed = y[n / 2];
    free(y);
    if (!(ymax > 0.0) || !(ymed > 0.0))
        return gr_fail(err, GR_E_INPUT,
                       "FLIP exposures: the reference's luminance %s is not > 0; give the exposures explicitly",
                       ymax > 0.0 ? "median" : "maximum");
    /* x_0.85 solves (c0 - t c3) x^2 + (c1 - t c4) x + (c2 - t c5) = 0 for t = 0.85 */
    double c[6];
    tm_coeffs(tm, c);
    const double t = 0.85, qa = c[0] - t * c[3], qb = c[1] - t * c[4], qc = c[2] - t * c[5];
    const double x85 = fabs(qa) > 1e-12 ? (-qb + sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa) : -qc / qb;
    *start = log2(x85 / ymax);
    *stop = log2(x85 / ymed);
    const int k = (int)ceil(*stop - *start);
    *count = k < 2 ? 2 : k;
    return GR_OK;
}

static gr_status check_image(const gr_image *img, const char *role, gr_error *err)
{
    if (!img || !img->pixels) return gr_fail(err, GR_E_INPUT, "FLIP: no %s image", role);
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->nchannels;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(img->pixels[i])) return gr_fail(err, GR_E_INPUT, "FLIP: the %s image has a non-finite sample", role);
    return GR_OK;
}

/* Image im's exposure, tone mapped (HDR) and clamped to [0, 1], into rgb[3 n]: scale times
 * the image first (the test's fitted scale; 1 for the reference). HDR: the exposure's gain,
 * then ACES per channel or Reinhard on luminance (colour / (1 + Y)), which keeps hues (checked
 * against the published tool: per channel it differs); the tone mapper's output is taken as
 * linear RGB (HDR-FLIP paper, section 3). */
static void tone_image(const gr_image *img, const int ch[3], double scale, const gr_flip_options *opt, double gain,
                       const double c[6], double *rgb)
{
    const size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < n; p++)
        for (int j = 0; j < 3; j++) {
            double v = scale * img->pixels[p * (size_t)img->nchannels + (size_t)ch[j]];
            if (opt->mode == GR_FLIP_HDR) {
                v = gain * (v < 0.0 ? 0.0 : v);
                v = opt->tonemapper == GR_FLIP_TM_REINHARD ? v / (1.0 + gain * scale * lum_pos(img, ch, p))
                                                           : tonemap(c, v);
            }
            rgb[3 * p + (size_t)j] = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
        }
}

/* Exposure k of nexp from start to stop (HDR), as a gain: c_k = start + k (stop - start) / (N - 1). */
static double exposure_gain(double start, double stop, int nexp, int k)
{
    const double ck = nexp > 1 ? start + (double)k * (stop - start) / (double)(nexp - 1) : start;
    return exp2(ck);
}

/* The reference's half, prepared (flip.h): per exposure, per pixel, what flip_combine reads of
 * the reference (5 doubles: Hunt-adjusted Lab of the filtered colour, edge and point
 * magnitudes). */
struct gr_flip_reference {
    const gr_image *ref;
    int w, h;
    gr_flip_mode mode;
    double ppd;
    gr_flip_tonemapper tonemapper;
    int given;                 /* the options gave the exposures (else derived from ref) */
    int undefined;             /* HDR, derived: the reference gives no range (why) */
    char why[256];
    double start, stop;
    int nexp;                  /* exposures (1 for LDR) */
    double *px;                /* nexp x n x 5; NULL when over the caller's bound */
};

/* The options' exposure range for ref, checked (HDR; LDR: one exposure). */
static gr_status resolve_exposures(const gr_image *ref, const gr_flip_options *opt, double *start, double *stop,
                                   int *nexp, gr_error *err)
{
    *start = *stop = 0.0;
    *nexp = 0;
    if (opt->mode != GR_FLIP_HDR) return GR_OK;
    if (opt->exposures_given) {
        if (!isfinite(opt->start_exposure) || !isfinite(opt->stop_exposure) || opt->stop_exposure < opt->start_exposure ||
            opt->n_exposures < 1)
            return gr_fail(err, GR_E_INPUT, "FLIP: exposures start %g stop %g count %d: need start <= stop, count >= 1",
                           opt->start_exposure, opt->stop_exposure, opt->n_exposures);
        *start = opt->start_exposure, *stop = opt->stop_exposure, *nexp = opt->n_exposures;
        return GR_OK;
    }
    return gr_flip_exposures(ref, opt->tonemapper, start, stop, nexp, err);
}

static double options_ppd(const gr_flip_options *opt) { return opt->ppd == 0.0 ? GR_FLIP_DEFAULT_PPD : opt->ppd; }

/* Does prepared reference r serve ref with these options and this resolved range? */
static int reference_matches(const gr_flip_reference *r, const gr_image *ref, const gr_flip_options *opt, double ppd,
                             double start, double stop, int nexp)
{
    return r->ref == ref && r->w == ref->width && r->h == ref->height && r->mode == opt->mode && r->ppd == ppd &&
           (opt->mode != GR_FLIP_HDR || (r->tonemapper == opt->tonemapper && !r->undefined && r->start == start &&
                                         r->stop == stop && r->nexp == nexp));
}

gr_status gr_flip_compute(const gr_image *ref, const gr_image *test, const gr_flip_options *opt, float *map,
                          gr_flip_result *res, gr_error *err)
{
    const gr_flip_options zero = {0};
    if (!opt) opt = &zero;
    if (!res) return gr_fail(err, GR_E_INPUT, "FLIP: NULL result");
    gr_status st = check_image(ref, "reference", err);
    if (st == GR_OK) st = check_image(test, "test", err);
    if (st != GR_OK) return st;
    if (ref->width != test->width || ref->height != test->height)
        return gr_fail(err, GR_E_INPUT, "FLIP: size mismatch: reference %d x %d, test %d x %d", ref->width, ref->height,
                       test->width, test->height);
    const double ppd = options_ppd(opt);
    if (!(ppd > 0.0) || !isfinite(ppd)) return gr_fail(err, GR_E_INPUT, "FLIP: pixels per degree %g is not > 0", ppd);
    memset(res, 0, sizeof *res);
    res->mode = opt->mode;
    res->ppd = ppd;
    res->tonemapper = opt->tonemapper;
    const gr_flip_reference *prep = opt->reference;
    if (prep && opt->mode == GR_FLIP_HDR && !opt->exposures_given && prep->ref == ref && !prep->given &&
        !prep->undefined) {
        /* the prepared reference derived the range from this image already */
        res->start_exposure = prep->start, res->stop_exposure = prep->stop, res->n_exposures = prep->nexp;
    } else if (opt->mode == GR_FLIP_HDR) {
        st = resolve_exposures(ref, opt, &res->start_exposure, &res->stop_exposure, &res->n_exposures, err);
        if (st != GR_OK) return st;
    }
    const int nexp = opt->mode == GR_FLIP_HDR ? res->n_exposures : 1;
    /* a prepared reference serves only the image and the settings it was made for (a derived
     * range is the same numbers whichever call derived it) */
    if (prep && !reference_matches(prep, ref, opt, ppd, res->start_exposure, res->stop_exposure, nexp))
        return gr_fail(err, GR_E_INPUT, "FLIP: the prepared reference was made for another image or other options");
    const int w = ref->width, h = ref->height;
    const size_t n = (size_t)w * (size_t)h;
    const double *ref_px = prep ? prep->px : NULL; /* NULL: the reference's half computed here */
    flip_ws ws;
    st = ws_init(&ws, w, h, ppd, ref_px ? 2u : 3u, err);
    if (st != GR_OK) return st;
    double *rgb[2] = {ref_px ? NULL : malloc(3 * n * sizeof(double)), malloc(3 * n * sizeof(double))};
    float *e = malloc(n * sizeof(float)), *best = malloc(n * sizeof(float));
    double *sorted = malloc(n * sizeof(double));
    if ((!ref_px && !rgb[0]) || !rgb[1] || !e || !best || !sorted) {
        st = gr_fail(err, GR_E_NOMEM, "FLIP: out of memory for a %d x %d image", w, h);
        goto done;
    }
    int ch[2][3];
    gr_metrics_pick_rgb(ref, ch[0]);
    gr_metrics_pick_rgb(test, ch[1]);
    const double tscale = opt->test_scale == 0.0 ? 1.0 : opt->test_scale;
    if (!isfinite(tscale)) {
        st = gr_fail(err, GR_E_INPUT, "FLIP: test scale %g is not finite", tscale);
        goto done;
    }
    double c[6];
    tm_coeffs(opt->tonemapper, c);
    for (int k = 0; k < nexp; k++) {
        const double gain = exposure_gain(res->start_exposure, res->stop_exposure, nexp, k);
        if (!ref_px) {
            tone_image(ref, ch[0], 1.0, opt, gain, c, rgb[0]);
            flip_half(&ws, 0, rgb[0]);
        }
        tone_image(test, ch[1], tscale, opt, gain, c, rgb[1]);
        flip_half(&ws, 1, rgb[1]);
        flip_combine(&ws, ref_px ? ref_px + (size_t)k * n * 5 : NULL, e);
        /* HDR-FLIP: per pixel the largest error over the exposures */
        for (size_t p = 0; p < n; p++) best[p] = (k == 0 || e[p] > best[p]) ? e[p] : best[p];
    }
    double sum = 0.0, mn = INFINITY, mx = -INFINITY;
    size_t m = 0;
    for (size_t p = 0; p < n; p++) {
        if (opt->scored && !opt->scored[p]) continue;
        const double v = best[p];
        sum += v;
        mn = fmin(mn, v), mx = fmax(mx, v);
        sorted[m++] = v;
    }
    res->n_pooled = (long long)m;
    if (m > 0) {
        qsort(sorted, m, sizeof(double), cmp_double);
        res->mean = sum / (double)m, res->min = mn, res->max = mx;
        const double qs[3] = {0.25, 0.5, 0.75};
        double *dst[3] = {&res->q1, &res->median, &res->q3};
        for (int q = 0; q < 3; q++) {
            const double pos = qs[q] * (double)(m - 1);
            const size_t lo = (size_t)floor(pos), hi = lo + 1 < m ? lo + 1 : lo;
            *dst[q] = sorted[lo] + (pos - (double)lo) * (sorted[hi] - sorted[lo]);
        }
    }
    if (map) memcpy(map, best, n * sizeof(float));
done:
    free(rgb[0]), free(rgb[1]), free(e), free(best), free(sorted);
    ws_free(&ws);
    return st;
}


/* The reference's half of exposure k into px[n x 5] (one job of gr_flip_reference_create). */
typedef struct prep_job {
    gr_flip_reference *r;
    const gr_flip_options *opt;
} prep_job;

static gr_status prep_exposure(void *arg, int k, gr_error *err)
{
    prep_job *j = arg;
    gr_flip_reference *r = j->r;
    const size_t n = (size_t)r->w * (size_t)r->h;
    flip_ws ws;
    gr_status st = ws_init(&ws, r->w, r->h, r->ppd, 1u, err);
    if (st != GR_OK) return st;
    double *rgb = malloc(3 * n * sizeof(double));
    if (!rgb) {
        ws_free(&ws);
        return gr_fail(err, GR_E_NOMEM, "FLIP: out of memory for a %d x %d image", r->w, r->h);
    }
    int ch[3];
    gr_metrics_pick_rgb(r->ref, ch);
    double c[6], wh[3];
    tm_coeffs(r->tonemapper, c);
    white_xyz(wh);
    tone_image(r->ref, ch, 1.0, j->opt, exposure_gain(r->start, r->stop, r->nexp, k), c, rgb);
    flip_half(&ws, 0, rgb);
    double *out = r->px + (size_t)k * n * 5;
    for (size_t p = 0; p < n; p++) half_pixel(&ws, 0, p, wh, out + 5 * p, out + 5 * p + 3);
    free(rgb);
    ws_free(&ws);
    return GR_OK;
}

gr_status gr_flip_reference_create(const gr_image *ref, const gr_flip_options *opt, size_t max_bytes, int threads,
                                   gr_flip_reference **out, gr_error *err)
{
    const gr_flip_options zero = {0};
    if (!out) return gr_fail(err, GR_E_INPUT, "FLIP: NULL output");
    *out = NULL;
    if (!opt) opt = &zero;
    gr_status st = check_image(ref, "reference", err);
    if (st != GR_OK) return st;
    const double ppd = options_ppd(opt);
    if (!(ppd > 0.0) || !isfinite(ppd)) return gr_fail(err, GR_E_INPUT, "FLIP: pixels per degree %g is not > 0", ppd);
    gr_flip_reference *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "FLIP: out of memory");
    r->ref = ref, r->w = ref->width, r->h = ref->height, r->mode = opt->mode, r->ppd = ppd;
    r->tonemapper = opt->tonemapper;
    r->given = opt->mode == GR_FLIP_HDR && opt->exposures_given;
    r->nexp = 1;
    if (opt->mode == GR_FLIP_HDR) {
        gr_error e = {GR_OK, ""};
        st = resolve_exposures(ref, opt, &r->start, &r->stop, &r->nexp, &e);
        if (st == GR_E_INPUT && !r->given) {
            /* no range (a black truth): kept, so that gr_flip_compute_defined says so at once */
            r->undefined = 1, r->nexp = 0;
            snprintf(r->why, sizeof r->why, "%s", e.msg);
            *out = r;
            return GR_OK;
        }
        if (st != GR_OK) {
            free(r);
            return gr_fail(err, st, "%s", e.msg);
        }
    }
    const size_t n = (size_t)r->w * (size_t)r->h;
    if ((double)r->nexp * (double)n * 5.0 * sizeof(double) > (double)max_bytes) {
        *out = r; /* more memory than it is worth: no planes (every FLIP computes the reference's
                     half itself), the resolved range only, so that a kept one is not remade */
        return GR_OK;
    }
    r->px = malloc((size_t)r->nexp * n * 5 * sizeof(double));
    if (!r->px) {
        const int nexp = r->nexp;
        gr_flip_reference_destroy(r);
        return gr_fail(err, GR_E_NOMEM, "FLIP: out of memory for the reference's %d exposures", nexp);
    }
    prep_job j = {r, opt};
    st = gr_parallel_try(r->nexp, threads, prep_exposure, &j, err);
    if (st != GR_OK) {
        gr_flip_reference_destroy(r);
        return st;
    }
    *out = r;
    return GR_OK;
}

int gr_flip_reference_matches(const gr_flip_reference *r, const gr_image *ref, const gr_flip_options *opt)
{
    const gr_flip_options zero = {0};
    if (!opt) opt = &zero;
    if (!r || !ref || r->ref != ref || r->w != ref->width || r->h != ref->height || r->mode != opt->mode ||
        r->ppd != options_ppd(opt))
        return 0;
    if (opt->mode != GR_FLIP_HDR) return 1;
    if (r->tonemapper != opt->tonemapper || r->given != (opt->exposures_given != 0)) return 0;
    return !r->given || (r->start == opt->start_exposure && r->stop == opt->stop_exposure && r->nexp == opt->n_exposures);
}

size_t gr_flip_reference_bytes(const gr_flip_reference *r)
{
    return r ? sizeof *r + (r->px ? (size_t)r->nexp * (size_t)r->w * (size_t)r->h * 5 * sizeof(double) : 0) : 0;
}

int gr_flip_reference_has_planes(const gr_flip_reference *r) { return r && r->px; }

void gr_flip_reference_destroy(gr_flip_reference *r)
{
    if (!r) return;
    free(r->px);
    free(r);
}

gr_status gr_flip_compute_defined(const gr_image *ref, const gr_image *test, const gr_flip_options *opt, float *map,
                                  gr_flip_result *res, int *undefined, char *why, size_t why_n, gr_error *err)
{
    *undefined = 0;
    if (!ref || !opt || !res || opt->mode != GR_FLIP_HDR || opt->exposures_given)
        return gr_flip_compute(ref, test, opt, map, res, err);
    gr_flip_options o = *opt;
    gr_error e = {GR_OK, ""};
    gr_status st;
    const gr_flip_reference *r = opt->reference;
    if (r && r->ref == ref && !r->given) {
        /* the prepared reference's range (or its reason for none): the same as derived here */
        st = r->undefined ? GR_E_INPUT : GR_OK;
        if (st != GR_OK) snprintf(e.msg, sizeof e.msg, "%s", r->why);
        o.start_exposure = r->start, o.stop_exposure = r->stop, o.n_exposures = r->nexp;
    } else {
        st = gr_flip_exposures(ref, o.tonemapper, &o.start_exposure, &o.stop_exposure, &o.n_exposures, &e);
    }
    if (st == GR_E_INPUT) {
        memset(res, 0, sizeof *res);
        res->mode = o.mode;
        res->tonemapper = o.tonemapper;
        res->mean = res->min = res->max = res->median = res->q1 = res->q3 = NAN;
        if (map) memset(map, 0, (size_t)ref->width * (size_t)ref->height * sizeof *map);
        if (why && why_n) snprintf(why, why_n, "%s", e.msg);
        *undefined = 1;
        return GR_OK;
    }
    if (st != GR_OK) return gr_fail(err, st, "%s", e.msg);
    o.exposures_given = 1; /* the same range gr_flip_compute would derive (a prepared reference's
                              range matches it exactly) */
    return gr_flip_compute(ref, test, &o, map, res, err);
}

gr_status gr_flip_heatmap(const float *map, int width, int height, gr_image **out, gr_error *err)
{
    if (!map || !out || width < 1 || height < 1) return gr_fail(err, GR_E_INPUT, "FLIP heat map: bad arguments");
    *out = NULL;
    gr_image *g = gr_image_create(width, height, 1, (const char *const[]){"Y"});
    if (!g) return gr_fail(err, GR_E_NOMEM, "FLIP heat map: out of memory");
    for (size_t p = 0; p < (size_t)width * (size_t)height; p++) {
        const float v = map[p];
        g->pixels[p] = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
    }
    gr_status st = gr_oiio_color_map(g, 0, "magma", out, err);
    gr_image_destroy(g);
    return st;
}
