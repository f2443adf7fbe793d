// three values from the manifest's defines and an include
out vec4 o_color;
#include "lib/green.glsl"
void main() { o_color = vec4(RED, green(), BLUE_EXPR, 1.0); }
