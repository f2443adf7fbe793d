/* A real headless GL context (llvmpipe through Mesa's surfaceless EGL platform on machines
 * without a GPU): strings, an exactly predictable render into an RGBA32F FBO, timer queries,
 * error reporting of gr_gl_check and of shader compile/link failures. */
#include "check.h"

#include "gl/gl.h"
#include "gl/glctx.h"

#include <stdlib.h>
#include <string.h>

#define W 8
#define H 8

/* Triangle (-1,-1), (0.9,-1), (-1,0.9) in NDC: the hypotenuse is x + y = -0.1. */
static const char *tri_vs =
    "#version 330 core\n"
    "void main() {\n"
    "  vec2 p[3] = vec2[3](vec2(-1.0, -1.0), vec2(0.9, -1.0), vec2(-1.0, 0.9));\n"
    "  gl_Position = vec4(p[gl_VertexID], 0.0, 1.0);\n"
    "}\n";
static const char *tri_fs =
    "#version 330 core\n"
    "out vec4 color;\n"
    "void main() { color = vec4(0.25, 0.5, 0.75, 1.0); }\n";
static const float shader_rgba[4] = {0.25f, 0.5f, 0.75f, 1.0f};
static const float clear_rgba[4] = {0.125f, 0.0f, 0.0625f, 0.5f};

/* Renders the triangle into a W x H RGBA32F FBO and checks every pixel against coverage worked
 * out by hand: pixel (i, j) (j from the bottom row, as glReadPixels returns it) has its center
 * at NDC ((i + 0.5) / 4 - 1, (j + 0.5) / 4 - 1), which lies inside iff x + y < -0.1, i.e.
 * (i + j + 1) / 4 - 2 < -0.1, i.e. i + j <= 6 (no center lies on an edge, so the
 * rasterizer's tie rules do not matter). Values must be the exact colours: float storage. */
static void check_render(void)
{
    gr_error err = {GR_OK, ""};
    unsigned prog = 0;
    gr_status st = gr_gl_build_program("triangle", tri_vs, tri_fs, &prog, &err);
    CHECK_OK(st, err);
    CHECK(prog != 0);

    GLuint tex = 0, fbo = 0, vao = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, W, H, 0, GL_RGBA, GL_FLOAT, NULL);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    CHECK(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
    glGenVertexArrays(1, &vao); /* core profile draws need a bound VAO, even an empty one */
    glBindVertexArray(vao);
    glViewport(0, 0, W, H);
    glClearColor(clear_rgba[0], clear_rgba[1], clear_rgba[2], clear_rgba[3]);
    glClear(GL_COLOR_BUFFER_BIT);

    /* Timer query around the draw: a GL_TIME_ELAPSED result and two GL_TIMESTAMPs. */
    GLuint q[3];
    glGenQueries(3, q);
    glQueryCounter(q[0], GL_TIMESTAMP);
    glBeginQuery(GL_TIME_ELAPSED, q[1]);
    glUseProgram(prog);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEndQuery(GL_TIME_ELAPSED);
    glQueryCounter(q[2], GL_TIMESTAMP);
    st = gr_gl_check("draw", &err);
    CHECK_OK(st, err);

    float px[W * H * 4];
    for (int k = 0; k < W * H * 4; k++) px[k] = -1.0f;
    glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, px);
    st = gr_gl_check("glReadPixels", &err);
    CHECK_OK(st, err);
    int inside = 0, bad = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            int in = i + j <= 6;
            const float *want = in ? shader_rgba : clear_rgba;
            const float *got = px + (j * W + i) * 4;
            inside += in;
            for (int c = 0; c < 4; c++)
                if (got[c] != want[c]) {
                    if (bad++ < 5)
                        fprintf(stderr, "pixel (%d,%d) channel %d: got %.9g want %.9g (%s)\n", i, j, c,
                                (double)got[c], (double)want[c], in ? "inside" : "outside");
                }
        }
    CHECK(inside == 28); /* sum over j of the 7 - j pixels with i <= 6 - j */
    CHECK_MSG(bad == 0, "%d channel values differ from the hand-computed image", bad);

    GLuint64 elapsed = 0, t0 = 0, t1 = 0;
    GLint bits = 0, avail = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    glGetQueryObjectui64v(q[1], GL_QUERY_RESULT, &elapsed); /* waits for the result */
    glGetQueryObjectiv(q[1], GL_QUERY_RESULT_AVAILABLE, &avail);
    glGetQueryObjectui64v(q[0], GL_QUERY_RESULT, &t0);
    glGetQueryObjectui64v(q[2], GL_QUERY_RESULT, &t1);
    st = gr_gl_check("timer queries", &err);
    CHECK_OK(st, err);
    CHECK(bits > 0);
    CHECK(avail == GL_TRUE);
    CHECK_MSG(elapsed < 10000000000ull, "GL_TIME_ELAPSED = %llu ns", (unsigned long long)elapsed);
    CHECK_MSG(t0 > 0 && t1 >= t0, "timestamps %llu, %llu", (unsigned long long)t0, (unsigned long long)t1);
    CHECK_MSG(t1 - t0 >= elapsed / 2, "timestamps span %llu ns, elapsed %llu ns",
              (unsigned long long)(t1 - t0), (unsigned long long)elapsed);
    printf("timer: draw of an %dx%d triangle took %llu ns (timestamps span %llu ns)\n", W, H,
           (unsigned long long)elapsed, (unsigned long long)(t1 - t0));

    glDeleteQueries(3, q);
    glDeleteVertexArrays(1, &vao);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    glDeleteProgram(prog);
}

