// shared code
#include "../missing_shader/a.frag"
