out vec4 o_color;
void main() {
    o_color = vec4(u_set_gian, u_sun_uvv, 1.0);
}
