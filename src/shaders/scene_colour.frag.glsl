// Scene colour, the lit surfaces (src/realtime/scenecolour.h; docs/techniques.md "Harness
// textures", docs/volume-techniques.md "Scene colour"): where the view ray meets the seabed or
// an occluder before the water surface, a Lambertian surface of albedo u_albedo lit by the
// refracted sun through the caustic stack,
//   E = E_sun C(p) / mu_t max(N . l, 0) exp(-sigma_t d(p) / mu_t) V(p)        (docs eq. SC1)
//   L = albedo / pi E exp(-sigma_t t)                                           (docs eq. SC2)
// written as L / u_unit (the radiance of 1, the light pass's normalization). Blended as
// (ONE_MINUS_DST_ALPHA, ONE) over the light pass, whose alpha is 1 where the surface is seen
// first: those pixels keep the light pass's value exactly. Compiled after volume_version.glsl,
// volume_fragment.glsl, caustic_stack.glsl and volume_common.glsl (positions eye-relative).
in vec2 v_ndc;
uniform mat4 u_inv_vp_rot;      // clip -> eye-relative direction
uniform sampler2D u_eye_depth;  // metres along the ray, R32F at this target's size
uniform vec2 u_size;            // this target's size (px)
uniform float u_far;            // eye depth where nothing is hit
uniform float u_seabed;         // seabed y - eye y (m); -1e30 without a seabed
uniform vec3 u_albedo;
uniform vec3 u_inv_unit;        // 1 / the radiance of 1 (per channel; 0 where E_sun is 0)
uniform float u_normal_offset;  // m: the shadow map is read this far off the surface along N
layout(location = 0) out vec4 o_color;

vec3 view_dir(vec2 ndc)
{
    vec4 q = u_inv_vp_rot * vec4(ndc, 1.0, 1.0);
    return normalize(q.xyz / q.w);
}

// The eye-relative point seen through pixel px + o (o one pixel step), and whether it is a surface.
bool point_at(ivec2 px, ivec2 o, out vec3 p, out float t)
{
    ivec2 q = clamp(px + o, ivec2(0), ivec2(u_size) - 1);
    t = texelFetch(u_eye_depth, q, 0).r;
    p = view_dir(v_ndc + 2.0 * vec2(q - px) / u_size) * t;
    return t < u_far && q != px;
}

// Normal of an occluder from the eye depth: the cross product of the position's differences to
// the neighbours in x and y, each on the side whose depth is closer to this pixel's (not across
// a silhouette); facing the eye. With no usable neighbour: toward the eye.
vec3 depth_normal(ivec2 px, vec3 p, float t, vec3 w)
{
    vec3 pa, pb, dx = vec3(0.0), dy = vec3(0.0);
    float ta, tb;
    bool a = point_at(px, ivec2(1, 0), pa, ta), b = point_at(px, ivec2(-1, 0), pb, tb);
    if (a && (!b || abs(ta - t) <= abs(tb - t))) dx = pa - p;
    else if (b) dx = p - pb;
    a = point_at(px, ivec2(0, 1), pa, ta);
    b = point_at(px, ivec2(0, -1), pb, tb);
    if (a && (!b || abs(ta - t) <= abs(tb - t))) dy = pa - p;
    else if (b) dy = p - pb;
    vec3 n = cross(dx, dy);
    if (!(dot(n, n) > 0.0)) return -w;
    n = normalize(n);
    return dot(n, w) > 0.0 ? -n : n;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float t = texelFetch(u_eye_depth, px, 0).r;
    if (!(t < u_far)) {
        o_color = vec4(0.0); // nothing hit: no surface to light (the water beyond is dark)
        return;
    }
    vec3 w = view_dir(v_ndc);
    vec3 p = w * t;
    // the seabed plane (N = +y) where the depth is its distance along the ray, else an occluder
    float ts = w.y < 0.0 ? u_seabed / w.y : -1.0;
    vec3 n = abs(t - ts) <= 1e-4 * ts + 1e-4 ? vec3(0.0, 1.0, 0.0) : depth_normal(px, p, t, w);
    float mu = -u_refr.y;
    float d = max(u_rest - p.y, 0.0);
    float cosl = max(dot(n, -u_refr), 0.0);
    // the shadow map read off the surface along its normal (no self-shadowing acne)
    float v = vol_shadow(p + u_normal_offset * n);
    vec3 e = u_esun * (vol_caustic(p, d) / mu * cosl) * exp(-u_sigma_t * (d / mu)) * v; // SC1
    vec3 L = u_albedo / PI * e * exp(-u_sigma_t * t); // SC2
    o_color = vec4(L * u_inv_unit, 0.0);
}
