// Flux variant pre-pass (docs/realtime-shafts.md "flux"): one texel per point of the shaft
// lattice (M x M): with shaft_width < 1 point 2 i + c is cell i's corner c in {0, 1} (M =
// 2 (N - 1)); with width 1 the shafts tile the grid and point p is the grid line p (M = N).
// Each texel holds the point on the Gerstner surface (eq. 5.5.7, viewer-relative), its Fresnel
// transmittance (eq. 5.5.2b) and its refracted sun direction (eq. 5.5.1), evaluated once
// instead of in every vertex of the lattice.

// Compiled after seed_waves.glsl (#version, the waves' uniforms, surface()).

uniform vec3 u_origin;        // P - viewer (m)
uniform float u_spacing;      // S (m)
uniform float u_width;        // shaft width as a fraction of the cell
uniform float u_half;         // (N - 1) / 2
uniform int u_tiled;          // 1: shaft_width 1, lattice = grid lines
uniform vec3 u_sun_dir;       // I
uniform float u_eta;          // 1 / ior
uniform float u_r0;           // Schlick R0

layout(location = 0) out vec4 o_pos_tr; // corner position (viewer-relative), transmittance
layout(location = 1) out vec4 o_refr;   // refracted direction

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 rest;
    if (u_tiled != 0) {
        rest = (vec2(p) - u_half) * u_spacing;
    } else {
        vec2 cell = vec2(p / 2) + 0.5 - u_half;
        vec2 corner = vec2((p.x & 1) != 0 ? 0.5 : -0.5, (p.y & 1) != 0 ? 0.5 : -0.5);
        rest = (cell + corner * u_width) * u_spacing;
    }
    vec3 disp, n;
    surface(rest, disp, n);
    float m = 1.0 - clamp(dot(-u_sun_dir, n), 0.0, 1.0);
    float m2 = m * m;
    float tr = 1.0 - (u_r0 + (1.0 - u_r0) * (m2 * m2 * m));
    vec3 q = u_origin + vec3(rest.x, 0.0, rest.y) + disp;
    vec3 rd = refract(u_sun_dir, n, u_eta);
    o_pos_tr = vec4(q, tr);
    o_refr = vec4(rd, 0.0);
}
