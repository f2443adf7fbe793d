#version 330 core
// radial_blur at blur_scale < 1 (docs/radial-blur.md, "Cost"): the blur ran on a reduced
// target; this pass stretches it bilinearly over the frame (the GPU Gems 3 chapter's and the
// engines' reduced-resolution post-process). The output scale is already in the blurred values.
uniform sampler2D u_src;     // the reduced blur target, bilinear, clamped
uniform vec2 u_size;         // output size (pixels)
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(texture(u_src, gl_FragCoord.xy / u_size).rgb, 1.0); }
