#version 450 core
// Full-screen triangle, one instance per slice (slicing) or one (froxel apply).
out vec2 v_ndc;
flat out int v_slice;
void main()
{
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_ndc = p;
    v_slice = gl_InstanceID;
    gl_Position = vec4(p, 0.0, 1.0);
}
