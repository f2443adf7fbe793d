#version 330 core
// Radial blur pass (GPU Gems 3 ch. 13; seed 004's listing): per pixel, the light pass at
// uv plus N taps marching toward the refracted sun's screen position,
//   c = L(uv) + weight * sum_{i=1..N} decay^(i-1) L(uv - i delta),
//   delta = (uv - sun_uv) density / N,
// times u_scale = exposure * sample_scale * intensity * peak * fade (set on the CPU).
// Dither: the march is shifted by (j - 1/2) delta, j the pixel's interleaved-gradient noise,
// which turns the tap pattern's bands into noise (docs/radial-blur.md, "Banding").
uniform sampler2D u_light;   // light pass, bilinear, black border
uniform vec2 u_sun_uv;
uniform vec2 u_size;         // output size (pixels)
uniform int u_samples;
uniform float u_density, u_decay, u_weight;
uniform vec3 u_scale;
uniform int u_dither;
layout(location = 0) out vec4 o_color;

float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main()
{
    vec2 uv = gl_FragCoord.xy / u_size;
    vec2 delta = (uv - u_sun_uv) * (u_density / float(u_samples));
    float j = u_dither != 0 ? ign(gl_FragCoord.xy) - 0.5 : 0.0;
    vec3 c = texture(u_light, uv).rgb;
    float w = u_weight;
    for (int i = 1; i <= u_samples; i++) {
        c += texture(u_light, uv - (float(i) + j) * delta).rgb * w;
        w *= u_decay;
    }
    o_color = vec4(c * u_scale, 1.0);
}
