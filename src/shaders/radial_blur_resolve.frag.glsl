#version 330 core
// Seed 003 resolve: sum of the quads' (f c, f) -> c-weighted mean where quads overlap
// (divide by max(1, sum f) when u_normalize), times the output scale.
uniform sampler2D u_acc;
uniform vec3 u_scale;
uniform int u_normalize;
layout(location = 0) out vec4 o_color;
void main()
{
    vec4 a = texelFetch(u_acc, ivec2(gl_FragCoord.xy), 0);
    float d = u_normalize != 0 ? max(1.0, a.a) : 1.0;
    o_color = vec4(a.rgb / d * u_scale, 1.0);
}
