// Radial blur, light pass (docs/radial-blur.md, "Light pass"): the bright region where the
// refracted sun is seen through the Gerstner surface (seed 000 on NVIDIA's Nalu demo), in
// units of the flat-water peak:
//   s = T(d, N) / T_flat * K(angle(refract(d, -N, n), to_sun)) * exp(-sigma_t t) * V
// d: the pixel's view ray (up), t: its distance to the surface, N: the surface normal there
// (seed eq. 5.5.8 with seed 000's wave packing), T: exact Fresnel transmittance water -> air
// (zero under total internal reflection: outside Snell's window no sun is seen), K: the
// bright-region kernel (1 - (a/a0)^2)^2 around the sun in air, V: 0 where an occluder or the
// seabed is nearer than the surface (occluders drawn black). Alpha: 1 where the ray reaches the
// surface first (it rises, and no occluder or seabed is nearer when u_occluders), else 0: the
// scene colour (realtime/scenecolour.h) lights the other pixels' surfaces.

in vec2 v_ndc;
uniform mat4 u_inv_vp_rot;       // clip -> eye-relative direction
uniform float u_depth;           // rest height - eye y (m), > 0
// Compiled after seed_waves.glsl (#version, u_waves with wt folded to the eye, surface()).
uniform float u_ior;
uniform vec3 u_to_sun;
uniform float u_a0;              // kernel radius (rad)
uniform vec3 u_extinction;       // sigma_t (1/m)
uniform float u_t_flat;          // transmittance of the flat surface along the sun
uniform float u_threshold;
uniform int u_occluders;
uniform sampler2D u_eye_depth;   // metres, R32F at this target's size
uniform int u_dither8;           // +-half an 8-bit step of noise before 8-bit storage
layout(location = 0) out vec4 o_color;

// Interleaved gradient noise (Jimenez 2014): deterministic per pixel, in [0, 1).
float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

// Seed 000's CalculateWaterNormal (seed_waves.glsl's surface(); its y0 is our z) and the
// surface height sum A cos(phase), both at the eye-relative rest point (x0, z0).
void water(float x0, float z0, out vec3 n, out float eta)
{
    vec3 disp;
    surface(vec2(x0, z0), disp, n);
    eta = disp.y;
}

// Exact unpolarized Fresnel reflectance from the side of index n1 (docs/optics.md).
float fresnel(float cos_i, float n1, float n2)
{
    float s2 = (n1 / n2) * (n1 / n2) * max(0.0, 1.0 - cos_i * cos_i);
    if (s2 >= 1.0) return 1.0;
    float cos_t = sqrt(1.0 - s2);
    float rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    float rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
    return 0.5 * (rs * rs + rp * rp);
}

void main()
{
    vec4 q = u_inv_vp_rot * vec4(v_ndc, 1.0, 1.0);
    vec3 d = normalize(q.xyz / q.w);
    vec3 s = vec3(0.0);
    float first = 0.0;
    if (d.y > 1e-4) {
        // Rest plane first, then one correction by the wave height there (the horizontal
        // Gerstner displacement is neglected: docs, "Surface point").
        float t = u_depth / d.y;
        vec3 n;
        float eta;
        water(t * d.x, t * d.z, n, eta);
        t = max(0.0, (u_depth + eta) / d.y);
        water(t * d.x, t * d.z, n, eta);
        first = (u_occluders != 0 && texelFetch(u_eye_depth, ivec2(gl_FragCoord.xy), 0).r < t) ? 0.0 : 1.0;
        float cos_i = dot(d, n);
        vec3 a = cos_i > 0.0 ? refract(d, -n, u_ior) : vec3(0.0);
        if (dot(a, a) > 0.0) {
            float ang = acos(clamp(dot(normalize(a), u_to_sun), -1.0, 1.0));
            float x = ang / u_a0;
            float k = x < 1.0 ? (1.0 - x * x) * (1.0 - x * x) : 0.0;
            float tr = 1.0 - fresnel(cos_i, u_ior, 1.0);
            s = vec3(tr / u_t_flat * k) * exp(-u_extinction * t);
            if (first == 0.0) s = vec3(0.0);
        }
    }
    s = max(s - vec3(u_threshold), vec3(0.0));
    if (u_dither8 != 0) s = max(s + vec3((ign(gl_FragCoord.xy) - 0.5) / 255.0), vec3(0.0));
    o_color = vec4(s, first);
}
