/* Memory estimates checked before large allocations (docs/reliability.md, "Memory"): a
 * command that would need more than the limit refuses at once with exit 2 and the estimate,
 * instead of failing late or being killed by the kernel.
 * The limit: gr_memlimit_set (a command's --max-memory), else $GODRAYS_MAX_MEMORY, else 80 %
 * of the machine's physical memory. Sizes are written like 512M, 8G, 1.5G or plain bytes. */
#ifndef GR_MEMLIMIT_H
#define GR_MEMLIMIT_H

#include "common/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Parses "8G", "512M", "1.5G", "100000" (K, M, G, T: powers of 1024) into *bytes; GR_E_USAGE
 * naming what (e.g. "--max-memory") when it is not a size > 0. */
gr_status gr_memlimit_parse(const char *what, const char *text, double *bytes, gr_error *err);
void gr_memlimit_set(double bytes);
/* The limit in bytes and where it comes from ("--max-memory", "GODRAYS_MAX_MEMORY", "80 % of
 * the physical memory"). An unparsable $GODRAYS_MAX_MEMORY is GR_E_USAGE. */
gr_status gr_memlimit_get(double *bytes, const char **source, gr_error *err);
/* GR_OK when need_bytes fits the limit, else GR_E_INPUT "WHAT needs about X GiB (DETAIL),
 * over the memory limit of Y GiB (SOURCE)". */
gr_status gr_memlimit_check(const char *what, double need_bytes, const char *detail, gr_error *err);

#ifdef __cplusplus
}
#endif
#endif
