out vec4 o_color;

// seed 000's CalculateWaterNormal, ported line by line on the packed u_waves
vec3 seed_normal(float x0, float y0)
{
    vec3 t1 = vec3(1.0, 0.0, 0.0);
    vec3 t2 = vec3(0.0, 0.0, 1.0);
    for (int i = 0, j = 0; i < u_wave_groups; i++, j += 5) {
        vec4 kx = u_waves[j];
        vec4 ky = u_waves[j + 1];
        vec4 Ainvk = u_waves[j + 2];
        vec4 A = u_waves[j + 3];
        vec4 wt = u_waves[j + 4];
        vec4 phase = kx * x0 + ky * y0 - wt;
        vec4 sinp = sin(phase), cosp = cos(phase);
        t1.x -= dot(Ainvk, kx * cosp * kx);
        t1.z -= dot(Ainvk, ky * cosp * kx);
        t1.y += dot(A, (-sinp) * kx);
        t2.x -= dot(Ainvk, kx * cosp * ky);
        t2.z -= dot(Ainvk, ky * cosp * ky);
        t2.y += dot(A, (-sinp) * ky);
    }
    return normalize(cross(t2, t1));
}

void main()
{
    vec2 xz = (v_uv - 0.5) * u_set_extent_m;
    vec3 v;
    if (u_set_mode == 0) v = gr_view_ray(v_uv);
    else if (u_set_mode == 1) v = gr_water_normal(xz);
    else if (u_set_mode == 2) v = seed_normal(xz.x, xz.y);
    else if (u_set_mode == 3) v = vec3(u_set_a, float(u_set_n), u_set_flag ? 1.0 : -1.0);
    else v = u_set_tint;
    o_color = vec4(v, 1.0);
}
