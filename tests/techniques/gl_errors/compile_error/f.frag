// line 1
// line 2
out vec4 o_color;
void main() {
    o_color = vec4(undeclared_thing, 1.0);
}
