out vec4 o_color;
void main() { float z = u_set_gain - 1.0; o_color = vec4(vec3(z / z), 1.0); }
