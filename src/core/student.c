#include "core/student.h"

double gr_student_t975(int dof)
{
    /* 0.975 quantiles of Student's t, dof 1..30 (Abramowitz & Stegun, table 26.10) */
    static const double t[30] = {12.7062047, 4.3026527, 3.1824463, 2.7764451, 2.5705818, 2.4469119, 2.3646243,
                                 2.3060041,  2.2621572, 2.2281389, 2.2009852, 2.1788128, 2.1603687, 2.1447867,
                                 2.1314495,  2.1199053, 2.1098155, 2.1009220, 2.0930241, 2.0859634, 2.0796138,
                                 2.0738731,  2.0686576, 2.0638986, 2.0595386, 2.0555294, 2.0518305, 2.0484071,
                                 2.0452296,  2.0422725};
    if (dof < 1) return GR_NORMAL_Q975;
    if (dof <= 30) return t[dof - 1];
    /* Cornish-Fisher expansion of the t quantile in 1/nu (A&S 26.7.5), z the normal quantile */
    double z = GR_NORMAL_Q975, z2 = z * z, nu = (double)dof;
    double g1 = (z2 + 1.0) * z / 4.0, g2 = ((5.0 * z2 + 16.0) * z2 + 3.0) * z / 96.0;
    double g3 = (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) * z / 384.0;
    return z + g1 / nu + g2 / (nu * nu) + g3 / (nu * nu * nu);
}
