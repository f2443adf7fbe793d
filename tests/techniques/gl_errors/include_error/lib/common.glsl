// shared
vec3 shade() {
    return vec3(u_set_gain) * missing_factor;
}