static void check_errors(void)
{
    gr_error err = {GR_OK, ""};
    unsigned prog = 7;
    /* compile error: the log names the undeclared identifier, all on one line */
    const char *bad_fs = "#version 330 core\nout vec4 color;\n"
                         "void main() { color = vec4(undeclared_thing); }\n";
    gr_status st = gr_gl_build_program("broken.frag.glsl", tri_vs, bad_fs, &prog, &err);
    CHECK(st == GR_E_GL);
    CHECK(err.status == GR_E_GL);
    CHECK(prog == 0);
    CHECK_MSG(strstr(err.msg, "broken.frag.glsl") && strstr(err.msg, "fragment"), "%s", err.msg);
    CHECK_MSG(strstr(err.msg, "undeclared_thing") != NULL, "log missing: %s", err.msg);
    CHECK_MSG(strchr(err.msg, '\n') == NULL, "not one line: %s", err.msg);
    printf("compile error: %s\n", err.msg);

    /* link error: a function declared (so each stage compiles) but defined in no stage */
    const char *link_fs = "#version 330 core\nvec3 v_missing();\nout vec4 color;\n"
                          "void main() { color = vec4(v_missing(), 1.0); }\n";
    st = gr_gl_build_program("mismatch", tri_vs, link_fs, &prog, &err);
    CHECK(st == GR_E_GL);
    CHECK(prog == 0);
    CHECK_MSG(strstr(err.msg, "link") && strstr(err.msg, "v_missing"), "%s", err.msg);
    CHECK_MSG(strchr(err.msg, '\n') == NULL, "not one line: %s", err.msg);
    printf("link error: %s\n", err.msg);

    /* gr_gl_check names the pending error and clears it */
    CHECK(gr_gl_check("clean", &err) == GR_OK);
    glEnable(0x7fff); /* not a capability: GL_INVALID_ENUM */
    st = gr_gl_check("glEnable(0x7fff)", &err);
    CHECK(st == GR_E_GL);
    CHECK_MSG(strstr(err.msg, "glEnable(0x7fff)") && strstr(err.msg, "GL_INVALID_ENUM"), "%s", err.msg);
    CHECK(gr_gl_check("after", &err) == GR_OK);
}

/* gr_gl_check_target_size (issue 31): a small target passes; one past GL_MAX_TEXTURE_SIZE is
 * refused naming the limit; a 16384 x 16384 RGBA32F target is either refused with the reason
 * or, where accepted, really makes a complete framebuffer (the check says what the driver
 * does: llvmpipe failed it late as "framebuffer incomplete (0x8cd6)"); no GL error is left. */
