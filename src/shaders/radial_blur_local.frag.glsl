#version 330 core
// Seed 003: the radial blur toward this quad's light, faded to the quad's edge by
// f = (1 - r)^falloff (r = distance from the light in half-sizes; 1 linear, 2 quadratic).
// Output (f c, f), added over all quads; the resolve pass divides by max(1, sum f).
in vec2 v_corner;
flat in vec2 v_light_uv;
uniform sampler2D u_light;
uniform vec2 u_size;
uniform int u_samples;
uniform float u_density, u_decay, u_weight, u_falloff;
uniform int u_dither;
layout(location = 0) out vec4 o_color;

float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main()
{
    float r = length(v_corner);
    if (r >= 1.0) discard;
    float f = pow(1.0 - r, u_falloff);
    vec2 uv = gl_FragCoord.xy / u_size;
    vec2 delta = (uv - v_light_uv) * (u_density / float(u_samples));
    float j = u_dither != 0 ? ign(gl_FragCoord.xy) - 0.5 : 0.0;
    vec3 c = texture(u_light, uv).rgb;
    float w = u_weight;
    for (int i = 1; i <= u_samples; i++) {
        c += texture(u_light, uv - (float(i) + j) * delta).rgb * w;
        w *= u_decay;
    }
    o_color = vec4(c * f, f);
}
