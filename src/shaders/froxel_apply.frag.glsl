
// Froxel fog, pass 3: each pixel reads the integrated volume at its ray's end (the first
// occluder / seabed, the water surface, the reference's cutoff): the accumulated radiance
// at the enclosing froxel's back face, interpolated linearly in depth from the front face
// (0 before the first froxel), bilinearly across the grid.
in vec2 v_ndc;
uniform mat4 u_inv_vp_rot;
uniform vec3 u_forward;
uniform float u_bounds[257];
uniform int u_nz;
uniform sampler3D u_integrated;
uniform sampler2D u_eye_depth;
uniform vec2 u_size;
uniform float u_tmax;
uniform int u_phase_pixel;
layout(location = 0) out vec4 o_color;

void main()
{
    vec4 c = u_inv_vp_rot * vec4(v_ndc, 1.0, 1.0);
    vec3 w = normalize(c.xyz / c.w);
    float zf = dot(w, u_forward);
    vec2 uv = gl_FragCoord.xy / u_size;
    float tend = min(texture(u_eye_depth, uv).r, u_tmax);
    if (w.y > 0.0) tend = min(tend, u_rest / w.y);
    float zend = tend * zf;
    int k = 0;
    while (k < u_nz - 1 && zend > u_bounds[k + 1]) k++;
    float f = clamp((zend - u_bounds[k]) / (u_bounds[k + 1] - u_bounds[k]), 0.0, 1.0);
    vec3 back = texture(u_integrated, vec3(uv, (float(k) + 0.5) / float(u_nz))).rgb;
    vec3 front = k > 0 ? texture(u_integrated, vec3(uv, (float(k) - 0.5) / float(u_nz))).rgb : vec3(0.0);
    float ph = u_phase_pixel != 0 ? vol_hg(dot(u_refr, -w), u_g) : 1.0;
    o_color = vec4(mix(front, back, f) * ph, 1.0);
}
