#version 450 core
// Froxel fog, pass 2: Hillaire's energy-conserving front-to-back integration (Hillaire 2015,
// "Physically based and unified volumetric rendering in Frostbite"): per froxel of length dt
// with constant in-scattering S and extinction sigma_t,
//   L += T S (1 - exp(-sigma_t dt)) / sigma_t,   T *= exp(-sigma_t dt),
// storing L at the back face of each froxel.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform readonly image3D u_scatter;
layout(rgba32f, binding = 1) uniform writeonly image3D u_integrated;
uniform ivec3 u_grid;
uniform float u_bounds[257];
uniform mat4 u_inv_vp_rot;
uniform vec3 u_forward;
uniform vec3 u_sigma_t;

void main()
{
    ivec2 id = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(id, u_grid.xy))) return;
    vec2 ndc = (vec2(id) + 0.5) / vec2(u_grid.xy) * 2.0 - 1.0;
    vec4 c = u_inv_vp_rot * vec4(ndc, 1.0, 1.0);
    vec3 w = normalize(c.xyz / c.w);
    float zf = dot(w, u_forward);
    vec3 L = vec3(0.0), T = vec3(1.0);
    for (int z = 0; z < u_grid.z; z++) {
        float dt = (u_bounds[z + 1] - u_bounds[z]) / zf;
        vec3 S = imageLoad(u_scatter, ivec3(id, z)).rgb;
        vec3 tr = exp(-u_sigma_t * dt);
        // (1 - exp(-s dt)) / s, with its limit dt for s -> 0
        vec3 k = mix((1.0 - tr) / max(u_sigma_t, vec3(1e-30)), vec3(dt), lessThan(u_sigma_t * dt, vec3(1e-4)));
        L += T * S * k;
        T *= tr;
        imageStore(u_integrated, ivec3(id, z), vec4(L, dot(T, vec3(1.0 / 3.0))));
    }
}
