#version 330 core
// Flux variant, second pre-pass (docs/realtime-shafts.md "flux"): the irradiance across the
// beam of every shaft (cell) and depth slab, texel (i, j + slab (N - 1)), as a multiple of
// E_sun. Energy conservation: the flux through the shaft's top face, E_sun |A_top . I| T,
// crosses its section across the flat T at every depth, never smaller than the sun disc's blur
// (Steiner: P r + pi r^2, r = alpha_w s); the slab takes the mean over its depth range. The lattice
// points come from the corner pre-pass.

uniform sampler2D u_corner_pos;  // lattice points (viewer-relative) and transmittance
uniform sampler2D u_corner_refr; // refracted directions
uniform int u_tiled;             // 1: lattice point of cell i is i, else 2 i
uniform int u_cells;             // N - 1
uniform int u_slabs;
uniform float u_length;          // extrusion length (m)
uniform float u_width;           // shaft width as a fraction of the cell
uniform vec3 u_sun_dir;          // I
uniform vec3 u_refr_flat;        // T of the flat surface
uniform float u_sun_radius_w;    // the sun's angular radius under water (rad)
uniform mat4 u_shadow_matrix;    // viewer-relative -> shadow texture [0,1]^3 (scenegl's map)
uniform sampler2D u_shadow_map;  // the occluders' depth along T; 1 where none
uniform float u_shadow_bias;     // depth bias in the same units
uniform int u_shadows;           // 1: apply the occluders' shadows

// 1 if the point p (viewer-relative) sees the refracted sun past the occluders (seed's test)
float lit(vec3 p)
{
    vec4 sp = u_shadow_matrix * vec4(p, 1.0);
    float sz = textureLod(u_shadow_map, sp.xy / sp.w, 0.0).x;
    return (sz >= 1.0 || sp.z / sp.w - u_shadow_bias < sz) ? 1.0 : 0.0;
}

layout(location = 0) out vec4 o_e;

void main()
{
    ivec2 t = ivec2(gl_FragCoord.xy);
    int slab = t.y / u_cells;
    ivec2 cell = ivec2(t.x, t.y - slab * u_cells);
    ivec2 base = u_tiled != 0 ? cell : 2 * cell;
    vec3 q[4];
    vec3 rd[4];
    float trs = 0.0;
    for (int k = 0; k < 4; k++) {
        ivec2 c = base + ivec2((k == 1 || k == 2) ? 1 : 0, (k >= 2) ? 1 : 0);
        vec4 pt = texelFetch(u_corner_pos, c, 0);
        q[k] = pt.xyz;
        trs += 0.25 * pt.w;
        rd[k] = texelFetch(u_corner_refr, c, 0).xyz;
    }
    // The slab's irradiance is E's mean over its depth range (so that the slab carries the
    // light that the continuous beam carries through it: a slab whose middle falls on a focus
    // is not the focus' peak): the section of the four corner rays is a quadratic in s,
    // averaged here with 8 midpoint samples.
    float a_top = 0.5 * abs(dot(cross(q[2] - q[0], q[3] - q[1]), u_sun_dir));
    float ds = u_length / float(u_slabs);
    float e = 0.0;
    for (int i = 0; i < 8; i++) {
        float sm = (float(slab) + (float(i) + 0.5) / 8.0) * ds;
        vec3 m[4];
        for (int k = 0; k < 4; k++) m[k] = q[k] + rd[k] * sm;
        float a_sec = 0.5 * abs(dot(cross(m[2] - m[0], m[3] - m[1]), u_refr_flat));
        float perim = 0.0; // the section's perimeter across T
        for (int k = 0; k < 4; k++) {
            vec3 ed = m[(k + 1) & 3] - m[k];
            perim += length(ed - dot(ed, u_refr_flat) * u_refr_flat);
        }
        // the sun disc of angular radius alpha_w blurs every point into a disc of radius
        // r = alpha_w s, which adds P r + pi r^2 to the section (Steiner's formula for the
        // Minkowski sum): what a section shrunk to a line or a point focus still covers. A
        // smooth maximum of the two, as in a tiled grid the neighbours' blur spills back in
        // (on flat water E stays Phi / A to 0.1 %)
        float r = u_sun_radius_w * sm;
        float a_blur = perim * r + 3.14159265 * r * r;
        // occluders: the sample's lit fraction (its 4 corners and centre against the shadow
        // map): a weight of the slab, so shafts stay closed solids (docs "Occluder shadows")
        float f = 1.0;
        if (u_shadows != 0)
            f = 0.2 * (lit(m[0]) + lit(m[1]) + lit(m[2]) + lit(m[3]) + lit(0.25 * (m[0] + m[1] + m[2] + m[3])));
        e += f / max(sqrt(a_sec * a_sec + a_blur * a_blur), 1e-12);
    }
    // each shaft carries its whole cell's flux (width^2 of the cell is drawn)
    o_e = vec4(a_top * trs * (e / 8.0) / (u_width * u_width), 0.0, 0.0, 1.0);
}
