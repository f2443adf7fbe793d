#version 330 core
// Seed 000 second pass: blur the shaft intensities with 4 bilinear taps, times the
// un-normalized Henyey-Greenstein phase (eq. 5.5.4 with beta_M = 1), plus the bias.

in vec4 v_uv[2];
in vec4 v_view;

uniform sampler2D u_shafts;   // seed: godraysSam (bilinear, clamp)
uniform vec3 u_hgg;           // (1 - g^2, 1 + g^2, 2 g): seed HGg
uniform vec3 u_refr_sun;      // refracted sun direction T (eq. 5.5.5b): seed refrSunDir
uniform vec3 u_intensity;     // user factor: seed intensity
uniform float u_bias;         // seed: 0.15

layout(location = 0) out vec4 o_color;

// Mie phase function (seed ComputeMie): HGg.x / (HGg.y - HGg.z cos)^(3/2).
float compute_mie(vec3 view_dir, vec3 sun_dir)
{
    float den = u_hgg.y - u_hgg.z * dot(sun_dir, view_dir);
    den = inversesqrt(den);
    return u_hgg.x * (den * den * den);
}

void main()
{
    vec4 shafts = vec4(0.0);
    for (int i = 0; i < 2; i++) {
        shafts += texture(u_shafts, v_uv[i].xy);
        shafts += texture(u_shafts, v_uv[i].zw);
    }
    shafts /= 4.0;

    vec3 view_vector = normalize(v_view.xyz / v_view.w);
    float phase = compute_mie(-view_vector, u_refr_sun);

    // Final colour with the seed's small bias to hide aliasing.
    vec3 color = (u_bias + u_intensity * shafts.xyz) * phase;
    o_color = vec4(color, 1.0);
}
