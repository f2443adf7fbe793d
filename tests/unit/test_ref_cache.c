/* reference/cache: the ground-truth cache.
 *  - the key changes with everything the ground truth renders (waves, sun, medium, camera,
 *    occluders, reference quality settings) and with nothing it does not (scene name, shaft
 *    settings, reference.threads), and with the build digest of the ground truth's sources;
 *  - FNV-1a 64 against the published test vectors (offset basis for "", "a" -> af63dc4c8601ec8c);
 *  - the directory rule ($GODRAYS_CACHE, then $XDG_CACHE_HOME or $HOME, then ./.godrays-cache);
 *  - store + load gives back the same bytes; every failed check of a read (key attribute,
 *    size, channels, partial render, unreadable file) is a miss with its reason, not an error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "realtime/technique.h"
#include "image/exr.h"
#include "reference/cache.h"
#include "scene/scene.h"

static const char *BASE =
    "{\"name\": \"cache-test\", \"water\": {\"waves\": [{\"amplitude_m\": 0.1, \"wavelength_m\": 6}]},"
    " \"camera\": {\"position_m\": [0, -5, 0], \"width\": 8, \"height\": 6}}";

static void key_of(const char *o1, const char *o2, char *key)
{
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err = {GR_OK, ""};
    const char *ov[2] = {o1, o2};
    const int n = o2 ? 2 : o1 ? 1 : 0;
    gr_status st = gr_scene_load_string(BASE, "t", ov, n, s, &err);
    CHECK_OK(st, err);
    st = gr_cache_key(s, key, &err);
    CHECK_OK(st, err);
    free(s);
}

static gr_image *ref_image(int w, int h, int with_stderr)
{
    static const char *const names[6] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    gr_image *img = gr_image_create(w, h, with_stderr ? 6 : 3, names);
    for (int i = 0; img && i < w * h * img->nchannels; i++) img->pixels[i] = 0.001f * (float)(i % 997);
    return img;
}

static int file_exists(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0;
}

int main(void)
{
    gr_technique_count(); /* the built-in techniques' sections ("shafts") before any scene */
    /* FNV-1a 64 test vectors (Fowler/Noll/Vo reference list) */
    CHECK(gr_fnv1a64(GR_FNV_BASIS, "", 0) == 0xcbf29ce484222325ull);
    CHECK(gr_fnv1a64(GR_FNV_BASIS, "a", 1) == 0xaf63dc4c8601ec8cull);
    CHECK(gr_fnv1a64(GR_FNV_BASIS, "foobar", 6) == 0x85944171f73967e8ull);

    char k0[GR_CACHE_KEY_LEN + 1], k1[GR_CACHE_KEY_LEN + 1];
    key_of(NULL, NULL, k0);
    CHECK(strlen(k0) == GR_CACHE_KEY_LEN && k0[16] == '-');
    key_of(NULL, NULL, k1);
    CHECK(!strcmp(k0, k1)); /* deterministic */
    /* what the ground truth does not read leaves the key alone */
    static const char *const same[] = {"name=other", "shafts.K=0.5", "shafts.N=21", "reference.threads=1",
                                       "shafts.target_format=rgba16f"};
    for (size_t i = 0; i < sizeof same / sizeof same[0]; i++) {
        key_of(same[i], NULL, k1);
        CHECK_MSG(!strcmp(k0, k1), "%s changed the key", same[i]);
    }
    /* what it reads changes it, in the scene part or in the settings part */
    static const char *const differ[][2] = {
        {"medium.g=0.8", "scene"}, {"sun.elevation_deg=50", "scene"}, {"camera.width=9", "scene"},
        {"water.time_s=0.5", "scene"}, {"medium.absorption_per_m=[0.3,0.05,0.02]", "scene"},
        {"reference.spp=2", "settings"}, {"reference.seed=2", "settings"}, {"reference.surface_res=100", "settings"},
        {"reference.transmittance_cutoff=0.01", "settings"}};
    for (size_t i = 0; i < sizeof differ / sizeof differ[0]; i++) {
        key_of(differ[i][0], NULL, k1);
        const int scene_part = !strcmp(differ[i][1], "scene");
        CHECK_MSG(strcmp(k0, k1) != 0, "%s did not change the key", differ[i][0]);
        /* and only the part it belongs to */
        CHECK_MSG(scene_part ? (strncmp(k0, k1, 16) != 0 && !strcmp(k0 + 17, k1 + 17))
                             : (!strncmp(k0, k1, 16) && strcmp(k0 + 17, k1 + 17) != 0),
                  "%s: %s vs %s", differ[i][0], k0, k1);
    }

    /* the build digest of the ground truth's sources is in the settings part: another digest
     * (another integrator) is another key, this build's is gr_cache_key's */
    {
        gr_scene *s = calloc(1, sizeof *s);
        gr_error err = {GR_OK, ""};
        CHECK_OK(gr_scene_load_string(BASE, "t", NULL, 0, s, &err), err);
        const char *d = gr_cache_digest();
        CHECK_MSG(strlen(d) == 16 && strspn(d, "0123456789abcdef") == 16, "digest '%s': 16 hex digits", d);
        char kd[GR_CACHE_KEY_LEN + 1], ke[GR_CACHE_KEY_LEN + 1];
        CHECK_OK(gr_cache_key_digest(s, d, kd, &err), err);
        CHECK(!strcmp(kd, k0));
        CHECK_OK(gr_cache_key_digest(s, "0000000000000000", ke, &err), err);
        CHECK_MSG(!strncmp(ke, k0, 16) && strcmp(ke + 17, k0 + 17) != 0, "another digest: %s vs %s", ke, k0);
        free(s);
    }

    /* directory rule */
    const char *out = getenv("GODRAYS_TEST_OUT");
    char root[1024], buf[4096], expect[2048];
    snprintf(root, sizeof root, "%s/report_cache", out ? out : "/tmp");
    char cmd[2200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    CHECK(system(cmd) == 0);
    gr_error err = {GR_OK, ""};
    snprintf(expect, sizeof expect, "%s/explicit/deeper", root);
    setenv("GODRAYS_CACHE", expect, 1);
    CHECK(gr_cache_dir(buf, sizeof buf, &err) == GR_OK && !strcmp(buf, expect) && file_exists(expect));
    /* an explicit directory that cannot be made is an error naming the variable */
    snprintf(expect, sizeof expect, "%s/a_file", root);
    FILE *f = fopen(expect, "w");
    CHECK(f != NULL);
    if (f) fclose(f);
    char below[2100];
    snprintf(below, sizeof below, "%s/sub", expect);
    setenv("GODRAYS_CACHE", below, 1);
    CHECK(gr_cache_dir(buf, sizeof buf, &err) == GR_E_IO && strstr(err.msg, "GODRAYS_CACHE") != NULL);
    unsetenv("GODRAYS_CACHE");
    snprintf(expect, sizeof expect, "%s/xdg", root);
    setenv("XDG_CACHE_HOME", expect, 1);
    snprintf(expect, sizeof expect, "%s/xdg/godrays", root);
    CHECK(gr_cache_dir(buf, sizeof buf, &err) == GR_OK && !strcmp(buf, expect));
    unsetenv("XDG_CACHE_HOME");
    snprintf(expect, sizeof expect, "%s/home", root);
    setenv("HOME", expect, 1);
    snprintf(expect, sizeof expect, "%s/home/.cache/godrays", root);
    CHECK(gr_cache_dir(buf, sizeof buf, &err) == GR_OK && !strcmp(buf, expect));
    /* an unusable HOME falls back to ./.godrays-cache in the working directory */
    setenv("HOME", below, 1);
    snprintf(expect, sizeof expect, "%s/cwd", root);
    mkdir(expect, 0777);
    CHECK(chdir(expect) == 0);
    CHECK(gr_cache_dir(buf, sizeof buf, &err) == GR_OK && !strcmp(buf, ".godrays-cache") &&
          file_exists(".godrays-cache"));

    /* store and load */
    char dir[2048];
    snprintf(dir, sizeof dir, "%s/store", root);
    mkdir(dir, 0777);
    gr_image *img = ref_image(8, 6, 1), *got = NULL;
    gr_metadata meta, back;
    gr_meta_init(&meta);
    gr_meta_init(&back);
    gr_meta_set_string(&meta, "godrays:renderer", "test");
    gr_meta_set_int(&meta, "godrays:partial", 0);
    int hit = -1;
    char why[2048];
    CHECK(gr_cache_load(dir, k0, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 &&
          strstr(why, "not cached yet"));
    CHECK_OK(gr_cache_store(dir, k0, img, &meta, &err), err);
    CHECK(gr_cache_load(dir, k0, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 1);
    if (got) {
        CHECK(got->width == 8 && got->height == 6 && got->nchannels == 6);
        CHECK(!memcmp(got->pixels, img->pixels, sizeof(float) * 8 * 6 * 6));
        const gr_meta_item *it = gr_meta_get(&back, GR_CACHE_META_KEY);
        CHECK(it && it->type == GR_META_STRING && !strcmp(it->str, k0));
        it = gr_meta_get(&back, "godrays:renderer");
        CHECK(it && it->type == GR_META_STRING && !strcmp(it->str, "test"));
    }
    gr_image_destroy(got);
    got = NULL;
    /* a different size is a miss */
    CHECK(gr_cache_load(dir, k0, 9, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 && !got &&
          strstr(why, "size 8 x 6, expected 9 x 6"));
    /* a file whose key attribute differs from its name (renamed, or a hash collision) is a miss */
    char p0[4300], p1[4300];
    CHECK(gr_cache_path(dir, k0, p0, sizeof p0, &err) == GR_OK);
    CHECK(gr_cache_path(dir, k1, p1, sizeof p1, &err) == GR_OK);
    CHECK(rename(p0, p1) == 0);
    CHECK(gr_cache_load(dir, k1, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 &&
          strstr(why, "does not match"));
    /* no stderr channels: a miss */
    gr_image *plain = ref_image(8, 6, 0);
    CHECK_OK(gr_cache_store(dir, k0, plain, &meta, &err), err);
    CHECK(gr_cache_load(dir, k0, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 &&
          strstr(why, "stderr.R is missing"));
    /* an interrupted render is never reused */
    gr_meta_set_int(&meta, "godrays:partial", 1);
    CHECK_OK(gr_cache_store(dir, k0, img, &meta, &err), err);
    CHECK(gr_cache_load(dir, k0, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 &&
          strstr(why, "partial"));
    /* garbage: a miss that says the file is unreadable */
    f = fopen(p0, "w");
    if (f) {
        fputs("not an EXR\n", f);
        fclose(f);
    }
    CHECK(gr_cache_load(dir, k0, 8, 6, &got, &back, &hit, why, sizeof why, &err) == GR_OK && hit == 0 &&
          strstr(why, "unreadable"));
    /* nothing temporary is left behind by the stores */
    snprintf(cmd, sizeof cmd, "ls '%s' | grep -q tmp", dir);
    CHECK(system(cmd) != 0);
    gr_image_destroy(img);
    gr_image_destroy(plain);
    gr_meta_free(&meta);
    gr_meta_free(&back);
    CHECK_DONE();
}
