// Seed 000 (Lanza, "Animation and Rendering of Underwater God Rays"), shaft vertex shader,
// ported from the seed's HLSL VS. Every deviation is listed in docs/realtime-shafts.md.
// Positions are relative to the viewer (camera-relative rendering): the CPU subtracts the
// viewer in double precision, so float stays exact far from the world origin.

// Compiled after seed_waves.glsl (#version, the waves' uniforms, surface()).

layout(location = 0) in vec2 a_cell;    // cell centre, in grid cells, relative to P (flux: lattice point)
layout(location = 1) in vec2 a_corner;  // corner of the shaft's cross-section, +-0.5 cell
layout(location = 2) in float a_bottom; // fraction of the extrusion length: 0 top (seed: input.length = 0),
                                        // 1 bottom; b / slabs for the flux variant's lattice levels

uniform vec3 u_origin;        // P - viewer (m): seed `origin`, eq. 5.5.5a
uniform float u_spacing;      // S (m): seed `spacing`, eq. 5.5.6
uniform float u_width;        // shaft width as a fraction of the grid cell
uniform float u_length;       // extrusion length (m) of bottom vertices
uniform vec3 u_extinction;    // c (1/m), eq. 5.5.3: seed `extinction_c`
uniform vec3 u_sun_dir;       // I, unit direction of travel: seed `sunDir`
uniform float u_eta;          // 1 / ior (seed: 1./1.333)
uniform float u_r0;           // Schlick R0 (seed: 0.0204)
uniform mat4 u_view_proj;     // viewer-relative world -> clip
uniform mat4 u_shadow_matrix; // viewer-relative world -> shadow-map texture space [0,1]^3
uniform int u_variant;        // 0 seed, 1 path, 2 flux (docs/realtime-shafts.md "Variants")
uniform float u_ratio;        // path: irradiance factor cos(theta_i) / cos(theta_t) / width^2 (flat water)
uniform vec3 u_refr_flat;     // flux: T of the flat surface (cross-sections are taken across it)
uniform float u_sun_radius_w; // flux: the sun's angular radius under water (rad), the regularizer
uniform sampler2D u_corner_pos;  // flux: corner positions (viewer-relative) and transmittance
uniform sampler2D u_corner_refr; // flux: corner refracted directions (shafts_corner.frag.glsl)
uniform sampler2D u_shadow_map;  // path: the occluders' depth along the flat T (scenegl, [0,1])
uniform float u_shadow_dz;       // path: metres per shadow depth unit; 0: shafts are not cut

out vec3 v_intensity;   // seed: output.intensity (read as input.outScattering by its PS)
out vec4 v_shadow_pos;  // seed: output.shadowmapPos
out vec3 v_world;       // viewer-relative world position (transform-feedback capture only)
out float v_len;        // path, flux: distance travelled under water along the refracted ray (m)
out float v_tr;         // path, flux: Fresnel transmittance at the shaft's top
out float v_ratio;      // path, flux: irradiance across the beam / (E_sun), constant per slab

// Seed eq. 5.5.2a with the incidence cosine as argument (the listing declares 3 parameters
// and calls it with 2); clamped so that pow never sees a negative base.
float fast_fresnel(float cos_i, float r0)
{
    float m = 1.0 - clamp(cos_i, 0.0, 1.0);
    float m2 = m * m;
    return r0 + (1.0 - r0) * (m2 * m2 * m);
}

// Path: length along the refracted direction rd from the surface point p (viewer-relative)
// to the first occluder in the shadow map (docs/realtime-shafts.md "Occluder shadows"): the
// map stores the casters' depth along the flat T, so the caster lies (sz - z) dz metres
// along T below p; 1e30 where no caster is stored.
float shadow_length(vec3 p, vec3 rd)
{
    if (u_shadow_dz <= 0.0) return 1e30;
    vec4 sp = u_shadow_matrix * vec4(p, 1.0);
    float sz = textureLod(u_shadow_map, sp.xy / sp.w, 0.0).x;
    if (sz >= 1.0) return 1e30;
    return max(sz - sp.z / sp.w, 0.0) * u_shadow_dz / max(dot(rd, u_refr_flat), 0.1);
}

void main()
{
    if (u_variant == 2) {
        // Flux (docs: "flux"): a_cell is the lattice point (p, q), a_bottom the level's fraction
        // of the length; the point, its refracted direction and the length to the first
        // occluder come from the pre-pass, the slabs' irradiance is read per face (fragment).
        vec4 pt = texelFetch(u_corner_pos, ivec2(a_cell), 0);
        vec4 rl = texelFetch(u_corner_refr, ivec2(a_cell), 0);
        float lenf = a_bottom * u_length; // occluders: each slab's lit fraction (shafts_flux.frag.glsl)
        vec3 posf = pt.xyz + rl.xyz * lenf;
        v_len = lenf;
        v_tr = 1.0;
        v_ratio = 1.0;
        v_intensity = vec3(0.0);
        v_shadow_pos = vec4(0.0);
        v_world = posf;
        gl_Position = u_view_proj * vec4(posf, 1.0);
        gl_Position.z = 0.01;
        return;
    }
    // Scale and translate the vertex on the water surface (rest position, relative to P).
    vec2 rest = (a_cell + a_corner * u_width) * u_spacing;
    vec3 disp, normal;
    surface(rest, disp, normal);

    // Top vertices on the Gerstner surface (eq. 5.5.7; the seed's listing leaves them flat).
    vec3 pos = u_origin + vec3(rest.x, 0.0, rest.y) + disp;

    // Extrude bottom vertices along the refracted sunlight (eq. 5.5.1, GLSL refract).
    float len = a_bottom * u_length;
    if (a_bottom > 0.0) {
        vec3 refr = refract(u_sun_dir, normal, u_eta);
        // path: the whole shaft ends where its centre ray meets an occluder (one length for
        // its 4 bottom corners keeps it a closed solid: docs "Occluder shadows")
        if (u_shadow_dz > 0.0) {
            vec2 rest_c = a_cell * u_spacing;
            vec3 disp_c, normal_c;
            surface(rest_c, disp_c, normal_c);
            vec3 top_c = u_origin + vec3(rest_c.x, 0.0, rest_c.y) + disp_c;
            len = min(len, shadow_length(top_c, refract(u_sun_dir, normal_c, u_eta)));
        }
        pos += refr * len;
    }

    // Transmittance (eq. 5.5.2b) and attenuation over surface->vertex->viewer (eq. 5.5.3).
    float tr = 1.0 - fast_fresnel(dot(-u_sun_dir, normal), u_r0);
    float total_dist = len + length(pos);
    v_intensity = exp(-total_dist * u_extinction) * tr;
    v_len = len;
    v_tr = tr;
    v_ratio = u_ratio;

    v_shadow_pos = u_shadow_matrix * vec4(pos, 1.0);
    v_world = pos;

    gl_Position = u_view_proj * vec4(pos, 1.0);
    // Seed: force z so shafts close to the viewer are not clipped. With z = 0.01 the GL
    // clip test -w <= z <= w keeps exactly what D3D's 0 <= z <= w keeps: w >= 0.01.
    gl_Position.z = 0.01;
}
