
// Light rays (seed 001 after Hu et al. 2010), pass 2, geometry stage: the texel's sun ray is
// refracted at its surface point p0 (seed eq. 5.5.1, exact Fresnel) and becomes one line
// along T from the surface to the first occluder (the shadow map, marched then bisected), the
// seabed or u_max_len. The line stands for its texel's beam, a prism around it whose
// cross-section across T is the footprint of u_kernel x u_kernel texels (u1, u2: the lattice of the light's texels
// carried along the sun to the rest plane and along T across it; m1, m2 its dual vectors).
// Drawn as (docs/volume-techniques.md, "Light rays"):
//   u_footprint 0 (prism): the prism's faces that look at the eye (its exact cover); the
//     fragment integrates the pixel's ray through the prism exactly;
//   u_footprint 1 (ribbon): a camera-facing ribbon, the sheet spanned by T and b = T x p0 / D
//     (D = |T x p0|, the line's distance from the eye), world width w = max(beam, u_line_width
//     pixels at the distance), NSEG pieces; the fragment adds sigma_s p Phi exp(...) r / (w D).
layout(points) in;
layout(triangle_strip, max_vertices = 18) out;
in vec4 v_pos[];
in vec4 v_nrm[];
uniform mat4 u_vp_rot;         // eye-relative position -> clip
uniform vec3 u_sun_dir;        // I: direction sunlight travels in air
uniform float u_ior;
uniform float u_texel_area;    // the texel's area across the sun's direction (m^2)
uniform vec3 u_h1, u_h2;       // the texel's edges carried along I to the rest plane (m)
uniform int u_footprint;       // 0 prism, 1 ribbon
uniform float u_pix;           // a centre pixel's world size at 1 m: 2 tan(fov_y / 2) / height
uniform vec2 u_size;           // viewport (px)
uniform float u_line_width;    // pixels
uniform float u_kernel;        // the footprint's side in texels (an integer: flat water stays exact)
uniform float u_max_len;       // m
uniform float u_seabed;        // seabed y - eye y (m); -1e30 without a seabed
out vec3 g_p;                  // ribbon: eye-relative position
out float g_w;                 // ribbon: width (m)
flat out vec3 g_p0;            // the line's surface point
flat out vec3 g_t;             // its refracted direction
flat out float g_flux;         // ribbon: F_t A_perp, flux per unit E_sun (m^2); prism: E_beam / E_sun
flat out float g_d;            // ribbon: D
flat out vec3 g_m1, g_m2;      // prism: dual lattice vectors (1/m)
flat out float g_ybot;         // prism: y of the line's end (eye-relative)

const int NSEG = 8;

// the prism's flat outputs, written again before each vertex (outputs are undefined after
// EmitVertex)
vec3 s_p0, s_t, s_m1, s_m2;
float s_flux, s_d, s_ybot;

void emit_prism(vec4 pos)
{
    g_p = vec3(0.0);
    g_w = 0.0;
    g_p0 = s_p0;
    g_t = s_t;
    g_flux = s_flux;
    g_d = s_d;
    g_m1 = s_m1;
    g_m2 = s_m2;
    g_ybot = s_ybot;
    gl_Position = pos;
    EmitVertex();
}

void emit_ndc(vec2 ndc)
{
    emit_prism(vec4(ndc, 0.0, 1.0));
}

