/* Small helpers for tests that read what the code wrote: a whole file as text, and a member of
 * parsed JSON by a dotted path ("errors_y.rmse"). Header-only, like check.h. */
#ifndef GR_TEST_FILES_H
#define GR_TEST_FILES_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

/* The file's bytes, NUL-terminated (malloc'd); NULL if it cannot be read. */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) n = 0;
    if (s) s[n] = '\0';
    fclose(f);
    return s;
}

/* o's member at a dotted path of object keys; NULL if any is missing. */
static cJSON *get(cJSON *o, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *tok = strtok(buf, "."); tok && o; tok = strtok(NULL, ".")) o = cJSON_GetObjectItemCaseSensitive(o, tok);
    return o;
}

#endif
