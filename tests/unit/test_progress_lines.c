/* reference/progress.h when stderr is no terminal (issue 29): whole lines, one per 10 % (or
 * per 10 s), silent in the first 2 s, never when disabled (--quiet), with the elapsed and
 * remaining time. stderr is redirected to a file (not a terminal) and read back. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "reference/progress.h"

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    nanosleep(&ts, NULL);
}

int main(void)
{
    char path[] = "/tmp/gr_progress_lines_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    dup2(fd, STDERR_FILENO);
    CHECK(!isatty(STDERR_FILENO));

    gr_progress *q = gr_progress_create("quiet", 0);
    gr_progress *p = gr_progress_create("truth", 1);
    CHECK(p && q);
    gr_progress_update(p, 0.5, "early"); /* within the first 2 s: silent */
    sleep_s(2.1);
    gr_progress_update(q, 0.5, "disabled");
    gr_progress_update(p, 0.55, "same decile as nothing printed yet: a line"); /* 5 deciles crossed since 0 */
    gr_progress_update(p, 0.57, "same decile: silent");
    gr_progress_update(p, 0.61, "next decile");
    gr_progress_update(p, 1.0, "done: silent (the step's own message follows)");
    gr_progress_destroy(p);
    gr_progress_destroy(q);

    fflush(stderr);
    dup2(saved, STDERR_FILENO);
    close(saved);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL);
    char buf[4096] = "";
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    buf[n] = '\0';
    if (f) fclose(f);
    close(fd);
    unlink(path);
    int lines = 0;
    for (char *c = buf; *c; c++) lines += *c == '\n';
    CHECK_MSG(lines == 2, "%d lines:\n%s", lines, buf);
    CHECK_MSG(strstr(buf, "truth:  55%  elapsed 00:02  remaining 00:02  same decile as nothing printed yet") != NULL, "%s", buf);
    CHECK_MSG(strstr(buf, "truth:  61%  elapsed 00:02  remaining 00:01  next decile\n") != NULL, "%s", buf);
    CHECK(strstr(buf, "quiet") == NULL && strstr(buf, "silent") == NULL && strstr(buf, "early") == NULL);
    CHECK(strchr(buf, '\r') == NULL && strchr(buf, '\033') == NULL); /* no bar, no escapes */
    CHECK_DONE();
}