static void check_target_size(void)
{
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_gl_check_target_size("small", 64, 36, GL_RGBA32F, &err), err);
    GLint max = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max);
    CHECK(gr_gl_check_target_size("wide", max + 1, 4, GL_RGBA32F, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "wide: a ") && strstr(err.msg, "GL_MAX_TEXTURE_SIZE"), "%s", err.msg);
    gr_status st = gr_gl_check_target_size("big", 16384, 16384, GL_RGBA32F, &err);
    if (st == GR_OK) {
        GLuint tex = 0, fbo = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, 16384, 16384);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
        CHECK(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &tex);
    } else {
        CHECK(st == GR_E_INPUT);
        CHECK_MSG(strstr(err.msg, "big: a 16384x16384 render target"), "%s", err.msg);
    }
    printf("16384 x 16384 RGBA32F: %s\n", st == GR_OK ? "held" : err.msg);
    CHECK(gr_gl_check("after the target checks", &err) == GR_OK);
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    gr_gl_destroy(NULL); /* accepted */

    /* bad override: a usage error naming the variable, no context */
    setenv("GODRAYS_GL_PLATFORM", "vulkan", 1);
    gr_gl *gl = (gr_gl *)&err;
    CHECK(gr_gl_create(NULL, &gl, &err) == GR_E_USAGE);
    CHECK(gl == NULL);
    CHECK_MSG(strstr(err.msg, "GODRAYS_GL_PLATFORM") && strstr(err.msg, "vulkan"), "%s", err.msg);
    unsetenv("GODRAYS_GL_PLATFORM");

    /* AUTO: surfaceless here (no GPU); the device platform where a GPU is. */
    gr_status st = gr_gl_create(NULL, &gl, &err);
    CHECK_OK(st, err);
    if (st != GR_OK) CHECK_DONE();
    int maj = 0, min = 0;
    gr_gl_context_version(gl, &maj, &min);
    printf("platform %s, context %d.%d: %s | %s | %s | GLSL %s\n", gr_gl_platform_name(gl), maj, min,
           gr_gl_vendor(gl), gr_gl_renderer(gl), gr_gl_version(gl), gr_gl_glsl_version(gl));
    CHECK(strlen(gr_gl_renderer(gl)) > 0);
    CHECK(strlen(gr_gl_vendor(gl)) > 0);
    CHECK(strlen(gr_gl_glsl_version(gl)) > 0);
    CHECK(!strcmp(gr_gl_platform_name(gl), "surfaceless") || !strcmp(gr_gl_platform_name(gl), "device"));
    CHECK(maj > 3 || (maj == 3 && min >= 3));
    /* GL_VERSION starts with the context's "major.minor" */
    char prefix[16];
    snprintf(prefix, sizeof prefix, "%d.%d", maj, min);
    CHECK_MSG(!strncmp(gr_gl_version(gl), prefix, strlen(prefix)), "%s vs %s", gr_gl_version(gl), prefix);
    GLint profile = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    CHECK(profile & GL_CONTEXT_CORE_PROFILE_BIT);
    check_render();
    check_errors();
    check_target_size();

    /* A second context on the same display: destroying it must leave the first usable. */
    gr_gl *gl2 = NULL;
    st = gr_gl_create(NULL, &gl2, &err);
    CHECK_OK(st, err);
    gr_gl_destroy(gl2);
    st = gr_gl_make_current(gl, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) check_render();
    gr_gl_destroy(gl);

    /* Forced surfaceless, with a debug context (KHR_debug callback installed). */
    setenv("GODRAYS_GL_PLATFORM", "surfaceless", 1);
    gr_gl_options opts = {GR_GL_AUTO, 1};
    st = gr_gl_create(&opts, &gl, &err);
    unsetenv("GODRAYS_GL_PLATFORM");
    CHECK_OK(st, err);
    if (st == GR_OK) {
        CHECK(!strcmp(gr_gl_platform_name(gl), "surfaceless"));
        GLint flags = 0;
        glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
        CHECK(flags & GL_CONTEXT_FLAG_DEBUG_BIT);
        check_render();
        gr_gl_destroy(gl);
    }

    /* Forced device platform: Mesa offers its software device here, a GPU elsewhere; where
     * neither works the failure must be a GL error naming the platform. */
    opts.platform = GR_GL_DEVICE;
    opts.debug = 0;
    gl = NULL;
    st = gr_gl_create(&opts, &gl, &err);
    if (st == GR_OK) {
        printf("device platform: %s\n", gr_gl_renderer(gl));
        CHECK(!strcmp(gr_gl_platform_name(gl), "device"));
        check_render();
        gr_gl_destroy(gl);
    } else {
        printf("device platform unavailable: %s\n", err.msg);
        CHECK(st == GR_E_GL);
        CHECK_MSG(strstr(err.msg, "EGL device platform") != NULL, "%s", err.msg);
    }
    CHECK_DONE();
}
