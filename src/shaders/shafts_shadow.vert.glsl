#version 330 core
// Shadow map of the occluders, orthographic along the refracted sun from P (seed eq. 5.5.5).
layout(location = 0) in vec3 a_pos; // occluder vertex relative to P (m)
uniform mat4 u_light_view_proj;     // P-relative world -> light clip space
void main()
{
    gl_Position = u_light_view_proj * vec4(a_pos, 1.0);
}
