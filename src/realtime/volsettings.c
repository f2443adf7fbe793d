/* The volume techniques' settings block (volsettings.h): no GL. */
#include "realtime/volsettings.h"

#include <stdio.h>

/* The block alone, for its descriptors' offsets (vol first: offsets into gr_vol_settings). */
typedef struct vol_block {
    gr_vol_settings vol;
} vol_block;
static const gr_param vol_caustic_descriptors[] = {GR_VOL_PARAMS_CAUSTICS(vol_block), GR_VOL_PARAMS_SUN_DISC(vol_block)};

const gr_param *gr_vol_caustic_descriptors(size_t *n)
{
    *n = sizeof vol_caustic_descriptors / sizeof vol_caustic_descriptors[0];
    return vol_caustic_descriptors;
}

gr_status gr_vol_check(const char *name, const gr_vol_settings *s, gr_error *err)
{
    if (!(s->caustic_last_m >= s->caustic_first_m))
        return gr_fail(err, GR_E_INPUT, "%s.caustic_last_m = %g: must be >= %s.caustic_first_m (%g)", name,
                       s->caustic_last_m, name, s->caustic_first_m);
    return GR_OK;
}
