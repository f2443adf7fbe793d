/* Memory limit (memlimit.h). */
#include "common/memlimit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static double g_limit = 0.0; /* 0: not set by a flag */

gr_status gr_memlimit_parse(const char *what, const char *text, double *bytes, gr_error *err)
{
    char *end = NULL;
    double v = text ? strtod(text, &end) : NAN;
    if (!text || end == text || !isfinite(v) || v <= 0.0)
        return gr_fail(err, GR_E_USAGE, "%s %s: expected a size such as 8G, 512M or a number of bytes", what,
                       text ? text : "");
    double mul = 1.0;
    if (*end) {
        const char *units = "KMGT";
        const char *u = strchr(units, *end >= 'a' ? *end - 32 : *end);
        if (!u || !*end) return gr_fail(err, GR_E_USAGE, "%s %s: unknown unit (K, M, G or T)", what, text);
        for (const char *q = units; q <= u; q++) mul *= 1024.0;
        end++;
        if (*end == 'B' || *end == 'b' || *end == 'i') end++;
        if (*end == 'B') end++;
        if (*end) return gr_fail(err, GR_E_USAGE, "%s %s: expected a size such as 8G, 512M or a number of bytes", what, text);
    }
    *bytes = v * mul;
    return GR_OK;
}

void gr_memlimit_set(double bytes) { g_limit = bytes; }

gr_status gr_memlimit_get(double *bytes, const char **source, gr_error *err)
{
    if (g_limit > 0.0) {
        *bytes = g_limit;
        *source = "--max-memory";
        return GR_OK;
    }
    const char *env = getenv("GODRAYS_MAX_MEMORY");
    if (env && env[0]) {
        *source = "GODRAYS_MAX_MEMORY";
        return gr_memlimit_parse("GODRAYS_MAX_MEMORY", env, bytes, err);
    }
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    *bytes = pages > 0 && page > 0 ? 0.8 * (double)pages * (double)page : INFINITY;
    *source = "80 % of the physical memory; --max-memory or GODRAYS_MAX_MEMORY to change it";
    return GR_OK;
}

gr_status gr_memlimit_check(const char *what, double need_bytes, const char *detail, gr_error *err)
{
    double limit;
    const char *source;
    gr_status st = gr_memlimit_get(&limit, &source, err);
    if (st != GR_OK) return st;
    if (need_bytes <= limit) return GR_OK;
    const double gib = 1024.0 * 1024.0 * 1024.0;
    return gr_fail(err, GR_E_INPUT, "%s needs about %.2f GiB (%s), over the memory limit of %.2f GiB (%s)", what,
                   need_bytes / gib, detail, limit / gib, source);
}
