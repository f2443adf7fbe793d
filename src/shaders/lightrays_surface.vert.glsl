// Light rays (seed 001, Hu et al. 2010), pass 1: the water surface seen from the sun. One
// vertex of a grid over the light's window (6 per cell), carried along the sun's direction to
// the rest plane, displaced by seed 000 eq. 5.5.7 with the normal from the analytic tangents
// (eq. 5.5.8), projected orthographically along the sun. Positions are eye-relative (m).
uniform int u_cells;          // grid cells per side
uniform float u_half;         // grid half side in the window plane (m)
uniform float u_win;          // the light window's half side (m): clip x, y = +-1
uniform float u_zr;           // depth half range along the sun (m)
uniform vec3 u_c;             // window centre on the rest plane (eye-relative)
uniform vec3 u_e1, u_e2;      // across the sun's direction
uniform vec3 u_sun_dir;       // direction sunlight travels in air (unit, down)
// Compiled after volume_version.glsl and volume_surface.glsl (u_wa: phase = k dir . x_eye_relative + c).
out vec3 v_p;
out vec3 v_n;

void main()
{
    const ivec2 corner[6] = ivec2[6](ivec2(0, 0), ivec2(1, 0), ivec2(1, 1), ivec2(0, 0), ivec2(1, 1), ivec2(0, 1));
    int cell = gl_VertexID / 6, k = gl_VertexID % 6;
    ivec2 ij = ivec2(cell % u_cells, cell / u_cells) + corner[k];
    vec2 uv = (vec2(ij) / float(u_cells) * 2.0 - 1.0) * u_half;
    vec3 q = u_c + u_e1 * uv.x + u_e2 * uv.y;
    vec3 x0 = q + u_sun_dir * ((u_c.y - q.y) / u_sun_dir.y); // along the sun to the rest plane
    vec3 p = x0;
    vec3 tx, tz;
    vol_waves(x0.xz, p, tx, tz);
    v_p = p;
    v_n = cross(tz, tx);
    vec3 r = p - u_c;
    gl_Position = vec4(dot(r, u_e1) / u_win, dot(r, u_e2) / u_win, dot(r, u_sun_dir) / u_zr, 1.0);
}
