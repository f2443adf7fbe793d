#version 330 core
// Seed 003's localized rays: one screen quad per light, all lights in one draw. Each vertex
// carries its corner (-1..1), its light's uv and the quad's half-size in uv.
layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec2 a_light_uv;
layout(location = 2) in vec2 a_half;
out vec2 v_corner;
flat out vec2 v_light_uv;
void main()
{
    v_corner = a_corner;
    v_light_uv = a_light_uv;
    vec2 uv = a_light_uv + a_corner * a_half;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
