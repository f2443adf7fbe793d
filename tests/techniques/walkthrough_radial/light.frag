// Light pass: the refracted sun as a soft disc, occluders and the seabed drawn black
// (an engine renders its sun sprite and its opaque geometry in black here).
out vec4 o_color;

void main()
{
    vec2 d = (v_uv - u_sun_uv) * vec2(u_aspect, 1.0);
    float disc = exp(-dot(d, d) / (u_set_sun_radius * u_set_sun_radius));
    float open = gr_eye_depth(v_uv) >= u_far ? 1.0 : 0.0;
    o_color = vec4(u_sun_irradiance * u_transmittance_flat * disc * open, 1.0);
}
