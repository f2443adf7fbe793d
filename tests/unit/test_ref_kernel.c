/* The sun-disc kernel's geometry (reference/beams.h): the equal-area 16-gon and the
 * fraction of it inside a triangle (Sutherland-Hodgman clipping), against values computed
 * here independently:
 *  - the polygon has the unit disc's area (pi) and nearly its mean squared radius (1/2);
 *  - half-planes: through the centre 1/2 (any direction), beyond the circumradius 0 or 1;
 *  - random triangles (three half-planes): a 1000 x 1000 point grid over the polygon,
 *    counting the points inside the polygon and inside all three half-planes. */
#include "check.h"

#include <math.h>
#include "reference/beams.h"

static const double PI = 3.14159265358979323846;

static double vx[GR_BEAM_KERNEL_N], vy[GR_BEAM_KERNEL_N];

static int in_polygon(double x, double y)
{
    for (int i = 0; i < GR_BEAM_KERNEL_N; i++) {
        int j = (i + 1) % GR_BEAM_KERNEL_N;
        if ((vx[j] - vx[i]) * (y - vy[i]) - (vy[j] - vy[i]) * (x - vx[i]) < 0.0) return 0;
    }
    return 1;
}

/* Fraction of the polygon's grid points inside a_i + b_i . c >= 0 for all i. */
static double raster(const double a[3], const double b[6], int n)
{
    double rho = gr_beam_kernel_radius(), step = 2.0 * rho / n;
    long in = 0, tot = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = -rho + (i + 0.5) * step, y = -rho + (j + 0.5) * step;
            if (!in_polygon(x, y)) continue;
            tot++;
            int ok = 1;
            for (int k = 0; k < 3 && ok; k++) ok = a[k] + b[2 * k] * x + b[2 * k + 1] * y >= 0.0;
            in += ok;
        }
    return (double)in / (double)tot;
}

static unsigned long long lcg = 77;
static double urand(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg >> 11) * 0x1p-53;
}

int main(void)
{
    double rho = gr_beam_kernel_radius(), area = 0.0, m2 = 0.0;
    for (int i = 0; i < GR_BEAM_KERNEL_N; i++) {
        vx[i] = rho * cos(2.0 * PI * i / GR_BEAM_KERNEL_N);
        vy[i] = rho * sin(2.0 * PI * i / GR_BEAM_KERNEL_N);
    }
    for (int i = 0; i < GR_BEAM_KERNEL_N; i++) {
        int j = (i + 1) % GR_BEAM_KERNEL_N;
        double cr = vx[i] * vy[j] - vx[j] * vy[i];
        area += 0.5 * cr;
        /* second moment of the triangle (0, v_i, v_j): cr/12 (|v_i|^2 + v_i . v_j + |v_j|^2) */
        m2 += cr / 12.0 * (vx[i] * vx[i] + vy[i] * vy[i] + vx[i] * vx[j] + vy[i] * vy[j] + vx[j] * vx[j] + vy[j] * vy[j]);
    }
    printf("kernel polygon: radius %.6f, area %.9f (pi %.9f), mean squared radius %.6f (disc 0.5)\n", rho, area, PI,
           m2 / area);
    CHECK_REL(area, PI, 1e-12);
    CHECK_REL(m2 / area, 0.5, 2e-3);

    /* half-planes through the centre, and wholly inside / outside */
    for (int k = 0; k < 16; k++) {
        double t = 2.0 * PI * urand(), a[3] = {0.0, 1.0, 1.0}, b[6] = {cos(t), sin(t), 0, 0, 0, 0};
        CHECK_NEAR(gr_beam_kernel_coverage(a, b), 0.5, 1e-12);
        a[0] = 1.0001 * rho;
        CHECK_NEAR(gr_beam_kernel_coverage(a, b), 1.0, 1e-12);
        a[0] = -1.0001 * rho;
        CHECK_NEAR(gr_beam_kernel_coverage(a, b), 0.0, 1e-12);
    }
    /* random triangles against the raster count (grid error ~ perimeter x step / area) */
    const int n = 1000;
    double worst = 0.0;
    for (int k = 0; k < 40; k++) {
        double a[3], b[6];
        /* a triangle with vertices around the kernel: edge normals from its vertices */
        double px[3], py[3];
        for (int i = 0; i < 3; i++) {
            double r = 2.0 * rho * urand(), t = 2.0 * PI * urand();
            px[i] = r * cos(t);
            py[i] = r * sin(t);
        }
        double s = (px[1] - px[0]) * (py[2] - py[0]) - (py[1] - py[0]) * (px[2] - px[0]);
        if (fabs(s) < 0.05) { k--; continue; }
        for (int i = 0; i < 3; i++) {
            int j = (i + 1) % 3;
            /* edge i from vertex i to j; inside = left of it for a counter-clockwise triangle */
            double ex = px[j] - px[i], ey = py[j] - py[i], sg = s > 0.0 ? 1.0 : -1.0;
            b[2 * i] = -ey * sg;
            b[2 * i + 1] = ex * sg;
            a[i] = -(b[2 * i] * px[i] + b[2 * i + 1] * py[i]);
        }
        double c = gr_beam_kernel_coverage(a, b), ref = raster(a, b, n);
        worst = fmax(worst, fabs(c - ref));
        CHECK_NEAR(c, ref, 3e-4);
        CHECK(c >= 0.0 && c <= 1.0);
    }
    printf("40 random triangles: largest |clipped - raster| = %.2e\n", worst);
    CHECK_DONE();
}
