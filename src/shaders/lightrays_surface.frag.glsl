#version 450 core
// Light rays, pass 1: the surface point (eye-relative, w = 1: a surface is there) and its unit
// normal, per texel of the light's view (nearest to the sun by the depth test).
in vec3 v_p;
in vec3 v_n;
layout(location = 0) out vec4 o_pos;
layout(location = 1) out vec4 o_nrm;
void main()
{
    o_pos = vec4(v_p, 1.0);
    o_nrm = vec4(normalize(v_n), 0.0);
}
