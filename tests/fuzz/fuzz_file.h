/* The fuzz input as a file the readers open by name: an in-memory file (memfd) reached as
 * /proc/self/fd/N (gr_fuzz_file), or, where the reader goes by the name's extension, a file
 * NAME.EXT in /dev/shm (tmpfs) (gr_fuzz_named_file); rewritten for every input, no disk I/O. */
#ifndef GR_FUZZ_FILE_H
#define GR_FUZZ_FILE_H
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

static const char *gr_fuzz_file(const uint8_t *data, size_t size)
{
    static int fd = -1;
    static char path[64];
    if (fd < 0) {
        fd = memfd_create("gr_fuzz", 0);
        if (fd < 0) abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    if (ftruncate(fd, 0) != 0) abort();
    if (size && pwrite(fd, data, size, 0) != (ssize_t)size) abort();
    return path;
}

static void gr_fuzz_cleanup(void);
static char gr_fuzz_paths[32][96];
static int gr_fuzz_npaths = 0;
static void gr_fuzz_cleanup(void)
{
    for (int i = 0; i < gr_fuzz_npaths; i++) unlink(gr_fuzz_paths[i]);
}

static const char *gr_fuzz_named_file(const uint8_t *data, size_t size, const char *ext)
{
    static char path[96];
    snprintf(path, sizeof path, "/dev/shm/gr_fuzz_%ld.%s", (long)getpid(), ext);
    int known = 0;
    for (int i = 0; i < gr_fuzz_npaths; i++) known |= !strcmp(gr_fuzz_paths[i], path);
    if (!known && gr_fuzz_npaths < 32) {
        if (gr_fuzz_npaths == 0) atexit(gr_fuzz_cleanup);
        snprintf(gr_fuzz_paths[gr_fuzz_npaths++], sizeof gr_fuzz_paths[0], "%s", path);
    }
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd < 0) abort();
    if (size && write(fd, data, size) != (ssize_t)size) abort();
    close(fd);
    return path;
}
#endif
