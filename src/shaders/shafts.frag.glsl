#version 330 core
// Seed 000 shaft pixel shader: interpolated intensity times an unfiltered shadow test
// (variant seed); the signed length integral of the path and flux variants
// (docs/realtime-shafts.md "Variants").

in vec3 v_intensity;
in vec4 v_shadow_pos;
in vec3 v_world;
in float v_len;
in float v_tr;
in float v_ratio;

uniform sampler2D u_shadow_map; // depth along the refracted sun, [0,1] over [near, far]
uniform float u_shadow_bias;    // depth bias in the same [0,1] units
uniform int u_variant;          // 0 seed, 1 path, 2 flux
uniform float u_prescale;       // factor before blending (divided out in the final pass)
uniform vec3 u_extinction;      // c (1/m)
uniform vec3 u_refr_flat;       // T of the flat surface
uniform int u_depth_test;       // 1: eye depth of occluders / seabed in u_eye_depth
uniform sampler2D u_eye_depth;  // distance (m) from the eye to the first occluder or the seabed
uniform vec2 u_target_size;     // shaft target size (texels)
uniform sampler2D u_flux_e;     // flux: irradiance / E_sun per cell and slab (shafts_flux.frag.glsl)
uniform int u_tiled;            // flux: 1 when the shafts tile the grid (lattice point of cell i is i)
uniform int u_lattice;          // flux: lattice points per side, M
uniform int u_cells;            // flux: N - 1
uniform int u_slabs;            // flux: slabs

// Flux: irradiance of region (rx, rz) of the lattice in slab b; 0 outside the shafts (the
// gaps between shafts when width < 1, above the surface, below the last slab, off the grid).
float flux_e(int rx, int rz, int b)
{
    if (rx < 0 || rz < 0 || rx >= u_lattice - 1 || rz >= u_lattice - 1 || b < 0 || b >= u_slabs) return 0.0;
    if (u_tiled == 0 && ((rx & 1) != 0 || (rz & 1) != 0)) return 0.0;
    ivec2 c = u_tiled != 0 ? ivec2(rx, rz) : ivec2(rx >> 1, rz >> 1);
    return texelFetch(u_flux_e, ivec2(c.x, c.y + b * u_cells), 0).x;
}

// Flux: the weight E_A - E_B of the face this fragment belongs to, A the region its normal
// points away from and B the one it points into (docs "flux": one face per lattice boundary,
// gl_PrimitiveID / 2 numbers the quads: x faces, z faces, then caps).
float flux_weight()
{
    int qd = gl_PrimitiveID >> 1;
    int m = u_lattice, c = u_cells;
    int nx = m * c * u_slabs;
    if (qd < 2 * nx) {
        int zf = qd >= nx ? 1 : 0;
        qd -= zf * nx;
        int b = qd / (m * c), rem = qd - b * (m * c);
        int p = rem / c, j = rem - p * c;
        int rj = u_tiled != 0 ? j : 2 * j;
        if (zf == 0) return flux_e(p - 1, rj, b) - flux_e(p, rj, b);
        return flux_e(rj, p - 1, b) - flux_e(rj, p, b);
    }
    qd -= 2 * nx;
    int b = qd / (c * c), rem = qd - b * (c * c);
    int j = rem / c, i = rem - j * c;
    int ri = u_tiled != 0 ? i : 2 * i, rj = u_tiled != 0 ? j : 2 * j;
    return flux_e(ri, rj, b - 1) - flux_e(ri, rj, b);
}

layout(location = 0) out vec4 o_color;

// (1 - e^-x) / x, stable near 0
vec3 expint1(vec3 x)
{
    vec3 big = (1.0 - exp(-x)) / x;
    vec3 small = 1.0 - x * (0.5 - x * (1.0 / 6.0 - x / 24.0));
    return mix(big, small, lessThan(abs(x), vec3(1e-2)));
}

void main()
{
    float t = length(v_world);
    float t_max = 1e30;
    if (u_depth_test != 0) t_max = texture(u_eye_depth, gl_FragCoord.xy / u_target_size).x;
    if (u_variant == 0) {
        if (t > t_max) discard;
        // Distance to the light source (normalized depth along the refracted sun).
        float z = v_shadow_pos.z / v_shadow_pos.w;
        // Fetch shadowmap (point sampled, as the seed's sampler state).
        float sz = textureProj(u_shadow_map, v_shadow_pos).x;
        // (scenegl's map: depth 1 where no caster is stored, lit at any depth)
        float lit = (sz >= 1.0 || z - u_shadow_bias < sz) ? 1.0 : 0.0;
        // Alpha 1 per fragment: in a float target it counts the shafts' surfaces crossed.
        o_color = vec4(v_intensity * lit * u_prescale, 1.0);
        return;
    }
    // Path / flux: along the view ray w, the light path under water is s(t) = s0 + t w.T_y
    // ... s grows by w.y / T.y per metre, so exp(-c (s + t)) = exp(-c s0) exp(-c k t) with
    // k = 1 + w.y / T.y, whose integral from the eye to t is exp(-c s0) t (1 - e^{-c k t}) / (c k t).
    // Entry faces subtract it, exit faces add it; their sum is the integral over the length
    // of shaft traversed (for c = 0: exit t minus entry t).
    vec3 w = v_world / max(t, 1e-6);
    float dsdt = w.y / u_refr_flat.y;
    float len = v_len;
    if (t > t_max) {            // the ray stops at the occluder / seabed: crossing moved there
        len += (t_max - t) * dsdt;
        t = t_max;
    }
    float k = 1.0 + dsdt;
    vec3 e0 = exp(-u_extinction * (len - dsdt * t)); // exp(-c s0): s0 = light path at t = 0
    float weight = u_variant == 2 ? flux_weight() : v_tr * v_ratio;
    vec3 v = e0 * t * expint1(u_extinction * k * t) * weight;
    float sgn = gl_FrontFacing ? -1.0 : 1.0; // outward winding: front = entry
    o_color = vec4(sgn * v * u_prescale, sgn);
}
