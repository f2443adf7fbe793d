
// Slicing (seed 002 as seed 000 describes it): slice i is the plane slab of view depth
// [u_bounds[i], u_bounds[i+1]]; each pixel adds the in-scattering at the middle of its ray's
// part inside the slab (clipped to the ray's end), times the slab weight: the exact integral of
// the two paths' extinction across the slab, 2 sinh(kappa h / 2) / kappa with
// kappa = sigma_t (1 - w_y / mu_t) (docs/volume-techniques.md, "Slice weights").
in vec2 v_ndc;
flat in int v_slice;
uniform mat4 u_inv_vp_rot;      // clip -> eye-relative direction
uniform vec3 u_forward;
uniform float u_bounds[513];
uniform sampler2D u_eye_depth;  // metres to the first occluder / seabed
uniform vec2 u_size;
uniform float u_tmax;
layout(location = 0) out vec4 o_color;

void main()
{
    vec4 c = u_inv_vp_rot * vec4(v_ndc, 1.0, 1.0);
    vec3 w = normalize(c.xyz / c.w);
    float zf = dot(w, u_forward);
    float a = u_bounds[v_slice] / zf, b = u_bounds[v_slice + 1] / zf;
    float tend = min(texture(u_eye_depth, gl_FragCoord.xy / u_size).r, u_tmax);
    if (w.y > 0.0) tend = min(tend, u_rest / w.y);
    b = min(b, tend);
    if (!(b > a)) discard;
    float h = b - a, tm = 0.5 * (a + b);
    vec3 p = w * tm;
    vec3 kappa = u_sigma_t * (1.0 - w.y / -u_refr.y);
    vec3 x = abs(0.5 * kappa * h); // sinh(x) / x is even
    vec3 L = vol_inscatter_slab(p, w, tm, x, h);
    o_color = vec4(L, 1.0);
}
