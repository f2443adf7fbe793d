#version 330 core
// Seed 000 shaft pixel shader: interpolated intensity times an unfiltered shadow test.

in vec3 v_intensity;
in vec4 v_shadow_pos;
in vec3 v_world;

uniform sampler2D u_shadow_map; // depth along the refracted sun, [0,1] over [near, far]
uniform float u_shadow_bias;    // depth bias in the same [0,1] units

layout(location = 0) out vec4 o_color;

void main()
{
    // Distance to the light source (normalized depth along the refracted sun).
    float z = v_shadow_pos.z / v_shadow_pos.w;
    // Fetch shadowmap (point sampled, as the seed's sampler state).
    float sz = textureProj(u_shadow_map, v_shadow_pos).x;
    float lit = (z - u_shadow_bias < sz) ? 1.0 : 0.0;
    // Alpha 1 per fragment: in a float target it counts the shafts' surfaces crossed.
    o_color = vec4(v_intensity * lit, 1.0);
}
