#version 330 core
// Shared prelude of the shaders that evaluate seed 000's waves (shafts.vert.glsl,
// shafts_corner.frag.glsl, radial_blur_light.frag.glsl): the seed's packed Gerstner waves and
// its surface function, compiled in front of each (shaders.h stages).

#define MAX_WAVE_GROUPS 16

uniform int u_wave_groups;    // number of groups of 4 waves
// Seed layout per group of 4 waves: kx, ky, A/|k|, A, phase constant. Here "ky" is the
// z component of the wave vector and the constant is c = w t - phi0 - k.P (mod 2 pi, in
// double on the CPU), so phase = k.(X0 - P) - c = k.X0 - w t + phi0, eq. 5.5.7.
uniform vec4 u_waves[MAX_WAVE_GROUPS * 5];

// Seed CalculateWaterNormal (eq. 5.5.8), plus the displacement of eq. 5.5.7, at a rest
// position relative to P.
void surface(vec2 rest, out vec3 disp, out vec3 normal)
{
    vec3 t1 = vec3(1.0, 0.0, 0.0);
    vec3 t2 = vec3(0.0, 0.0, 1.0);
    disp = vec3(0.0);
    for (int i = 0, j = 0; i < u_wave_groups; i++, j += 5) {
        vec4 kx = u_waves[j];
        vec4 ky = u_waves[j + 1];
        vec4 Ainvk = u_waves[j + 2];
        vec4 A = u_waves[j + 3];
        vec4 wt = u_waves[j + 4];
        vec4 phase = kx * rest.x + ky * rest.y - wt;
        vec4 sinp = sin(phase);
        vec4 cosp = cos(phase);

        // eq. 5.5.7: X = X0 - sum a K/|K| sin(phase), y = y0 + sum a cos(phase)
        disp.x -= dot(Ainvk, kx * sinp);
        disp.z -= dot(Ainvk, ky * sinp);
        disp.y += dot(A, cosp);

        // Update tangent vector along x0 (eq. 5.5.8, T)
        t1.x -= dot(Ainvk, kx * cosp * kx);
        t1.z -= dot(Ainvk, ky * cosp * kx);
        t1.y += dot(A, (-sinp) * kx);

        // Update tangent vector along z0 (eq. 5.5.8, B)
        t2.x -= dot(Ainvk, kx * cosp * ky);
        t2.z -= dot(Ainvk, ky * cosp * ky);
        t2.y += dot(A, (-sinp) * ky);
    }
    normal = normalize(cross(t2, t1));
}
