#version 450 core
// Light rays, pass 2: one point per texel of the light's view (gl_VertexID), its surface
// point and normal handed to the geometry shader.
uniform sampler2D u_pos;
uniform sampler2D u_nrm;
uniform int u_rays;
out vec4 v_pos;
out vec4 v_nrm;
void main()
{
    ivec2 t = ivec2(gl_VertexID % u_rays, gl_VertexID / u_rays);
    v_pos = texelFetch(u_pos, t, 0);
    v_nrm = texelFetch(u_nrm, t, 0);
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
