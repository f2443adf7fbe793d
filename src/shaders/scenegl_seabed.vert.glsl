#version 330 core
// Full-screen triangle for the seabed's analytic eye distance (src/realtime/scenegl.c).
uniform mat4 u_inv_vp_rot; // clip -> eye-relative direction (view-projection without translation)
out vec3 v_dir;            // eye-relative point on the far plane, interpolated linearly
void main()
{
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
    vec4 q = u_inv_vp_rot * vec4(p, 1.0, 1.0);
    v_dir = q.xyz / q.w;
}
