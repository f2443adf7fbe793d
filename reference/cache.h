/* The ground-truth cache: a reference render is slow (about 2 minutes on the default scene on
 * 2 cores) and depends only on the scene's content, the reference settings and the code that
 * renders it, so it is stored as an EXR and reused while none of them changes. Reads and
 * writes go through the ground-truth provider (reference/truth.h); docs/reference.md.
 *
 * Key = "SCENEHASH-SETTINGSHASH" (16 hex digits each, FNV-1a 64):
 *  - SCENEHASH: the normalized scene JSON (every default filled in, stable key order) without
 *    the "name" and "reference" sections and every real-time technique's section
 *    (scene/sections.h): what the ground truth renders. A change of the real-time settings or
 *    of the scene's label does not invalidate the reference.
 *  - SETTINGSHASH: every reference.* setting except `threads` (the integrator gives the same
 *    bytes for any thread count), plus the godrays version and the build digest of the ground
 *    truth's sources (gr_cache_digest: scripts/truth_digest.cmake hashes reference/, src/core,
 *    src/scene and src/image/image.* at build time), so an edit of the integrator or of the
 *    settings table invalidates every older entry with no constant to bump by hand.
 * The file is CACHEDIR/reference-KEY.exr and carries the key in its "godrays:cache_key"
 * attribute; a read checks that key, the size, the channels, that the render was complete and
 * the checksum of the pixels (GR_CACHE_META_CHECKSUM), and treats any mismatch as a miss (with
 * the reason). A read also removes temporary files of killed processes from the folder. */
#ifndef GR_CACHE_H
#define GR_CACHE_H

#include <stddef.h>
#include "common/status.h"
#include "image/image.h"
#include "scene/scene.h"

#define GR_CACHE_KEY_LEN 33          /* 16 + 1 + 16 hex characters */
#define GR_CACHE_META_KEY "godrays:cache_key"
/* FNV-1a 64 of the pixel bytes (16 hex digits), checked on every read (docs/reliability.md) */
#define GR_CACHE_META_CHECKSUM "godrays:pixel_fnv1a64"

/* FNV-1a 64 (Fowler, Noll, Vo) of n bytes, continuing from h (start: GR_FNV_BASIS). */
#define GR_FNV_BASIS 14695981039346656037ull
unsigned long long gr_fnv1a64(unsigned long long h, const void *data, size_t n);

/* The build digest of the ground truth's sources (16 hex digits; scripts/truth_digest.cmake). */
const char *gr_cache_digest(void);

/* The cache key of s's ground truth into key[GR_CACHE_KEY_LEN + 1], with this build's digest.
 * GR_E_NOMEM. */
gr_status gr_cache_key(const gr_scene *s, char *key, gr_error *err);
/* The same with another build digest (what another build's key would be; tests). */
gr_status gr_cache_key_digest(const gr_scene *s, const char *digest, char *key, gr_error *err);

/* Chooses and creates the cache directory: $GODRAYS_CACHE if set and non-empty, else
 * $XDG_CACHE_HOME/godrays or $HOME/.cache/godrays, else ./.godrays-cache (relative to the
 * working directory, e.g. the build directory). The first that exists or can be created and
 * is writable wins; $GODRAYS_CACHE, when set, is the only candidate (a user who names a
 * directory means it): GR_E_IO naming GODRAYS_CACHE if it is unusable. */
gr_status gr_cache_dir(char *buf, size_t n, gr_error *err);

/* CACHEDIR/reference-KEY.exr into buf. GR_E_USAGE if it does not fit. */
gr_status gr_cache_path(const char *dir, const char *key, char *buf, size_t n, gr_error *err);

/* Looks the key up. On a valid entry *hit = 1, *img (caller destroys) and meta (initialized
 * by the caller; filled with the file's attributes) hold it. A missing file, a file that does
 * not read, or one that fails a check (key attribute, size width x height, channels R, G, B,
 * stderr.R/G/B, godrays:partial = 0, finite samples) gives *hit = 0 and the reason in why
 * (may be NULL); only allocation failures are errors (GR_E_NOMEM). */
gr_status gr_cache_load(const char *dir, const char *key, int width, int height, gr_image **img,
                        gr_metadata *meta, int *hit, char *why, size_t why_n, gr_error *err);

/* Stores img with meta plus the key attribute (atomically: temporary file renamed into
 * place, so concurrent runs never see half a file). */
gr_status gr_cache_store(const char *dir, const char *key, const gr_image *img, const gr_metadata *meta,
                         gr_error *err);

#endif
