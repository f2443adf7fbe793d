/* docs/techniques.md stays in step with the prelude a user shader sees: every harness
 * uniform, sampler and helper function the prelude declares (for a pass that reads both
 * harness textures) is named in the doc in backticks, and every manifest key the parser
 * accepts has a row. No GL: the prelude is generated from the parsed manifest. */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/usertech.h"

static char *read_all(const char *rel)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", src ? src : GR_SOURCE_DIR, rel);
    FILE *f = fopen(path, "rb");
    CHECK_MSG(f != NULL, "cannot open %s", path);
    if (!f) return NULL;
    char *buf = malloc(1 << 20);
    size_t n = fread(buf, 1, (1 << 20) - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* `name` (possibly followed by [ or ( inside the backticks) appears in doc */
static int documented(const char *doc, const char *name)
{
    char pat[96];
    const char *tails[] = {"`", "[", "(", ",", NULL};
    for (int i = 0; tails[i]; i++) {
        snprintf(pat, sizeof pat, "`%s%s", name, tails[i]);
        if (strstr(doc, pat)) return 1;
        /* inside a signature: `float gr_hg(float ...)` */
        snprintf(pat, sizeof pat, " %s(", name);
        if (strstr(doc, pat)) return 1;
    }
    return 0;
}

int main(void)
{
    char *doc = read_all("docs/techniques.md");
    if (!doc) CHECK_DONE();
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/data/techniques/shadow_march", src ? src : GR_SOURCE_DIR);
    gr_error err;
    gr_technique_class *cls = NULL;
    CHECK_OK(gr_usertech_load(dir, &cls, &err), err);
    if (!cls) CHECK_DONE();
    /* shadow_march's pass 0 reads shadow_map and eye_depth; scene_probe's reads caustics,
     * scene_colour and sun_light: together their preludes declare everything */
    static const char *const techs[2] = {"data/techniques/shadow_march", "tests/techniques/scene_probe"};
    int n_uniforms = 0, n_helpers = 0;
    for (int k = 0; k < 2; k++) {
        snprintf(dir, sizeof dir, "%s/%s", src ? src : GR_SOURCE_DIR, techs[k]);
        gr_technique_class *c2 = NULL;
        CHECK_OK(gr_usertech_load(dir, &c2, &err), err);
        if (!c2) CHECK_DONE();
        char *pre = gr_usertech_prelude(c2, 0, "fragment");
        CHECK(pre != NULL);
        if (!pre) CHECK_DONE();
        /* the prelude ends so that GLSL log line numbers are the user file's own */
        size_t lp = strlen(pre);
        CHECK(lp > 8 && !strcmp(pre + lp - 8, "#line 1\n"));
        for (char *line = pre; line && *line;) {
            char *nl = strchr(line, '\n');
            if (nl) *nl = '\0';
            char type[32], name[64];
            if (sscanf(line, "uniform %31s %63[A-Za-z0-9_]", type, name) == 2) {
                if (strncmp(name, "u_set_", 6)) { /* settings are the technique's own */
                    n_uniforms++;
                    CHECK_MSG(documented(doc, name), "docs/techniques.md does not name the uniform `%s`", name);
                }
            } else if (sscanf(line, "%31s %63[A-Za-z0-9_](", type, name) == 2 && !strncmp(name, "gr_", 3) &&
                       (strchr(line, '{') || (nl && nl[1] == '{'))) {
                n_helpers++;
                CHECK_MSG(documented(doc, name), "docs/techniques.md does not name the helper `%s`", name);
            }
            line = nl ? nl + 1 : NULL;
        }
        free(pre);
        gr_usertech_free(c2);
    }
    printf("%d uniforms/samplers and %d helpers checked\n", n_uniforms, n_helpers);
    CHECK(n_uniforms >= 50);
    CHECK(n_helpers >= 9);
    /* every manifest key of the parser has a row "| `key` |" */
    static const char *const keys[] = {"version", "name", "description", "settings", "shadow_map", "sun_light",
                                       "caustics", "scene_colour", "albedo", "radius_deg", "targets", "passes",
                                       "output", "allow_black", "gain", "ladder", "tune", "type", "default", "min", "max", "min_exclusive",
                                       "max_exclusive", "unit", "doc", "scale", "size", "format", "filter", "vertex",
                                       "fragment", "draw", "target", "blend", "clear", "inputs", NULL};
    for (int i = 0; keys[i]; i++) {
        char row[64];
        snprintf(row, sizeof row, "| `%s`", keys[i]);
        CHECK_MSG(strstr(doc, row) != NULL, "docs/techniques.md has no row for the manifest key `%s`", keys[i]);
    }
    gr_usertech_free(cls);
    free(doc);
    CHECK_DONE();
}
