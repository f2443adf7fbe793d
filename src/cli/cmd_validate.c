/* placeholder until the scene module lands (replaced in the same session) */
#include "cli/cli.h"
int cmd_validate(int argc, char **argv) { (void)argc; (void)argv; return 1; }
