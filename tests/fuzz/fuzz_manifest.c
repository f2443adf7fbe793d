/* libFuzzer target: a user technique's manifest (docs/techniques.md) parsed and validated by
 * gr_ut_manifest_load, with every input length and byte, as DIR/manifest.json in a folder on
 * tmpfs (/dev/shm) that also holds the shader files the seeds name (a.frag, b.frag, a.vert,
 * march.frag, upsample.frag) and one link out of the folder (out.frag -> /etc/hostname), so
 * that passes, links and the containment check are reached. No GL: the renderer is not run.
 * Corpus: tests/fuzz/corpus/manifest/ (the shipped example and tests/techniques/bad/). */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "realtime/usertech_manifest.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[96], manifest[128];

static void cleanup(void)
{
    static const char *const names[] = {"a.frag", "b.frag", "a.vert", "march.frag", "upsample.frag", "out.frag",
                                        GR_USERTECH_MANIFEST};
    char p[160];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        unlink(p);
    }
    rmdir(dir);
}

static void setup(void)
{
    static const char *const names[] = {"a.frag", "b.frag", "a.vert", "march.frag", "upsample.frag"};
    char p[160];
    snprintf(dir, sizeof dir, "/dev/shm/gr_fuzz_manifest_%ld", (long)getpid());
    if (mkdir(dir, 0700) != 0) abort();
    atexit(cleanup);
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        FILE *f = fopen(p, "w");
        if (!f) abort();
        fputs("out vec4 o_color;\nvoid main() { o_color = vec4(1.0); }\n", f);
        fclose(f);
    }
    snprintf(p, sizeof p, "%s/out.frag", dir);
    if (symlink("/etc/hostname", p) != 0) abort();
    snprintf(manifest, sizeof manifest, "%s/%s", dir, GR_USERTECH_MANIFEST);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!dir[0]) setup();
    FILE *f = fopen(manifest, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    gr_ut_manifest *m = NULL;
    gr_error err = {GR_OK, ""};
    if (gr_ut_manifest_load(dir, &m, &err) == GR_OK) {
        if (!m || !m->n_passes || !m->passes[0].fragment_src || strlen(m->source_hash) != 16) abort();
        gr_ut_manifest_free(m);
    } else if (m || !memchr(err.msg, '\0', sizeof err.msg) || strchr(err.msg, '\n') || !err.msg[0]) {
        abort(); /* the promise: no manifest, and one terminated line */
    }
    return 0;
}
