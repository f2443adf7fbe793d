#version 330 core
// Seed 000 second pass: full-screen quad (4 vertices, triangle strip, from gl_VertexID).

uniform mat4 u_inv_view_proj; // clip -> viewer-relative world (seed: invViewProjMatrix)
uniform vec2 u_texel;         // 1 / shaft target size (seed: invTexWidth)

out vec4 v_uv[2];             // four bilinear taps (seed: uv[2])
out vec4 v_view;              // homogeneous view vector, divided per pixel

void main()
{
    vec2 p = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
    vec2 uv = p * 0.5 + 0.5;
    // The seed's taps at +0 and +1 texel are centred in D3D9, whose pixel centres sit at
    // integer coordinates (content half a texel toward +u,+v); GL has no such offset, so
    // the same filter is four taps at +-1/2 texel around the pixel (docs: D15).
    v_uv[0].xy = uv + vec2(-0.5, -0.5) * u_texel;
    v_uv[0].zw = uv + vec2(0.5, -0.5) * u_texel;
    v_uv[1].xy = uv + vec2(0.5, 0.5) * u_texel;
    v_uv[1].zw = uv + vec2(-0.5, 0.5) * u_texel;
    // Point on the far plane seen through this pixel, relative to the viewer; the
    // perspective divide (missing in the seed's listing) is done per pixel.
    v_view = u_inv_view_proj * vec4(p, 1.0, 1.0);
}
