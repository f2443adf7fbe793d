
// ---- the caustic irradiance stack (src/realtime/caustics.h; docs/volume-techniques.md) ----
// One GLSL source for every reader: the volume techniques (volume_common.glsl) and the user
// techniques' "caustics" input (src/realtime/usertech.c pastes this file into the prelude).
// Layer j of t_caustics holds the horizontal irradiance per unit E_sun, without extinction, on
// the plane u_caustic_depth[j] below the rest height (flat water: cos(theta_i) F_t). Positions
// are in the caller's frame (eye-relative for the volume techniques, world for user shaders);
// u_caustic_origin is the patch corner (x, z) in that frame. Set by gr_vol_caustic_set.
uniform sampler2DArray t_caustics;
uniform int u_caustic_layers;
uniform float u_caustic_depth[64];  // plane depths below the rest height (m), increasing
uniform vec2 u_caustic_origin;      // patch corner (x, z) in the caller's frame (m)
uniform float u_caustic_patch;      // patch side (m): the texture repeats with this period
uniform float u_caustic_texel;      // texel side of the sampled (base) level (m)
uniform float u_caustic_sun_rw;     // the sun's angular radius in water (rad): 0 = a point sun

// Layer j at the point where the flat refracted sun `refr` through p (depth below the rest
// height) crosses that layer's plane.
float gr_caustic_layer(vec3 p, vec3 refr, float depth, int j)
{
    vec3 q = p + refr * ((u_caustic_depth[j] - depth) / -refr.y);
    vec3 uv = vec3((q.xz - u_caustic_origin) / u_caustic_patch, float(j));
    // The sun's disc blurs the pattern over a diameter 2 d r_w at depth d: the mip level whose
    // texel matches it (a box for the disc; docs, "Sun disc"), or the footprint's if coarser.
    float lod = log2(max(2.0 * u_caustic_depth[j] * u_caustic_sun_rw / u_caustic_texel, 1e-6));
#ifdef GR_FRAGMENT_STAGE
    lod = max(lod, textureQueryLod(t_caustics, uv.xy).y);
#endif
    return textureLod(t_caustics, uv, max(lod, 0.0)).r;
}

// Horizontal irradiance per unit E_sun at p, depth = rest height - p.y: the two planes around
// the depth, each read where the flat refracted sun carries p to it, blended linearly in
// depth; above the first plane the first, below the last the last (carried the same way).
float gr_caustic_stack(vec3 p, vec3 refr, float depth)
{
    if (depth <= u_caustic_depth[0] || u_caustic_layers == 1) return gr_caustic_layer(p, refr, depth, 0);
    int last = u_caustic_layers - 1;
    if (depth >= u_caustic_depth[last]) return gr_caustic_layer(p, refr, depth, last);
    int j = 0;
    while (j < last - 1 && depth > u_caustic_depth[j + 1]) j++;
    float f = (depth - u_caustic_depth[j]) / (u_caustic_depth[j + 1] - u_caustic_depth[j]);
    return mix(gr_caustic_layer(p, refr, depth, j), gr_caustic_layer(p, refr, depth, j + 1), f);
}
