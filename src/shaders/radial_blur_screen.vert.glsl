#version 330 core
// Full-screen triangle (3 vertices from gl_VertexID) for the radial blur's light, blur and
// resolve passes; v_ndc is the fragment's normalized device position.
out vec2 v_ndc;
void main()
{
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_ndc = p;
    gl_Position = vec4(p, 0.0, 1.0);
}