void main()
{
    if (v_pos[0].w < 0.5) return;                 // no surface in this texel
    vec3 p0 = v_pos[0].xyz, n = v_nrm[0].xyz;
    float cos_i = dot(n, -u_sun_dir);
    if (!(cos_i > 0.0)) return;                   // facet turned away from the sun
    vec3 T = refract(u_sun_dir, n, 1.0 / u_ior);
    if (!(T.y < -1e-4)) return;                   // grazing: the ray never goes down
    float ft = fresnel_t(cos_i, u_ior);
    float len = u_max_len;
    if (u_seabed > -1e29) len = min(len, (p0.y - u_seabed) / -T.y);
    if (u_use_shadow != 0) {
        // first occluder along the line: march, then bisect the step that enters the shadow
        float lo = 0.0, hi = -1.0;
        for (int i = 1; i <= 32; i++) {
            float s = len * float(i) / 32.0;
            if (vol_shadow(p0 + T * s) < 0.5) { hi = s; break; }
            lo = s;
        }
        if (hi > 0.0) {
            for (int i = 0; i < 10; i++) {
                float m = 0.5 * (lo + hi);
                if (vol_shadow(p0 + T * m) < 0.5) hi = m; else lo = m;
            }
            len = lo;
        }
    }
    if (!(len > 0.0)) return;
    vec3 pe = p0 + T * len;
    s_p0 = p0;
    s_t = T;
    s_ybot = pe.y;
    // the prism's cross-section across T: the rest-plane footprint h1, h2 carried along T
    // (u_kernel texels wide: the prisms of a lattice then cover each point u_kernel^2 times, and
    // each carries 1 / u_kernel^2 of its flux per area)
    vec3 u1 = (u_h1 - T * dot(u_h1, T)) * u_kernel, u2 = (u_h2 - T * dot(u_h2, T)) * u_kernel;
    float area = abs(dot(cross(u1, u2), T));      // = A_perp |T.y| / |I.y|
    s_m1 = cross(u2, T) / dot(cross(u1, u2), T);
    s_m2 = cross(T, u1) / dot(cross(u1, u2), T);
    vec3 b = cross(T, p0);
    float D = length(b);

    if (u_footprint == 0) {
        s_flux = ft * u_texel_area / area;        // E_beam / E_sun = F_t |I.y| / |T.y| on flat water
        s_d = D;
        float rho = 0.525 * (length(u1) + length(u2)); // 1.05 x a radius holding the cross-section
        if (D < 2.0 * rho) {
            // the prism passes by the eye: its projection is most of the view
            emit_ndc(vec2(-1.0, -1.0));
            emit_ndc(vec2(1.0, -1.0));
            emit_ndc(vec2(-1.0, 1.0));
            emit_ndc(vec2(1.0, 1.0));
            EndPrimitive();
            return;
        }
        // the prism itself (a parallelepiped: the slabs |(x - p0) . m_i| <= 1/2 between the
        // horizontal caps y = p0.y and y = pe.y): its faces that look at the eye, at most three,
        // cover each pixel whose ray meets it exactly once (docs/volume-techniques.md, "Light
        // rays", the prism's cover). Corner (a, b) = +-1/2 of the cross-section: on the top cap
        // p0 + o + T o.y / mu, on the bottom one pe + o + T o.y / mu (o = a u1 + b u2, mu = -T.y).
        float mu = -T.y;
        vec4 cp[8];
        vec3 cw[8];
        // clipped at view depth zn: every point of the prism is farther than rho from the eye
        // (D >= 2 rho), so no pixel's ray meets it nearer than zn sec(theta_max) < rho
        float zn = 0.5 * rho / sqrt(1.0 + 0.25 * u_pix * u_pix * dot(u_size, u_size));
        for (int k = 0; k < 8; k++) {
            vec3 o = (float(k & 1) - 0.5) * u1 + (float((k >> 1) & 1) - 0.5) * u2;
            cw[k] = ((k & 4) == 0 ? p0 : pe) + o + T * (o.y / mu);
            vec4 c = u_vp_rot * vec4(cw[k], 1.0);
            cp[k] = vec4(c.xy, c.w - 2.0 * zn, c.w);      // -w <= z <=> w (view depth) >= zn
        }
        // faces: corners in cyclic order, outward normal; a face looks at the eye (the origin)
        // when its normal points away from the eye side: dot(n, corner) < 0
        const ivec4 face[6] = ivec4[6](ivec4(1, 3, 7, 5), ivec4(0, 2, 6, 4), ivec4(2, 3, 7, 6),
                                       ivec4(0, 1, 5, 4), ivec4(0, 1, 3, 2), ivec4(4, 5, 7, 6));
        vec3 nf[6] = vec3[6](s_m1, -s_m1, s_m2, -s_m2, vec3(0.0, 1.0, 0.0), vec3(0.0, -1.0, 0.0));
        for (int f = 0; f < 6; f++) {
            ivec4 q = face[f];
            if (!(dot(nf[f], cw[q.x]) < 0.0)) continue;
            emit_prism(cp[q.x]);
            emit_prism(cp[q.y]);
            emit_prism(cp[q.w]);
            emit_prism(cp[q.z]);
            EndPrimitive();
        }
        return;
    }

    // ribbon
    float beam = sqrt(area);
    b = D > 1e-6 ? b / D : normalize(cross(T, abs(T.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 0, 1)));
    D = max(D, 1e-6);
    for (int k = 0; k <= NSEG; k++) {
        vec3 p = p0 + T * (len * float(k) / float(NSEG));
        float w = max(beam, u_line_width * u_pix * length(p));
        for (int side = -1; side <= 1; side += 2) {
            vec3 q = p + b * (0.5 * w * float(side));
            g_p = q;
            g_w = w;
            g_p0 = p0;
            g_t = T;
            g_flux = ft * u_texel_area;
            g_d = D;
            g_m1 = vec3(0.0);
            g_m2 = vec3(0.0);
            g_ybot = pe.y;
            gl_Position = u_vp_rot * vec4(q, 1.0);
            EmitVertex();
        }
    }
    EndPrimitive();
}
