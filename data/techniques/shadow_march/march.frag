// shadow_march, pass 1: single scattering along each view ray (docs/techniques.md walkthrough).
// L = int_0^D sigma_s p(theta) E_w F(x) V(x) exp(-sigma_t (l(x) + t)) dt   (docs/reference.md eq. 1
// under the flat-water beam irradiance E_w = F_t E_sun cos(theta_i) / cos(theta_t)), with
//   V(x)  the occluder shadow map along the refracted sun,
//   l(x)  the sunlight's path in water to x, (h0 - x.y) / cos(theta_t),
//   F(x)  the wave focusing: 1 / |det J| of the map from surface rest points to the plane at
//         x's depth along the refracted rays (seed eq. 5.5.1 at the Gerstner normal, eq. 5.5.8).
// The harness prelude declares every u_*, u_set_*, t_* used here and gr_* helpers.
#version 450 core
out vec4 o_color;

// Where the refracted sun ray through surface rest point x0 reaches depth d below the rest plane.
vec2 land(vec2 x0, float d)
{
    vec3 t = refract(u_sun_dir, gr_water_normal(x0), 1.0 / u_ior);
    if (t.y > -1e-3) t = u_refr_dir; // grazing or totally reflected: keep the flat direction
    return x0 + t.xz * (d / -t.y);
}

float focus(vec3 x)
{
    float d = u_rest_height - x.y;
    if (u_set_caustics <= 0.0 || d <= 0.0) return 1.0;
    // entry point under flat water, then one fixed-point step toward the wavy ray landing at x
    vec2 x0 = x.xz - u_refr_dir.xz * (d / -u_refr_dir.y);
    x0 += x.xz - land(x0, d);
    const float e = 0.05; // m, central differences
    vec2 jx = (land(x0 + vec2(e, 0.0), d) - land(x0 - vec2(e, 0.0), d)) / (2.0 * e);
    vec2 jz = (land(x0 + vec2(0.0, e), d) - land(x0 - vec2(0.0, e), d)) / (2.0 * e);
    float det = abs(jx.x * jz.y - jx.y * jz.x);
    float f = min(1.0 / max(det, 1e-4), u_set_focus_max);
    return mix(1.0, f, u_set_caustics);
}

// Jimenez's interleaved gradient noise: a per-pixel offset in [0, 1)
float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main()
{
    vec3 dir = gr_view_ray(v_uv);
    float t_end = min(gr_eye_depth(v_uv), u_set_max_distance_m);
    float ts = gr_dist_to_surface(u_eye, dir);
    if (ts > 0.0) t_end = min(t_end, ts);

    vec3 sig_t = u_extinction * u_set_extinction_scale;
    float cos_i = u_to_sun.y, cos_t = -u_refr_dir.y;
    vec3 e_w = u_sun_irradiance * (u_transmittance_flat * cos_i / cos_t);
    float phase = gr_hg(dot(dir, u_to_refr_sun), u_g);

    float dt = t_end / float(u_set_steps);
    float j = u_set_jitter ? ign(gl_FragCoord.xy) : 0.5;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < u_set_steps; i++) {
        float t = (float(i) + j) * dt;
        vec3 x = u_eye + dir * t;
        float l = (u_rest_height - x.y) / cos_t;
        if (l < 0.0) continue;
        float vis = gr_shadow(x, 1e-3);
        if (vis == 0.0) continue;
        sum += exp(-sig_t * (l + t)) * focus(x);
    }
    vec3 radiance = sum * dt * u_scattering * phase * e_w * u_set_intensity;
    o_color = vec4(radiance, t_end); // alpha: the ray's length, for the depth-aware upsample
}
