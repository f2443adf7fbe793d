/* common/paths: "the same file" (device and inode through symlinks and hard links; the
 * resolved place before a file exists), the input registry and common/outfile's refusal to
 * replace an input (issue 31, findings 1 and 2). The expectations are the file system's own:
 * what stat, symlink and link make of the names, written out by hand. */
#define _DEFAULT_SOURCE /* mkdtemp, symlink */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "common/outfile.h"
#include "common/paths.h"

static void touch(const char *p, const char *text)
{
    FILE *f = fopen(p, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

int main(void)
{
    char dir[] = "/tmp/godrays-paths-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    CHECK(chdir(dir) == 0);
    CHECK(mkdir("sub", 0755) == 0);
    touch("a.json", "{}");
    touch("b.json", "{}"); /* same bytes, another file */
    CHECK(symlink("a.json", "la.json") == 0);
    CHECK(symlink("../a.json", "sub/lla.json") == 0);
    CHECK(link("a.json", "ha.json") == 0);

    /* existing files: device and inode */
    CHECK(gr_path_same_file("a.json", "a.json"));
    CHECK(gr_path_same_file("a.json", "./sub/../a.json"));
    CHECK(gr_path_same_file("la.json", "a.json"));
    CHECK(gr_path_same_file("sub/lla.json", "a.json"));
    CHECK(gr_path_same_file("ha.json", "a.json"));
    CHECK(!gr_path_same_file("a.json", "b.json"));
    /* one exists, the other not: never the same */
    CHECK(!gr_path_same_file("a.json", "new.json"));
    /* neither exists: the same place */
    CHECK(gr_path_same_file("c.bin", "./c.bin"));
    CHECK(gr_path_same_file("c.bin", "sub/../c.bin"));
    CHECK(!gr_path_same_file("c.bin", "sub/c.bin"));
    CHECK(symlink("c.bin", "lc.bin") == 0); /* a dangling link: writing it writes c.bin */
    CHECK(gr_path_same_file("lc.bin", "c.bin"));

    /* the registry: an input is refused as an output, whatever its name; others pass */
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_paths_add_input("the scene", "a.json", &err), err);
    CHECK_OK(gr_paths_add_input("the scene", "missing.json", &err), err); /* ignored */
    CHECK(gr_paths_check_output("--constants", "b.json", &err) == GR_OK);
    CHECK(gr_paths_check_output("--constants", "missing.json", &err) == GR_OK);
    CHECK(gr_paths_check_output("--constants", "la.json", &err) == GR_E_USAGE);
    CHECK_MSG(!strcmp(err.msg, "--constants la.json: the same file as the scene a.json, an input: refusing to replace it"),
              "message: %s", err.msg);
    CHECK(gr_paths_check_output("-o", "ha.json", &err) == GR_E_USAGE);

    /* common/outfile refuses it too, creating nothing; the input keeps its bytes */
    gr_outfile o;
    CHECK(gr_outfile_open(&o, "sub/lla.json", &err) == GR_E_USAGE);
    CHECK(o.tmp == NULL);
    CHECK(gr_outfile_write("a.json", "replaced", -1, &err) == GR_E_USAGE);
    FILE *f = fopen("a.json", "r");
    char buf[16] = "";
    CHECK(f && fgets(buf, sizeof buf, f));
    if (f) fclose(f);
    CHECK(!strcmp(buf, "{}"));
    CHECK_OK(gr_outfile_write("b.json", "fine", -1, &err), err);

    /* gr_outfile_finish then commit: the check first, the rename only at commit */
    CHECK_OK(gr_outfile_open(&o, "p.bin", &err), err);
    fputs("12345", o.f);
    CHECK_OK(gr_outfile_finish(&o, 5, &err), err);
    struct stat sb;
    CHECK(stat("p.bin", &sb) != 0); /* not in place yet */
    CHECK_OK(gr_outfile_commit(&o, 5, &err), err);
    CHECK(stat("p.bin", &sb) == 0 && sb.st_size == 5);

    gr_paths_clear();
    CHECK(gr_paths_check_output("-o", "a.json", &err) == GR_OK);
    const char *rm[] = {"a.json", "b.json", "la.json", "sub/lla.json", "ha.json", "lc.bin", "p.bin"};
    for (size_t k = 0; k < sizeof rm / sizeof rm[0]; k++) unlink(rm[k]);
    rmdir("sub");
    CHECK(chdir("/") == 0);
    rmdir(dir);
    CHECK_DONE();
}
