void main() { gl_Position = vec4(5.0, 5.0, 0.0, 1.0); }
