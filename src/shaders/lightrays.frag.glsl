
// Light rays, pass 2, fragment stage (docs/volume-techniques.md, "Light rays"). Nothing behind
// the eye's first occluder / the seabed, above the surface or past the reference's cutoff.
//   prism: the pixel's ray x = w t crosses the line's prism (slabs |(x - p0) . m_i| <= 1/2,
//     y between the line's ends) over [t0, t1]; with E_beam = E_sun F_t |I.y| / |T.y| and the
//     sun's path s = (p0.y - y) / mu (mu = -T.y) the radiance is
//       sigma_s p(T . -w) E_beam exp(-sigma_t p0.y / mu) int_t0^t1 exp(-kappa t) dt,
//       kappa = sigma_t (1 - w.y / mu)   (the slicing's slab weight, exact);
//   ribbon: a sheet of width w carrying the flux Phi = E_sun F_t A_perp adds where the ray
//     crosses it sigma_s p(T . -w) Phi exp(-sigma_t (s + r)) r / (w D), D / r = |w . n| the
//     sheet's obliquity.
in vec3 g_p;
in float g_w;
flat in vec3 g_p0;
flat in vec3 g_t;
flat in float g_flux;
flat in float g_d;
flat in vec3 g_m1, g_m2;
flat in float g_ybot;
uniform sampler2D u_eye_depth; // metres to the first occluder / seabed
uniform vec2 u_size;
uniform float u_tmax;
uniform int u_footprint;
uniform mat4 u_inv_vp_rot;     // clip -> eye-relative direction
layout(location = 0) out vec4 o_color;

void slab(float dv, float a0, float lo, float hi, inout float t0, inout float t1)
{
    if (abs(dv) < 1e-12) {
        if (a0 < lo || a0 > hi) t1 = -1.0;
        return;
    }
    float ta = (lo - a0) / dv, tb = (hi - a0) / dv;
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
}

void main()
{
    float tend = min(texture(u_eye_depth, gl_FragCoord.xy / u_size).r, u_tmax);
    if (u_footprint == 0) {
        vec2 ndc = gl_FragCoord.xy / u_size * 2.0 - 1.0;
        vec4 c = u_inv_vp_rot * vec4(ndc, 1.0, 1.0);
        vec3 w = normalize(c.xyz / c.w);
        if (w.y > 0.0) tend = min(tend, u_rest / w.y);
        float t0 = 0.0, t1 = tend;
        slab(dot(w, g_m1), -dot(g_p0, g_m1), -0.5, 0.5, t0, t1);
        slab(dot(w, g_m2), -dot(g_p0, g_m2), -0.5, 0.5, t0, t1);
        slab(w.y, 0.0, g_ybot, g_p0.y, t0, t1);
        if (!(t1 > t0)) discard;
        float mu = -g_t.y, h = t1 - t0, tm = 0.5 * (t0 + t1);
        vec3 kappa = u_sigma_t * (1.0 - w.y / mu);
        vec3 x = abs(0.5 * kappa * h); // sinh(x) / x is even
        vec3 L = u_sigma_s * u_esun * (g_flux * vol_hg(dot(g_t, -w), u_g)) * vol_slab(-u_sigma_t * (g_p0.y / mu) - kappa * tm, x, h);
        o_color = vec4(L, 1.0);
        return;
    }
    float r = length(g_p);
    if (!(r < tend) || !(r > 0.0)) discard;
    vec3 w = g_p / r;
    float s = max(dot(g_p - g_p0, g_t), 0.0);
    vec3 L = u_sigma_s * u_esun * (g_flux * vol_hg(dot(g_t, -w), u_g) * r / (g_w * g_d)) * exp(-u_sigma_t * (s + r));
    o_color = vec4(L, 1.0);
}
