#version 450 core
// Caustic texture (seed 002), vertex stage: one vertex of the water grid over the patch, from
// gl_VertexID (6 per cell, two triangles). Displaced by seed 000 eq. 5.5.7, unit normal from
// the analytic tangents (eq. 5.5.8), the sun refracted (eq. 5.5.1, air 1.0 / water n) and the
// exact Fresnel transmittance (docs/optics.md). Positions are patch-local (metres from the
// patch corner, y from the rest height).
uniform int u_grid;          // cells per side
uniform float u_L;           // patch side (m)
uniform int u_n_waves;
uniform vec4 u_wa[64];       // (dir.x, dir.z, k, c): phase = k dir . x0_local + c
uniform float u_wamp[64];    // amplitude (m)
uniform vec3 u_sun_dir;      // direction sunlight travels in air (unit, down)
uniform float u_ior;
uniform int u_fresnel;
out vec3 v_pos;
out vec3 v_refr;
out float v_ft;

float fresnel_t(float cos_i, float n2)
{
    float s2 = (1.0 / n2) * (1.0 / n2) * max(0.0, 1.0 - cos_i * cos_i);
    if (s2 >= 1.0) return 0.0;
    float cos_t = sqrt(1.0 - s2);
    float rs = (cos_i - n2 * cos_t) / (cos_i + n2 * cos_t);
    float rp = (cos_t - n2 * cos_i) / (cos_t + n2 * cos_i);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

void main()
{
    const ivec2 corner[6] = ivec2[6](ivec2(0, 0), ivec2(1, 0), ivec2(1, 1), ivec2(0, 0), ivec2(1, 1), ivec2(0, 1));
    int cell = gl_VertexID / 6, k = gl_VertexID % 6;
    ivec2 ij = ivec2(cell % u_grid, cell / u_grid) + corner[k];
    float h = u_L / float(u_grid);
    vec2 x0 = vec2(ij) * h;
    vec3 p = vec3(x0.x, 0.0, x0.y);
    vec3 tx = vec3(1.0, 0.0, 0.0), tz = vec3(0.0, 0.0, 1.0);
    for (int i = 0; i < u_n_waves; i++) {
        vec2 d = u_wa[i].xy;
        float kk = u_wa[i].z, a = u_wamp[i];
        float ph = kk * dot(d, x0) + u_wa[i].w;
        float s = sin(ph), c = cos(ph);
        p += vec3(-a * d.x * s, a * c, -a * d.y * s);
        tx += vec3(-a * kk * d.x * d.x * c, -a * kk * d.x * s, -a * kk * d.x * d.y * c);
        tz += vec3(-a * kk * d.x * d.y * c, -a * kk * d.y * s, -a * kk * d.y * d.y * c);
    }
    vec3 n = normalize(cross(tz, tx));
    v_pos = p;
    v_refr = refract(u_sun_dir, n, 1.0 / u_ior);
    v_ft = u_fresnel != 0 ? fresnel_t(clamp(dot(n, -u_sun_dir), 0.0, 1.0), u_ior) : 1.0;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
