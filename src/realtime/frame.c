/* Per-frame shader inputs (see frame.h; derivations in docs/radial-blur.md, "Frame"). */
#include "realtime/frame.h"

#include <math.h>
#include <string.h>

#include "core/optics.h"

void gr_mat4_mul(const double a[16], const double b[16], double out[16])
{
    double t[16];
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double acc = 0.0;
            for (int k = 0; k < 4; k++) acc += a[k * 4 + r] * b[c * 4 + k];
            t[c * 4 + r] = acc;
        }
    memcpy(out, t, sizeof t);
}

/* Gauss-Jordan with partial pivoting on the transpose (row/column order does not matter
 * for an inverse: inv(M^T) = inv(M)^T, so working on the stored array directly is exact). */
int gr_mat4_inverse(const double m[16], double out[16])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 8; c++) a[r][c] = c < 4 ? m[r * 4 + c] : (c - 4 == r ? 1.0 : 0.0);
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
        if (!(fabs(a[piv][c]) > 1e-300)) return -1;
        if (piv != c)
            for (int k = 0; k < 8; k++) {
                double t = a[c][k];
                a[c][k] = a[piv][k];
                a[piv][k] = t;
            }
        double inv = 1.0 / a[c][c];
        for (int k = 0; k < 8; k++) a[c][k] *= inv;
        for (int r = 0; r < 4; r++) {
            if (r == c) continue;
            double f = a[r][c];
            for (int k = 0; k < 8; k++) a[r][k] -= f * a[c][k];
        }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) out[r * 4 + c] = a[r][c + 4];
    return 0;
}

void gr_mat4_apply(const double m[16], const double in[4], double out[4])
{
    double t[4];
    for (int r = 0; r < 4; r++) t[r] = m[r] * in[0] + m[4 + r] * in[1] + m[8 + r] * in[2] + m[12 + r] * in[3];
    memcpy(out, t, sizeof t);
}

void gr_frame_matf(const double m[16], float out[16])
{
    for (int i = 0; i < 16; i++) out[i] = (float)m[i];
}

void gr_frame_view_proj_rot(const gr_frame *f, double out[16])
{
    double v[16];
    memcpy(v, f->view, sizeof v);
    v[12] = v[13] = v[14] = 0.0; /* drop the translation column */
    gr_mat4_mul(f->proj, v, out);
}

static void set3(double *d, const double *s)
{
    d[0] = s[0];
    d[1] = s[1];
    d[2] = s[2];
}

