// GPU Gems 3 ch. 13 / seed 004 over the harness's light texture t_sun_light, as radial_blur's
// blur pass (src/shaders/radial_blur.frag.glsl), scaled to the truth's units by u_sun_light_units.
out vec4 o_color;

float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

// radial_blur's fade: 1 on screen, smoothstep to 0 over fade_margin beyond it, 0 behind
float fade()
{
    if (!(u_sun_clip_w > 0.0)) return 0.0;
    float e = max(abs(u_sun_ndc.x), abs(u_sun_ndc.y));
    if (!(e > 1.0)) return 1.0;
    if (!(u_set_fade_margin > 0.0)) return 0.0;
    float x = (e - 1.0) / u_set_fade_margin;
    return x >= 1.0 ? 0.0 : 1.0 - x * x * (3.0 - 2.0 * x);
}

void main()
{
    vec2 uv = gl_FragCoord.xy / u_resolution;
    vec2 delta = (uv - u_sun_uv) * (u_set_density / float(u_set_samples));
    float j = u_set_dither ? ign(gl_FragCoord.xy) - 0.5 : 0.0;
    vec3 c = texture(t_sun_light, uv).rgb;
    float w = u_set_weight;
    for (int i = 1; i <= u_set_samples; i++) {
        c += texture(t_sun_light, uv - (float(i) + j) * delta).rgb * w;
        w *= u_set_decay;
    }
    o_color = vec4(c * (u_sun_light_units * u_set_intensity * fade()), 1.0);
}
