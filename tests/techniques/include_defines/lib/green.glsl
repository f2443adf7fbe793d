#include "one.glsl"
float green() { return USE_GREEN != 0 ? ONE : 0.0; }
