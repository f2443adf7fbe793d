/* report/viewer: the two encodings the page's script decodes.
 *  - base64 against RFC 4648's test vectors (section 10) and a long input (the chunking);
 *  - RGBE (Ward, Graphics Gems II): decoding (m + 0.5) 2^(e - 136) as the page does gives each
 *    channel within 2^-8 of the pixel's largest channel (the mantissa of the largest lies in
 *    [128, 256): one step is at most 1/128 of it, half a step after the +0.5), black stays
 *    black, negatives clamp to 0, the exponent byte is floor(log2 max) + 129. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "report/viewer.h"

static double decode(unsigned char m, unsigned char e) { return e ? ((double)m + 0.5) * ldexp(1.0, (int)e - 136) : 0.0; }

int main(void)
{
    static const char *const in[7] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
    static const char *const want[7] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
    for (int i = 0; i < 7; i++) {
        gr_strbuf b;
        gr_sb_init(&b);
        gr_viewer_base64(&b, (const unsigned char *)in[i], strlen(in[i]));
        CHECK_MSG(strcmp(gr_sb_str(&b), want[i]) == 0, "base64(\"%s\") = \"%s\", want \"%s\"", in[i], gr_sb_str(&b),
                  want[i]);
        gr_sb_free(&b);
    }
    /* 10000 bytes of "foobar...": every 6 input bytes -> "Zm9vYmFy", across the 4 KiB chunks */
    {
        unsigned char *d = malloc(10002);
        CHECK(d != NULL);
        if (d) {
            for (int i = 0; i < 10002; i++) d[i] = (unsigned char)"foobar"[i % 6];
            gr_strbuf b;
            gr_sb_init(&b);
            gr_viewer_base64(&b, d, 10002);
            const char *s = gr_sb_str(&b);
            CHECK(strlen(s) == 10002 / 3 * 4);
            int ok = 1;
            for (size_t i = 0; i < strlen(s); i++) ok &= s[i] == "Zm9vYmFy"[i % 8];
            CHECK(ok);
            gr_sb_free(&b);
            free(d);
        }
    }
    /* RGBE */
    unsigned char q[4];
    gr_viewer_rgbe(0, 0, 0, q);
    CHECK(q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0);
    gr_viewer_rgbe(-1.0f, -2.0f, 0.0f, q);
    CHECK(q[3] == 0);
    gr_viewer_rgbe(-1.0f, 0.5f, 0.25f, q);
    CHECK(q[0] == 0 && q[3] == 128); /* 0.5 = 2^-1: floor(log2) + 129 = 128 */
    double worst = 0;
    unsigned s = 12345u;
    for (int i = 0; i < 20000; i++) {
        float c[3];
        for (int j = 0; j < 3; j++) {
            s = s * 1664525u + 1013904223u;
            /* values over 2^-30 .. 2^20, some channels far below the largest */
            c[j] = (float)ldexp((double)(s >> 8) / 16777216.0 + 0.001, (int)(s % 51) - 30);
        }
        gr_viewer_rgbe(c[0], c[1], c[2], q);
        const double mx = fmax(c[0], fmax(c[1], c[2]));
        CHECK_MSG(q[3] == (unsigned char)(floor(log2(mx)) + 129), "exponent byte %u for max %g", q[3], mx);
        for (int j = 0; j < 3; j++) {
            const double e = fabs(decode(q[j], q[3]) - c[j]) / mx;
            if (e > worst) worst = e;
        }
    }
    CHECK_MSG(worst <= 1.0 / 256.0, "worst RGBE error %g of the max channel", worst);
    CHECK_DONE();
}
