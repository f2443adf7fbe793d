#version 330 core
// Shadow map of the occluders along the refracted sun: depth only.
void main() {}
