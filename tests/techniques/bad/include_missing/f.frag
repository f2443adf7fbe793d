#include "nope.glsl"
