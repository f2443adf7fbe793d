out vec4 o_color;
void main() {
    o_color = vec4(texture(t_eye_depth, v_uv).r);
}