void gr_frame_init(const gr_scene *scene, gr_frame *f)
{
    memset(f, 0, sizeof *f);
    const gr_camera *cam = &scene->camera;
    f->width = cam->width;
    f->height = cam->height;
    f->time_s = scene->water.time_s;
    set3(f->eye, cam->position_m);
    set3(f->forward, cam->forward);
    set3(f->right, cam->right);
    set3(f->up, cam->up);
    f->fov_y_rad = cam->fov_deg * GR_PI / 180.0;
    f->aspect = (double)cam->width / (double)cam->height;

    /* View: rows right, up, -forward (right-handed, the camera looks down -z), translation
     * -R eye. Column-major: element (row r, column c) at [c * 4 + r]. */
    const double *R[3] = {cam->right, cam->up, cam->forward};
    const double sgn[3] = {1.0, 1.0, -1.0};
    for (int r = 0; r < 3; r++) {
        double t = 0.0;
        for (int c = 0; c < 3; c++) {
            f->view[c * 4 + r] = sgn[r] * R[r][c];
            t += sgn[r] * R[r][c] * f->eye[c];
        }
        f->view[12 + r] = -t;
    }
    f->view[15] = 1.0;
    /* Perspective (gluPerspective): x_ndc = (x_eye / -z_eye) / (tan(fov/2) aspect), so a pixel
     * centre's ndc gives back the scene's pixel ray (scene.h) exactly; z in [-1, 1]. */
    double tf = 1.0 / tan(0.5 * f->fov_y_rad), n = GR_FRAME_NEAR_M, fa = GR_FRAME_FAR_M;
    f->proj[0] = tf / f->aspect;
    f->proj[5] = tf;
    f->proj[10] = (fa + n) / (n - fa);
    f->proj[11] = -1.0;
    f->proj[14] = 2.0 * fa * n / (n - fa);
    gr_mat4_mul(f->proj, f->view, f->view_proj);
    if (gr_mat4_inverse(f->view_proj, f->inv_view_proj) != 0) memset(f->inv_view_proj, 0, sizeof f->inv_view_proj);

    /* Sun, and its refraction through the flat surface (seed eq. 5.5.1, normal +y, eta 1/n). */
    const gr_sun *sun = &scene->sun;
    set3(f->to_sun, sun->to_sun);
    set3(f->sun_dir, sun->dir);
    set3(f->sun_irradiance, sun->irradiance);
    f->sun_angular_radius_rad = 0.5 * sun->angular_diameter_deg * GR_PI / 180.0;
    double ior = scene->medium.ior;
    gr_dvec3 T = gr_refract_d(gr_d3(sun->dir[0], sun->dir[1], sun->dir[2]), gr_d3(0, 1, 0), 1.0 / ior);
    f->refr_dir[0] = T.x;
    f->refr_dir[1] = T.y;
    f->refr_dir[2] = T.z;
    for (int c = 0; c < 3; c++) f->to_refr_sun[c] = -f->refr_dir[c];
    f->transmittance_flat = 1.0 - gr_fresnel_exact(sun->to_sun[1], 1.0, ior);

    /* The refracted sun on screen: clip of the point at infinity (to_refr_sun, 0). */
    double d4[4] = {f->to_refr_sun[0], f->to_refr_sun[1], f->to_refr_sun[2], 0.0}, clip[4];
    gr_mat4_apply(f->view_proj, d4, clip);
    f->sun_clip_w = clip[3];
    f->sun_cos_view = f->forward[0] * f->to_refr_sun[0] + f->forward[1] * f->to_refr_sun[1] +
                      f->forward[2] * f->to_refr_sun[2];
    double w = fabs(clip[3]) > 1e-9 ? fabs(clip[3]) : 1e-9;
    for (int k = 0; k < 2; k++) {
        f->sun_ndc[k] = clip[k] / w;
        f->sun_uv[k] = 0.5 * f->sun_ndc[k] + 0.5;
    }
    f->snell_half_angle_rad = asin(1.0 / ior);

    /* Waves: per-wave form and the seed's groups of 4 (seed eq. 5.5.7 and its listing). */
    const gr_water *wt = &scene->water;
    f->rest_height_m = wt->rest_height_m;
    f->n_waves = wt->n_waves;
    f->n_wave_groups = (wt->n_waves + 3) / 4;
    for (int i = 0; i < wt->n_waves && i < GR_MAX_WAVES; i++) {
        const gr_wave *wv = &wt->waves[i];
        f->waves_a[i][0] = (float)wv->dir[0];
        f->waves_a[i][1] = (float)wv->dir[1];
        f->waves_a[i][2] = (float)wv->k;
        f->waves_a[i][3] = (float)wv->omega_rad_s;
        f->waves_b[i][0] = (float)wv->amplitude_m;
        f->waves_b[i][1] = (float)wv->phase_rad;
        int g = i / 4, lane = i % 4;
        double kx = wv->k * wv->dir[0], kz = wv->k * wv->dir[1];
        double c = fmod(wv->omega_rad_s * f->time_s - wv->phase_rad, 2.0 * GR_PI);
        if (c < 0) c += 2.0 * GR_PI;
        f->waves_seed[g * 5 + 0][lane] = (float)kx;
        f->waves_seed[g * 5 + 1][lane] = (float)kz;
        f->waves_seed[g * 5 + 2][lane] = wv->k > 0 ? (float)(wv->amplitude_m / wv->k) : 0.0f;
        f->waves_seed[g * 5 + 3][lane] = (float)wv->amplitude_m;
        f->waves_seed[g * 5 + 4][lane] = (float)c;
    }

    const gr_medium *m = &scene->medium;
    set3(f->absorption, m->absorption);
    set3(f->scattering, m->scattering);
    set3(f->extinction, m->extinction);
    f->g = m->g;
    f->ior = ior;
    f->seabed_y = scene->has_seabed ? wt->rest_height_m - scene->seabed_depth_m : -1e30;
}
