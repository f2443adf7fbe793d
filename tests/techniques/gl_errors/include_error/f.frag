// the pass
out vec4 o_color;
#include "lib/common.glsl"
void main() { o_color = vec4(shade(), 1.0); }
