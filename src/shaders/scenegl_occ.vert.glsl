#version 330 core
// Occluder triangles for the shared shadow map and eye-depth passes (src/realtime/scenegl.c).
// Positions arrive relative to an origin chosen on the CPU in double (the shadow map's centre,
// or the eye), so float keeps millimetres far from the world origin.

layout(location = 0) in vec3 a_pos; // metres, relative to the pass's origin
uniform mat4 u_mvp;                  // origin-relative position -> clip

out vec3 v_rel;                      // origin-relative position (eye pass: eye -> point)

void main()
{
    v_rel = a_pos;
    gl_Position = u_mvp * vec4(a_pos, 1.0);
}
