// The harness textures "caustics" and "scene_colour" (docs/techniques.md "Harness textures")
// written to the layer for tests/integration/test_usertech_textures.c.
out vec4 o_color;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 c = vec3(0.0);
    if (u_set_mode == 0) {
        // the stack's helper where this pixel's ray meets the plane y = rest - plane_depth_m
        vec3 d = gr_view_ray(v_uv);
        float y = u_rest_height - u_set_plane_depth_m;
        float t = d.y < -1e-4 ? (y - u_eye.y) / d.y : -1.0;
        if (t > 0.0) c = vec3(gr_caustic_irradiance(u_eye + d * t), t, 1.0);
    } else if (u_set_mode == 1) {
        c = vec3(texelFetch(t_caustics, ivec3(px, u_set_layer), 0).r);
    } else if (u_set_mode == 2) {
        c = texelFetch(t_scene_colour, px, 0).rgb * u_scene_colour_radiance;
    } else if (u_set_mode == 3) {
        c = texelFetch(t_sun_light, px, 0).rgb * u_sun_light_radiance;
    } else {
        c = vec3(texelFetch(t_scene_colour, px, 0).a, texelFetch(t_sun_light, px, 0).a, 0.0);
    }
    o_color = vec4(c, 1.0);
}
