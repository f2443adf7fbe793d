out vec4 o_color;
void main() {
    float x = gl_FragCoord.x * 1e-3;
    for (int i = 0; i < u_set_loops; i++) x = fract(x * 1.000173 + 0.1234567);
    o_color = vec4(x + 1e-3, 1.0, 1.0, 1.0) * 1e-3;
}
