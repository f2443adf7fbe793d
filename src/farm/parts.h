/* Parts of a ground-truth render and their merge (docs/farm.md). A part is a rectangle of
 * the work: image rows [row0, row1) x batches [batch0, batch1) of one scene (one frame, one
 * view), rendered by reference/integrator with gr_ref_options row/batch ranges. Its file
 * holds the raw per-batch sums, not an image: merging adds nothing up, it places each part's
 * sums where a single render would have accumulated them, and gr_ref_assemble then computes
 * the image, the error bars (batch-mean spread) and the statistics (image-level standard
 * errors, surface-bias probe) with the same code and the same floating-point order as a
 * single render: the merged EXR's pixels and error channels are its bytes.
 *
 * File format "godrays-part-1" (little-endian):
 *   line 1  "GODRAYS-PART 1"
 *   line 2  N, the byte length of the header
 *   N bytes a JSON header: format, cache_key, scene (the normalized scene JSON), scene_path,
 *           width, height, batches, row0, row1, batch0, batch1, passes, probe fields
 *           (levels, grid, its rows), timing counters, provenance (host, pid, date, wall_s,
 *           threads, version, command), payload_bytes, payload_fnv1a64
 *           (the sums' scalars under their names in reference/sums.h's table, which the
 *           writer, the reader and the merge all go through)
 *   payload for rows y in [row0, row1), x in [0, W), batches b in [batch0, batch1):
 *           3 doubles (RGB sums), then the same order again as uint32 sample counts; if the
 *           part ran the probe (it holds batch 0), for each of its probe_levels accumulators the
 *           probe rows inside [row0, row1): 3 doubles per probe pixel, then uint32 counts.
 *           (the table's arrays in its order.)
 * Files are written to a temporary name and renamed: never half a part. */
#ifndef GR_FARM_PARTS_H
#define GR_FARM_PARTS_H

#include "common/status.h"
#include "reference/integrator.h"
#include "scene/scene.h"

#define GR_PART_FORMAT "godrays-part-1"

/* Rows of tile i of n over h rows: [i h / n, (i + 1) h / n). */
void gr_part_rows(int i, int n, int h, int *row0, int *row1);

/* Writes the part that res (rendered with keep_sums and o's row/batch ranges) holds.
 * command: how it was made (provenance; may be NULL). GR_E_IO naming path. */
gr_status gr_part_write(const char *path, const gr_scene *scene, const gr_ref_options *o, const gr_ref_result *res,
                        const char *command, gr_error *err);

/* The merge of n part files. On success *scene is the parts' scene and out the result a
 * single render of it gives (pixels, error channels, statistics), with its metadata plus
 * godrays:merged_parts and one godrays:part.K provenance line per part, and key its cache
 * key. A file that does not read, a missing rectangle, a duplicated or overlapping one, or
 * parts of different scenes or settings: GR_E_INPUT naming the file(s) (exit 2). */
gr_status gr_parts_merge(const char *const *paths, int n, gr_scene *scene, gr_ref_result *out, char *key,
                         size_t key_n, gr_error *err);

#endif
