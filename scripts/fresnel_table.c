/* Prints the Schlick-vs-exact Fresnel table of docs/optics.md (air -> water, n = 1.333,
 * seed eqs. 5.5.2a/b) as Markdown, from the project's own gr_fresnel_exact and
 * gr_fresnel_schlick. Build and run from the source root:
 *   cc -std=c11 -Isrc scripts/fresnel_table.c src/core/optics.c -lm -o fresnel_table && ./fresnel_table
 */
#include <math.h>
#include <stdio.h>

#include "core/optics.h"

int main(void)
{
    const double n1 = 1.0, n2 = 1.333;
    const double r0 = gr_fresnel_r0(n1, n2);
    const double deg[] = {0, 10, 20, 30, 40, 50, 60, 70, 80, 85, 89};
    printf("R0 = ((n1 - n2) / (n1 + n2))^2 = %.6f\n\n", r0);
    printf("| incidence (deg) | R exact | R Schlick | R gap (S - E) | R rel. gap | T exact | T Schlick | T gap (S - E) | T rel. gap |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (unsigned i = 0; i < sizeof deg / sizeof deg[0]; i++) {
        double c = cos(deg[i] * GR_PI / 180.0);
        double re = gr_fresnel_exact(c, n1, n2), rs = gr_fresnel_schlick(c, r0);
        double te = 1.0 - re, ts = 1.0 - rs;
        printf("| %g | %.5f | %.5f | %+.5f | %+.2f%% | %.5f | %.5f | %+.5f | %+.2f%% |\n", deg[i], re, rs,
               rs - re, 100.0 * (rs - re) / re, te, ts, ts - te, 100.0 * (ts - te) / te);
    }
    return 0;
}
