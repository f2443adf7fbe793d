out vec4 o_color;
void main() { o_color = texelFetch(t_mid, ivec2(gl_FragCoord.xy), 0); }
