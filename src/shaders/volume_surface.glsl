// The water surface for the volume techniques' vertex and geometry stages (caustics.vert.glsl,
// lightrays_surface.vert.glsl, lightrays.geom.glsl), compiled after volume_version.glsl: the
// waves as gr_vol_waves packs them (src/realtime/caustics.h) and the exact Fresnel transmittance.
uniform int u_n_waves;
uniform vec4 u_wa[64];        // (dir.x, dir.z, k, c): phase = k dir . x0 + c (x0 in the caller's frame)
uniform float u_wamp[64];     // amplitude (m)

// Seed 000 eq. 5.5.7 at the rest point x0: p (x0 on entry) displaced, and the analytic
// tangents along x and z (eq. 5.5.8); the normal is normalize(cross(tz, tx)).
void vol_waves(vec2 x0, inout vec3 p, out vec3 tx, out vec3 tz)
{
    tx = vec3(1.0, 0.0, 0.0);
    tz = vec3(0.0, 0.0, 1.0);
    for (int i = 0; i < u_n_waves; i++) {
        vec2 d = u_wa[i].xy;
        float kk = u_wa[i].z, a = u_wamp[i];
        float ph = kk * dot(d, x0) + u_wa[i].w;
        float s = sin(ph), c = cos(ph);
        p += vec3(-a * d.x * s, a * c, -a * d.y * s);
        tx += vec3(-a * kk * d.x * d.x * c, -a * kk * d.x * s, -a * kk * d.x * d.y * c);
        tz += vec3(-a * kk * d.x * d.y * c, -a * kk * d.y * s, -a * kk * d.y * d.y * c);
    }
}

// Exact unpolarized Fresnel transmittance from air into water of index n2 (docs/optics.md).
float fresnel_t(float cos_i, float n2)
{
    float s2 = (1.0 / n2) * (1.0 / n2) * max(0.0, 1.0 - cos_i * cos_i);
    if (s2 >= 1.0) return 0.0;
    float cos_t = sqrt(1.0 - s2);
    float rs = (cos_i - n2 * cos_t) / (cos_i + n2 * cos_t);
    float rp = (cos_t - n2 * cos_i) / (cos_t + n2 * cos_i);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}
