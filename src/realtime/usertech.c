/* TEMPORARY placeholder, to be replaced at merge by the real src/realtime/usertech.c of branch
 * `user` (issue 10, item 5: user techniques from a folder with a JSON manifest). It only lets
 * the registry and the --technique-dir options link and fail cleanly until then. */
#include "realtime/technique.h"

gr_status gr_technique_add_dir(const char *dir, gr_error *err)
{
    return gr_fail(err, GR_E_INPUT, "%s: user techniques are not available in this build", dir ? dir : "(null)");
}
