
// ---- shared by the volume techniques (slicing, froxel; docs/volume-techniques.md) ----------
// Positions are eye-relative (metres). The caustic stack (src/realtime/caustics.c) holds the
// horizontal irradiance per unit E_sun at each depth; between two planes the pattern is
// carried along the flat refracted sun to each plane and blended linearly in depth.
uniform sampler2DArray u_caustics;
uniform int u_n_depths;
uniform float u_cdepth[64];     // plane depths below the rest height (m)
uniform vec2 u_corigin;         // patch corner (x, z) relative to the eye
uniform float u_patch;          // patch side (m)
uniform vec3 u_refr;            // direction sunlight travels under flat water (unit)
uniform float u_rest;           // rest height - eye y (m), > 0
uniform sampler2D u_shadow;     // occluders' depth along u_refr (scenegl)
uniform mat4 u_light_vp;        // eye-relative position -> the shadow map's clip space
uniform int u_use_shadow;
uniform vec3 u_sigma_t;         // extinction (1/m), both paths
uniform vec3 u_sigma_s;         // scattering (1/m)
uniform float u_g;              // HG asymmetry
uniform vec3 u_esun;            // E_sun x gain (W/m^2 per channel)
uniform float u_texel;          // texel side of the sampled (base) level (m)
uniform float u_sun_rw;         // the sun's angular radius in water (rad): 0 = a point sun

const float PI = 3.14159265358979;

float vol_caustic_layer(vec3 p, float depth, int j)
{
    vec3 q = p + u_refr * ((u_cdepth[j] - depth) / -u_refr.y);
    vec3 uv = vec3((q.xz - u_corigin) / u_patch, float(j));
    // The sun's disc blurs the pattern over a diameter 2 d r_w at depth d: the mip level whose
    // texel matches it (a box for the disc; docs, "Sun disc"), or the footprint's if coarser.
    float lod = log2(max(2.0 * u_cdepth[j] * u_sun_rw / u_texel, 1e-6));
#ifdef VOL_FRAGMENT
    lod = max(lod, textureQueryLod(u_caustics, uv.xy).y);
#endif
    return textureLod(u_caustics, uv, max(lod, 0.0)).r;
}

// Horizontal irradiance per unit E_sun at p (eye-relative), depth = u_rest - p.y.
float vol_caustic(vec3 p, float depth)
{
    if (depth <= u_cdepth[0] || u_n_depths == 1) return vol_caustic_layer(p, depth, 0);
    int last = u_n_depths - 1;
    if (depth >= u_cdepth[last]) return vol_caustic_layer(p, depth, last);
    int j = 0;
    while (j < last - 1 && depth > u_cdepth[j + 1]) j++;
    float f = (depth - u_cdepth[j]) / (u_cdepth[j + 1] - u_cdepth[j]);
    return mix(vol_caustic_layer(p, depth, j), vol_caustic_layer(p, depth, j + 1), f);
}

// 1 lit, 0 in an occluder's shadow along the refracted sun (outside the map: lit).
float vol_shadow(vec3 p)
{
    if (u_use_shadow == 0) return 1.0;
    vec4 c = u_light_vp * vec4(p, 1.0);
    vec3 s = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s.xy, vec2(1.0))) || s.z <= 0.0) return 1.0;
    float d = texture(u_shadow, s.xy).r;
    return (d >= 1.0 || s.z <= d + 1e-3) ? 1.0 : 0.0;
}

// Henyey-Greenstein, normalized over the sphere (seed 000 eq. 5.5.4 / 4 pi).
float vol_hg(float cos_t, float g)
{
    float d = 1.0 + g * g - 2.0 * g * cos_t;
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

// In-scattered radiance per metre at p toward the eye (view direction w, away from the eye):
// sigma_s p(T . -w) E_sun C(p) / mu_t exp(-sigma_t depth / mu_t) V(p); 0 above the surface.
// Without the phase (constant along a view ray for the one directional light):
vec3 vol_inscatter_nophase(vec3 p)
{
    float depth = u_rest - p.y;
    if (depth <= 0.0) return vec3(0.0);
    float mu = -u_refr.y;
    float e = vol_caustic(p, depth) / mu;
    return u_sigma_s * u_esun * e * exp(-u_sigma_t * (depth / mu)) * vol_shadow(p);
}
vec3 vol_inscatter(vec3 p, vec3 w) { return vol_inscatter_nophase(p) * vol_hg(dot(u_refr, -w), u_g); }
