/* libFuzzer target: the scene loader (JSON text -> validated gr_scene, then printed back),
 * with every input length and byte. Corpus: tests/fuzz/corpus/scene/ (the shipped scenes and
 * the rejected ones of tests/scenes/bad). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *json = malloc(size + 1);
    gr_scene *s = calloc(1, sizeof *s);
    if (!json || !s) {
        free(json);
        free(s);
        return 0;
    }
    memcpy(json, data, size);
    json[size] = '\0';
    gr_error err = {GR_OK, ""};
    if (gr_scene_load_string(json, "fuzz", NULL, 0, s, &err) == GR_OK) {
        char *back = gr_scene_to_json(s);
        free(back);
    } else if (!memchr(err.msg, '\0', sizeof err.msg) || strchr(err.msg, '\n')) {
        abort(); /* the promise: one terminated line */
    }
    free(s);
    free(json);
    return 0;
}
