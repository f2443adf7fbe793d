/* Student's t 0.975 quantiles (core/student.h) against an independent value: the t density
 * f(x) = Gamma((nu+1)/2) / (sqrt(nu pi) Gamma(nu/2)) (1 + x^2/nu)^(-(nu+1)/2) integrated by
 * Simpson's rule from 0 to the quantile must give 0.475 (two-sided 95 %). */
#include "check.h"

#include <math.h>
#include "core/student.h"

static double half_mass(double q, int nu)
{
    const int n = 200000; /* even */
    double h = q / n, s = 0.0, c = exp(lgamma(0.5 * (nu + 1)) - lgamma(0.5 * nu)) / sqrt(nu * 3.14159265358979323846);
    for (int i = 0; i <= n; i++) {
        double x = i * h, f = c * pow(1.0 + x * x / nu, -0.5 * (nu + 1));
        s += f * (i == 0 || i == n ? 1.0 : (i & 1) ? 4.0 : 2.0);
    }
    return s * h / 3.0;
}

int main(void)
{
    const int dofs[] = {1, 2, 3, 5, 7, 15, 30, 31, 40, 63, 100, 1000};
    for (size_t i = 0; i < sizeof dofs / sizeof dofs[0]; i++) {
        double q = gr_student_t975(dofs[i]), m = half_mass(q, dofs[i]);
        printf("dof %4d: t975 %.6f, mass in [0, t] %.7f\n", dofs[i], q, m);
        CHECK_NEAR(m, 0.475, 2e-6);
    }
    CHECK_NEAR(gr_student_t975(0), 1.959964, 1e-6);
    CHECK(gr_student_t975(7) > gr_student_t975(8) && gr_student_t975(40) > gr_student_t975(1000));
    CHECK_DONE();
}
