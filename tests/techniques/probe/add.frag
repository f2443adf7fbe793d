out vec4 o_color;
void main() { o_color = vec4(vec3(u_set_add), 0.0); }
