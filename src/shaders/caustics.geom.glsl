#version 450 core
// Caustic texture (seed 002), geometry stage: the surface triangle's refracted rays meet the
// plane y = u_plane_y (patch-local) at V_i = P_i + T_i (y - P_i.y) / T_i.y; the caustic
// triangle carries F_t |to_sun . a| / |A(V)| (flux per unit E_sun over its horizontal
// footprint: docs/volume-techniques.md, "Area ratio"). Drawn once per copy of the patch it
// overlaps (the texture tiles), in texture space [0, L)^2 -> NDC.
layout(triangles) in;
layout(triangle_strip, max_vertices = 27) out;
in vec3 v_pos[];
in vec3 v_refr[];
in float v_ft[];
uniform float u_L;
uniform float u_plane_y;
uniform vec3 u_to_sun;
uniform float u_texel;       // texel side of the rendered (2x) level (m)
out float g_value;

void main()
{
    vec2 V[3];
    for (int i = 0; i < 3; i++) {
        if (!(v_refr[i].y < -1e-4)) return; // total internal reflection / grazing: no beam
        float s = (u_plane_y - v_pos[i].y) / v_refr[i].y;
        if (s < 0.0) return;                // the plane is above this vertex
        V[i] = v_pos[i].xz + v_refr[i].xz * s;
    }
    vec3 a = 0.5 * cross(v_pos[1] - v_pos[0], v_pos[2] - v_pos[0]);
    if (a.y < 0.0) a = -a;
    float flux = max(0.0, dot(u_to_sun, a)) * (v_ft[0] + v_ft[1] + v_ft[2]) / 3.0;
    vec2 e1 = V[1] - V[0], e2 = V[2] - V[0];
    float area = 0.5 * abs(e1.x * e2.y - e1.y * e2.x);
    if (!(flux > 0.0) || !(area > 0.0)) return;
    float value = flux / area;
    vec2 c = (V[0] + V[1] + V[2]) / 3.0;
    vec2 shift = floor(c / u_L) * u_L;
    if (area < u_texel * u_texel) {
        // Sub-texel footprint (near a focus or a fold): a triangle would hit one sample or
        // none; deposit its whole flux into the texel of its centroid instead (a half-texel
        // square around that texel's centre covers exactly its one sample): flux conserved.
        vec2 q = (floor((c - shift) / u_texel) + 0.5) * u_texel / u_L;
        float hq = 0.25 * u_texel / u_L;
        g_value = flux / (u_texel * u_texel);
        for (int i = 0; i < 4; i++) {
            vec2 o = vec2((i & 1) != 0 ? hq : -hq, (i & 2) != 0 ? hq : -hq);
            gl_Position = vec4((q + o) * 2.0 - 1.0, 0.0, 1.0);
            EmitVertex();
        }
        EndPrimitive();
        return;
    }
    vec2 lo = min(min(V[0], V[1]), V[2]) - shift, hi = max(max(V[0], V[1]), V[2]) - shift;
    for (int oy = -1; oy <= 1; oy++)
        for (int ox = -1; ox <= 1; ox++) {
            vec2 o = vec2(ox, oy) * u_L;
            if (hi.x + o.x < 0.0 || lo.x + o.x > u_L || hi.y + o.y < 0.0 || lo.y + o.y > u_L) continue;
            for (int i = 0; i < 3; i++) {
                vec2 q = (V[i] - shift + o) / u_L;
                g_value = value;
                gl_Position = vec4(q * 2.0 - 1.0, 0.0, 1.0);
                EmitVertex();
            }
            EndPrimitive();
        }
}
