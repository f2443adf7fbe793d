#version 330 core
// Eye depth: linear distance (m) from the eye to the occluder surface seen through this
// pixel. Blended with GL_MIN into an R32F target cleared to the far distance, so the nearest
// surface wins without a depth buffer.
in vec3 v_rel;
layout(location = 0) out float o_dist;
void main() { o_dist = length(v_rel); }
