/* Output files written atomically, the one way every writer in godrays replaces a file
 * (docs/reliability.md):
 *  - an existing output that is not a regular file (a device node, a FIFO, a socket) is
 *    refused with GR_E_INPUT (exit 2): nothing is created, the node stays (a folder:
 *    GR_E_IO "Is a directory", as the rename would fail);
 *  - a symbolic link is followed: its final target is the file replaced, the link stays;
 *  - the data goes to TARGET.tmp-PID-N (N counts this process's outputs, so concurrent
 *    processes and threads never share a temporary name) in the target's folder;
 *  - every write, the flush, fsync and close are checked, and the file's size is checked
 *    before it is renamed over the target: a full disk gives GR_E_IO and no file, never a
 *    truncated one;
 *  - an input of the command (common/paths) is never replaced: GR_E_USAGE;
 *  - the temporary name is registered with common/signals so that SIGINT or SIGTERM removes
 *    it, and a signal arriving while a file is written is handled once it is in place. */
#ifndef GR_OUTFILE_H
#define GR_OUTFILE_H

#include <stdio.h>
#include "common/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gr_outfile {
    char *path;  /* what is replaced: the output, or its symlink's final target (owned) */
    char *tmp;   /* the temporary name to write to (owned) */
    FILE *f;     /* open on tmp after gr_outfile_open, else NULL */
    int slot;    /* its entry in the signal-cleanup registry, -1 when none */
    int deferred; /* signals wait while it is written (all but gr_outfile_open_stream's) */
    int finished; /* gr_outfile_finish succeeded: only the rename is left */
} gr_outfile;

/* Checks path (refusing an existing non-regular file, following symlinks), chooses the
 * temporary name and registers it. The caller writes o->tmp by any means, then calls
 * gr_outfile_commit or gr_outfile_abort. o is zeroed on failure. */
gr_status gr_outfile_begin(gr_outfile *o, const char *path, gr_error *err);
/* gr_outfile_begin, then o->f = fopen(o->tmp, "wb"). */
gr_status gr_outfile_open(gr_outfile *o, const char *path, gr_error *err);
/* gr_outfile_open for an output written over a long time (tune's trace.csv, one line per
 * evaluation): a signal is not held back while it is open but ends the process at once, which
 * removes the temporary file and leaves the previous file at path as it was; from
 * gr_outfile_finish or gr_outfile_commit on, a signal waits as for any output. */
gr_status gr_outfile_open_stream(gr_outfile *o, const char *path, gr_error *err);
/* The checks of gr_outfile_commit without the rename: closes o->f (ferror, fflush, fsync,
 * fclose) and checks the size. On failure o->tmp is removed and o released. Lets a caller
 * write several files and rename them only once all are complete (a .gltf and its .bin);
 * gr_outfile_commit then only renames. */
gr_status gr_outfile_finish(gr_outfile *o, long long min_size, gr_error *err);
/* Closes o->f if open (checking ferror, fflush, fsync, fclose), checks that o->tmp holds at
 * least min_size bytes (a writer that hides a failed write leaves fewer), then renames it over
 * o->path. On any failure o->tmp is removed and the message names o->path. Always releases o. */
gr_status gr_outfile_commit(gr_outfile *o, long long min_size, gr_error *err);
/* Closes and removes the temporary file; releases o. Accepts a zeroed or released o. */
void gr_outfile_abort(gr_outfile *o);

/* The whole text (len bytes; len < 0: strlen) written to path as above. */
gr_status gr_outfile_write(const char *path, const char *text, long long len, gr_error *err);

/* Refuses (GR_E_INPUT, exit 2) an input that exists and is neither a regular file nor a
 * folder (a FIFO, a device, a socket: reading one blocks or spins forever), before it is
 * opened; stat follows symlinks. Anything else is left to the open that follows. */
gr_status gr_check_regular_input(const char *path, gr_error *err);

#ifdef __cplusplus
}
#endif
#endif
