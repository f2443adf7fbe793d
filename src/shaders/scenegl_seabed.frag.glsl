#version 330 core
// Distance from the eye to the seabed plane y = u_seabed_rel (relative to the eye) along
// this pixel's view ray: t = y / dir.y for a unit dir pointing down; the far distance when
// the ray never meets it. Blended with GL_MIN over the occluders' distances.
in vec3 v_dir;
uniform float u_seabed_rel; // seabed y - eye y (m); < 0 below the eye
uniform float u_far;
layout(location = 0) out float o_dist;
void main()
{
    vec3 d = normalize(v_dir);
    float t = u_far;
    if (d.y < 0.0 && u_seabed_rel < 0.0) t = min(u_far, u_seabed_rel / d.y);
    o_dist = t;
}
