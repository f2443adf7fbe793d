/* placeholder until the GL module lands (replaced in the same session) */
#include "cli/cli.h"
int cmd_info(int argc, char **argv) { (void)argc; (void)argv; return 1; }
