// Caustic texture (seed 002), vertex stage: one vertex of the water grid over the patch, from
// gl_VertexID = the grid vertex i + j (grid + 1) (an indexed draw: 6 indices per cell, two
// triangles, so the post-transform cache shades a shared vertex once instead of six times). Displaced by seed 000 eq. 5.5.7, unit normal from
// the analytic tangents (eq. 5.5.8), the sun refracted (eq. 5.5.1, air 1.0 / water n) and the
// exact Fresnel transmittance (docs/optics.md). Positions are patch-local (metres from the
// patch corner, y from the rest height).
uniform int u_grid;          // cells per side
uniform float u_L;           // patch side (m)
// Compiled after volume_version.glsl and volume_surface.glsl (u_wa: phase = k dir . x0_local + c).
uniform vec3 u_sun_dir;      // direction sunlight travels in air (unit, down)
uniform float u_ior;
uniform int u_fresnel;
out vec3 v_pos;
out vec3 v_refr;
out float v_ft;

void main()
{
    ivec2 ij = ivec2(gl_VertexID % (u_grid + 1), gl_VertexID / (u_grid + 1));
    float h = u_L / float(u_grid);
    vec2 x0 = vec2(ij) * h;
    vec3 p = vec3(x0.x, 0.0, x0.y);
    vec3 tx, tz;
    vol_waves(x0, p, tx, tz);
    vec3 n = normalize(cross(tz, tx));
    v_pos = p;
    v_refr = refract(u_sun_dir, n, 1.0 / u_ior);
    v_ft = u_fresnel != 0 ? fresnel_t(clamp(dot(n, -u_sun_dir), 0.0, 1.0), u_ior) : 1.0;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
