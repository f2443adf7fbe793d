/* Atomic output files (outfile.h). */
#include "common/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/paths.h"
#include "common/signals.h"

static atomic_int g_counter = 0;

static const char *kind_name(mode_t m)
{
    if (S_ISDIR(m)) return "a folder";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISSOCK(m)) return "a socket";
    return "not a regular file";
}

static gr_status begin(gr_outfile *o, const char *path, int defer, gr_error *err)
{
    memset(o, 0, sizeof *o);
    o->slot = -1;
    if (!path || !path[0]) return gr_fail(err, GR_E_USAGE, "output: empty file name");
    /* an input of the command is never replaced, whatever the output (common/paths) */
    gr_status pst = gr_paths_check_output(NULL, path, err);
    if (pst != GR_OK) return pst;
    char *target = gr_path_final_target(path);
    if (!target) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    struct stat sb;
    if (stat(target, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        free(target);
        return gr_fail(err, GR_E_IO, "%s: cannot write: %s", path, strerror(EISDIR));
    }
    if (stat(target, &sb) == 0 && !S_ISREG(sb.st_mode)) {
        gr_status st = gr_fail(err, GR_E_INPUT, "%s: exists and is %s, not a regular file: refusing to replace it",
                               path, kind_name(sb.st_mode));
        free(target);
        return st;
    }
    size_t n = strlen(target) + 64;
    char *tmp = malloc(n);
    if (!tmp) {
        free(target);
        return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
    }
    snprintf(tmp, n, "%s.tmp-%ld-%d", target, (long)getpid(), atomic_fetch_add(&g_counter, 1));
    o->path = target;
    o->tmp = tmp;
    o->deferred = defer;
    if (defer) gr_signals_defer_begin();
    o->slot = gr_signals_add_temp(tmp);
    return GR_OK;
}

gr_status gr_outfile_begin(gr_outfile *o, const char *path, gr_error *err)
{
    return begin(o, path, 1, err);
}

static gr_status open_with(gr_outfile *o, const char *path, int defer, gr_error *err)
{
    gr_status st = begin(o, path, defer, err);
    if (st != GR_OK) return st;
    o->f = fopen(o->tmp, "wb");
    if (!o->f) {
        st = gr_fail(err, GR_E_IO, "%s: cannot create %s: %s", path, o->tmp, strerror(errno));
        gr_outfile_abort(o);
    }
    return st;
}

gr_status gr_outfile_open(gr_outfile *o, const char *path, gr_error *err)
{
    return open_with(o, path, 1, err);
}

gr_status gr_outfile_open_stream(gr_outfile *o, const char *path, gr_error *err)
{
    return open_with(o, path, 0, err);
}

static void release(gr_outfile *o, int remove_tmp)
{
    if (o->f) fclose(o->f);
    if (remove_tmp && o->tmp) unlink(o->tmp);
    const int had = o->tmp != NULL && o->deferred;
    gr_signals_remove_temp(o->slot);
    free(o->path);
    free(o->tmp);
    memset(o, 0, sizeof *o);
    o->slot = -1;
    if (had) gr_signals_defer_end(); /* may end the process if a signal waited */
}

void gr_outfile_abort(gr_outfile *o)
{
    if (o) release(o, 1);
}

gr_status gr_outfile_finish(gr_outfile *o, long long min_size, gr_error *err)
{
    if (!o->tmp) return gr_fail(err, GR_E_USAGE, "output: commit without begin");
    if (o->finished) return GR_OK;
    if (!o->deferred) { /* from here to the rename a signal waits, as for any output */
        gr_signals_defer_begin();
        o->deferred = 1;
    }
    gr_status st = GR_OK;
    int e = 0;
    if (o->f) {
        FILE *f = o->f;
        o->f = NULL;
        int bad = ferror(f) != 0;
        if (!bad && fflush(f) != 0) { bad = 1; e = errno; }
        if (!bad && fsync(fileno(f)) != 0 && errno != EINVAL) { bad = 1; e = errno; }
        if (fclose(f) != 0 && !bad) { bad = 1; e = errno; }
        if (bad) st = gr_fail(err, GR_E_IO, "%s: cannot write: %s", o->path, e ? strerror(e) : "write error");
    } else {
        int fd = open(o->tmp, O_RDONLY);
        if (fd < 0) {
            st = gr_fail(err, GR_E_IO, "%s: cannot reopen %s: %s", o->path, o->tmp, strerror(errno));
        } else {
            if (fsync(fd) != 0 && errno != EINVAL)
                st = gr_fail(err, GR_E_IO, "%s: cannot write: %s", o->path, strerror(errno));
            close(fd);
        }
    }
    struct stat sb;
    if (st == GR_OK) {
        if (stat(o->tmp, &sb) != 0)
            st = gr_fail(err, GR_E_IO, "%s: %s vanished: %s", o->path, o->tmp, strerror(errno));
        else if ((long long)sb.st_size < min_size)
            st = gr_fail(err, GR_E_IO, "%s: cannot write: only %lld of at least %lld bytes reached the disk "
                         "(is it full?)", o->path, (long long)sb.st_size, min_size);
    }
    if (st != GR_OK) release(o, 1);
    else o->finished = 1;
    return st;
}

gr_status gr_outfile_commit(gr_outfile *o, long long min_size, gr_error *err)
{
    gr_status st = gr_outfile_finish(o, min_size, err);
    if (st != GR_OK) return st;
    if (rename(o->tmp, o->path) != 0)
        st = gr_fail(err, GR_E_IO, "%s: cannot rename %s into place: %s", o->path, o->tmp, strerror(errno));
    release(o, st != GR_OK);
    return st;
}

gr_status gr_outfile_write(const char *path, const char *text, long long len, gr_error *err)
{
    gr_outfile o;
    gr_status st = gr_outfile_open(&o, path, err);
    if (st != GR_OK) return st;
    size_t n = len < 0 ? strlen(text) : (size_t)len;
    if (n && fwrite(text, 1, n, o.f) != n) {
        const int e = errno;
        gr_outfile_abort(&o);
        return gr_fail(err, GR_E_IO, "%s: cannot write: %s", path, strerror(e));
    }
    return gr_outfile_commit(&o, (long long)n, err);
}

gr_status gr_check_regular_input(const char *path, gr_error *err)
{
    struct stat sb;
    if (path && stat(path, &sb) == 0 && !S_ISREG(sb.st_mode) && !S_ISDIR(sb.st_mode))
        return gr_fail(err, GR_E_INPUT, "%s: %s, not a regular file: refusing to read it", path, kind_name(sb.st_mode));
    return GR_OK;
}
