/* Which files a command reads and writes, so that no output replaces an input and no two
 * outputs share a file (docs/reliability.md, "Outputs"):
 *  - two names are the same file when both exist and stat (following symbolic links) gives the
 *    same device and inode (a symlink or a hard link to an input is that input), or when they
 *    resolve to the same place: the final target of their symlinks, its folder made absolute
 *    (realpath), so `c.bin`, `./c.bin` and `d/../c.bin` are one name before either exists;
 *  - the inputs a command names are registered for the whole process (gr_paths_add_input),
 *    and common/outfile refuses to replace one (GR_E_USAGE, exit 2), whatever the command and
 *    whatever the output, the files written into an output folder included. The commands check
 *    their outputs up front as well (src/cli/args.h) so that the refusal comes before any work.
 * The registry is filled on the main thread before any work and only read afterwards. */
#ifndef GR_PATHS_H
#define GR_PATHS_H

#include "common/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The file that writing to path replaces: path itself, or the final target of the chain of
 * symlinks it names (a relative target is relative to its link's folder). malloc'd; NULL: no
 * memory. A loop of links ends after 40 hops (the open then reports ELOOP). */
char *gr_path_final_target(const char *path);

/* 1 when a and b name the same file as described above, else 0. */
int gr_path_same_file(const char *a, const char *b);

/* Registers an input of this process, described for messages as `role path` (role: "the
 * scene", "part", "--scene"; both strings must outlive the process's checks). A path that does
 * not exist is not registered (it cannot be replaced; the command's own open reports it).
 * GR_E_NOMEM. */
gr_status gr_paths_add_input(const char *role, const char *path, gr_error *err);
/* GR_E_USAGE, "ROLE PATH: the same file as INROLE INPATH, an input: refusing to replace it",
 * when path is a registered input; role NULL: the message starts with the path alone. */
gr_status gr_paths_check_output(const char *role, const char *path, gr_error *err);
/* Forgets every registered input (tests). */
void gr_paths_clear(void);

#ifdef __cplusplus
}
#endif
#endif
