#version 450 core
// Caustic texture (seed 002): additive blend of each caustic triangle's intensity.
in float g_value;
layout(location = 0) out vec4 o_value;
void main() { o_value = vec4(g_value, 0.0, 0.0, 1.0); }
