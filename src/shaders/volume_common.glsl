
// ---- shared by the volume techniques (slicing, froxel; docs/volume-techniques.md) ----------
// Positions are eye-relative (metres). The caustic stack (src/realtime/caustics.c) holds the
// horizontal irradiance per unit E_sun at each depth; between two planes the pattern is
// carried along the flat refracted sun to each plane and blended linearly in depth.
uniform vec3 u_refr;            // direction sunlight travels under flat water (unit)
uniform float u_rest;           // rest height - eye y (m), > 0
uniform sampler2D u_shadow;     // occluders' depth along u_refr (scenegl)
uniform mat4 u_light_vp;        // eye-relative position -> the shadow map's clip space
uniform int u_use_shadow;
uniform vec3 u_sigma_t;         // extinction (1/m), both paths
uniform vec3 u_sigma_s;         // scattering (1/m)
uniform float u_g;              // HG asymmetry
uniform vec3 u_esun;            // E_sun x gain (W/m^2 per channel)

const float PI = 3.14159265358979;

// Horizontal irradiance per unit E_sun at p (eye-relative), depth = u_rest - p.y: the stack of
// caustic_stack.glsl (compiled before this file), its origin eye-relative.
float vol_caustic(vec3 p, float depth) { return gr_caustic_stack(p, u_refr, depth); }

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

// Henyey-Greenstein, normalized over the sphere (seed 000 eq. 5.5.4 / 4 pi). Its denominator
// 1 + g^2 - 2 g cos written (1 - |g|)^2 + 2 |g| (1 - sign(g) cos), the same number: in float
// the first form cancels to 0 at cos = 1 for g >= 0.9999 (the peak an Inf) and keeps no digit
// near it; the second is >= (1 - |g|)^2 > 0 to full precision (docs/volume-techniques.md,
// "Floating point").
float vol_hg(float cos_t, float g)
{
    float ag = abs(g), c = g < 0.0 ? -cos_t : cos_t;
    float d = (1.0 - ag) * (1.0 - ag) + 2.0 * ag * max(1.0 - c, 0.0);
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

// h exp(e) sinh(x) / x: a slab's weight (the exact integral of the two paths' extinction over
// its length h, x = |kappa h / 2|) times the attenuation exp(e) at its middle, written
// h (exp(e + x) - exp(e - x)) / (2 x): its exponents are those at the slab's two ends (<= 0),
// where sinh(x) alone overflows to Inf past x = 89 (a long slab in murky water) and Inf times
// the middle's exp(e) = 0 makes NaN (docs/volume-techniques.md, "Floating point").
vec3 vol_slab(vec3 e, vec3 x, float h)
{
    vec3 big = h * (exp(e + x) - exp(e - x)) / (2.0 * max(x, vec3(1e-30)));
    vec3 small = h * exp(e) * (vec3(1.0) + x * x / 6.0);
    return mix(big, small, lessThan(x, vec3(1e-3)));
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
// A slab of view ray around p (at view distance tm, length h, x = |kappa h / 2|):
// vol_inscatter(p, w) exp(-sigma_t tm) h sinh(x) / x, the exponentials taken together (vol_slab).
vec3 vol_inscatter_slab(vec3 p, vec3 w, float tm, vec3 x, float h)
{
    float depth = u_rest - p.y;
    if (depth <= 0.0) return vec3(0.0);
    float mu = -u_refr.y;
    float e = vol_caustic(p, depth) / mu * vol_shadow(p) * vol_hg(dot(u_refr, -w), u_g);
    return u_sigma_s * u_esun * e * vol_slab(-u_sigma_t * (depth / mu + tm), x, h);
}
