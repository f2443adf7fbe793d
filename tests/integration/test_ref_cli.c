/* `godrays reference` end to end: EXR + PNG preview with the documented channels and
 * metadata; --target-error refines until both relative errors are below the target;
 * Ctrl-C (SIGINT) writes the partial image marked godrays:partial = 1 and exits 1; a bad
 * flag exits 2. Runs the built binary (GODRAYS_BINARY). */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include <math.h>

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "image/exr.h"

static char scene[4096], out_dir[4096];
static char A[16][64]; /* writable copies of the literal arguments (execv takes char *const[]) */
static char *w(int i, const char *s) { snprintf(A[i], sizeof A[i], "%s", s); return A[i]; }

static int run(char *const argv[], double interrupt_after_s)
{
    pid_t pid = fork();
    if (pid == 0) {
        execv(argv[0], argv);
        _exit(127);
    }
    if (pid < 0) return -1;
    if (interrupt_after_s > 0.0) {
        struct timespec ts = {(time_t)interrupt_after_s, (long)((interrupt_after_s - (time_t)interrupt_after_s) * 1e9)};
        nanosleep(&ts, NULL);
        kill(pid, SIGINT);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static double meta_num(const gr_metadata *m, const char *key)
{
    const gr_meta_item *it = gr_meta_get(m, key);
    CHECK_MSG(it != NULL, "metadata %s missing", key);
    return it ? it->num : -1.0;
}

int main(void)
{
    const char *bin = getenv("GODRAYS_BINARY"), *src = getenv("GODRAYS_SOURCE_DIR"), *out = getenv("GODRAYS_TEST_OUT");
    if (!bin || !src) {
        fprintf(stderr, "GODRAYS_BINARY and GODRAYS_SOURCE_DIR must be set (ctest does)\n");
        return 1;
    }
    snprintf(scene, sizeof scene, "%s/data/scenes/default.json", src);
    snprintf(out_dir, sizeof out_dir, "%s", out ? out : "/tmp");
    char exr[4200], png[4200];
    snprintf(exr, sizeof exr, "%s/ref_cli.exr", out_dir);
    snprintf(png, sizeof png, "%s/ref_cli.png", out_dir);
    unlink(exr);
    unlink(png);
    {
        char *argv[] = {(char *)bin, w(0, "reference"), scene, w(1, "-o"), exr, w(2, "--size"), w(3, "48x27"), w(4, "--surface-res"), w(5, "64"), w(6, "--quiet"), w(7, "--aov"), w(8, "--set"), w(9, "reference.near_cells_per_wavelength=0"), NULL};
        CHECK(run(argv, 0.0) == 0);
        struct stat st;
        CHECK_MSG(stat(png, &st) == 0 && st.st_size > 0, "PNG preview missing: %s", png);
        gr_image *img = NULL;
        gr_metadata m;
        gr_meta_init(&m);
        gr_error err = {GR_OK, ""};
        CHECK_OK(gr_exr_read(exr, &img, &m, &err), err);
        if (img) {
            const char *ch[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B", "transmittance", "ray_length"};
            for (int i = 0; i < 8; i++) CHECK_MSG(gr_image_channel(img, ch[i]) >= 0, "channel %s missing", ch[i]);
            CHECK(gr_meta_get(&m, "godrays:scene_hash") != NULL);
            CHECK(meta_num(&m, "godrays:reference.surface_res") == 64);
            CHECK(meta_num(&m, "godrays:partial") == 0);
            CHECK(meta_num(&m, "godrays:wall_s") > 0);
            CHECK(meta_num(&m, "godrays:rel_stderr_mean") > 0);
            CHECK(meta_num(&m, "godrays:spp") >= 8);
            /* the wavy scene's surface bias is measured (probe on by default); the bound is the
             * larger of twice the estimate and the figure with the measured order */
            double be = meta_num(&m, "godrays:bias_surface_rel_est"), bb = meta_num(&m, "godrays:bias_surface_rel_bound");
            double bo = meta_num(&m, "godrays:bias_surface_rel_measured_order");
            CHECK_MSG(be > 0.0 && be < 1.0, "bias estimate %g", be);
            CHECK_NEAR(bb, fmax(2.0 * be, bo), 1e-12 * bb);
            CHECK(bo >= be); /* the measured order is at most 2 */
            CHECK(meta_num(&m, "godrays:stderr_dof") == 7);
            CHECK(meta_num(&m, "godrays:bias_block_p95_rel") >= 0.0);
            const char *bc[] = {"bias.R", "bias.G", "bias.B"};
            for (int i = 0; i < 3; i++) CHECK_MSG(gr_image_channel(img, bc[i]) >= 0, "channel %s missing", bc[i]);
            CHECK(gr_meta_get(&m, "godrays:bias_surface_probe") != NULL);
        }
        gr_image_destroy(img);
        gr_meta_free(&m);
    }
    {
        char *argv[] = {(char *)bin, w(0, "reference"), scene, w(1, "-o"), exr, w(2, "--size"), w(3, "32x18"), w(4, "--surface-res"), w(5, "64"), w(6, "--steps"), w(7, "16"), w(8, "--target-error"), w(9, "0.02"), w(10, "--quiet"), w(11, "--set"), w(12, "reference.near_cells_per_wavelength=0"), NULL};
        CHECK(run(argv, 0.0) == 0);
        gr_image *img = NULL;
        gr_metadata m;
        gr_meta_init(&m);
        gr_error err = {GR_OK, ""};
        CHECK_OK(gr_exr_read(exr, &img, &m, &err), err);
        double a = meta_num(&m, "godrays:rel_stderr_mean"), b = meta_num(&m, "godrays:rel_stderr_p95");
        double passes = meta_num(&m, "godrays:passes"), per = meta_num(&m, "godrays:passes_per_round");
        printf("target 0.02: rel. errors %.3g %.3g after %g passes (%g per round)\n", a, b, passes, per);
        CHECK(a >= 0 && a < 0.02 && b >= 0 && b < 0.02);
        CHECK_MSG(passes > per, "the target needs more than one round here: %g passes", passes);
        gr_image_destroy(img);
        gr_meta_free(&m);
    }
    {
        unlink(exr);
        char *argv[] = {(char *)bin, w(0, "reference"), scene, w(1, "-o"), exr, w(2, "--size"), w(3, "320x180"), w(4, "--steps"), w(5, "256"), w(6, "--quiet"), NULL};
        int rc = run(argv, 4.0); /* long enough for process start-up on a loaded machine */
        CHECK_MSG(rc == 1, "interrupted render must exit 1, got %d", rc);
        gr_image *img = NULL;
        gr_metadata m;
        gr_meta_init(&m);
        gr_error err = {GR_OK, ""};
        CHECK_OK(gr_exr_read(exr, &img, &m, &err), err);
        CHECK(meta_num(&m, "godrays:partial") == 1);
        gr_image_destroy(img);
        gr_meta_free(&m);
    }
    {
        char *argv[] = {(char *)bin, w(0, "reference"), scene, w(1, "-o"), exr, w(2, "--no-such-flag"), NULL};
        CHECK(run(argv, 0.0) == 2);
        char *argv2[] = {(char *)bin, w(0, "reference"), scene, w(1, "-o"), exr, w(2, "--spp"), w(3, "0"), w(4, "--quiet"), NULL};
        CHECK(run(argv2, 0.0) == 2);
    }
    CHECK_DONE();
}
