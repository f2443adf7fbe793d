#include <common.glsl>
