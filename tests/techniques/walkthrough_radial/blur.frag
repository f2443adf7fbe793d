// GPU Gems 3 ch. 13 (Mitchell), the listing's loop as written, with the harness's names:
// screenLightPos -> u_sun_uv, NUM_SAMPLES -> u_set_samples, the constants -> u_set_*.
// Behind the camera the light has no screen position: fade out instead of mirroring.
out vec4 o_color;

void main()
{
    vec2 texCoord = v_uv;
    vec2 deltaTexCoord = (texCoord - u_sun_uv) * (u_set_density / float(u_set_samples));
    vec3 color = texture(t_light, texCoord).rgb;
    float illuminationDecay = 1.0;
    for (int i = 0; i < u_set_samples; i++) {
        texCoord -= deltaTexCoord;
        vec3 s = texture(t_light, texCoord).rgb * (illuminationDecay * u_set_weight);
        color += s;
        illuminationDecay *= u_set_decay;
    }
    float fade = clamp(u_sun_clip_w * 4.0, 0.0, 1.0);
    o_color = vec4(color * u_set_exposure * fade, 1.0);
}
