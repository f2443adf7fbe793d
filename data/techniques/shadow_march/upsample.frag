// shadow_march, pass 2: joint-bilateral upsample of the half-resolution march to the frame.
// The 4 nearest march texels are weighted bilinearly and by how close the ray length each one
// marched (its alpha) is to this pixel's own, so light does not bleed across occluder edges.
out vec4 o_color;

void main()
{
    float t = min(gr_eye_depth(v_uv), u_set_max_distance_m);
    float ts = gr_dist_to_surface(u_eye, gr_view_ray(v_uv));
    if (ts > 0.0) t = min(t, ts);

    ivec2 size = textureSize(t_march, 0);
    vec2 p = v_uv * vec2(size) - 0.5;
    ivec2 i0 = ivec2(floor(p));
    vec2 f = p - vec2(i0);
    vec3 sum = vec3(0.0);
    float wsum = 0.0, best = 1e30;
    vec3 nearest = vec3(0.0);
    for (int k = 0; k < 4; k++) {
        ivec2 o = ivec2(k & 1, k >> 1);
        vec4 s = texelFetch(t_march, clamp(i0 + o, ivec2(0), size - 1), 0);
        float bil = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        float dd = abs(s.a - t);
        float w = bil * exp(-dd / (0.02 * t + 0.05));
        sum += w * s.rgb;
        wsum += w;
        if (dd < best) { best = dd; nearest = s.rgb; }
    }
    o_color = vec4(wsum > 1e-6 ? sum / wsum : nearest, 1.0);
}
