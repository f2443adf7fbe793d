
// Froxel fog, pass 1 (docs/volume-techniques.md, "Froxels"): the in-scattering at the centre
// (or a jittered depth) of each froxel of the view-frustum grid: sigma_s x HG phase x the
// refracted sun's irradiance with the caustic texture as its cookie at the froxel's depth,
// the extinction along the sun's path and the occluders' shadow map.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly image3D u_scatter;
uniform ivec3 u_grid;
uniform float u_bounds[257];     // view-depth boundaries of the depth slices
uniform mat4 u_inv_vp_rot;
uniform vec3 u_forward;
uniform int u_jitter;
uniform int u_phase_pixel;       // 1: the phase is applied per pixel (pass 3), not here

float ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(id, u_grid))) return;
    vec2 ndc = (vec2(id.xy) + 0.5) / vec2(u_grid.xy) * 2.0 - 1.0;
    vec4 c = u_inv_vp_rot * vec4(ndc, 1.0, 1.0);
    vec3 w = normalize(c.xyz / c.w);
    float zf = dot(w, u_forward);
    float j = u_jitter != 0 ? ign(vec2(id.xy) + 5.588238 * float(id.z)) : 0.5;
    // A froxel the water surface cuts (flat rest plane) is sampled in its water part: pass 3
    // reads the slice up to the ray's end, so S stands for that part (docs, "Froxels").
    float zb = u_bounds[id.z + 1];
    if (w.y > 0.0) zb = clamp(u_rest / w.y * zf, u_bounds[id.z], zb);
    float z = mix(u_bounds[id.z], zb, j);
    vec3 p = w * (z / zf);
    imageStore(u_scatter, id, vec4(u_phase_pixel != 0 ? vol_inscatter_nophase(p) : vol_inscatter(p, w), 0.0));
}
