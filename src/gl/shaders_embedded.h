/* GLSL sources compiled into the binary (generated from src/shaders/ at build time). */
#ifndef GR_SHADERS_EMBEDDED_H
#define GR_SHADERS_EMBEDDED_H
typedef struct gr_embedded_shader {
    const char *name;   /* file name, e.g. "shafts.vert.glsl" */
    const char *source; /* NUL-terminated GLSL text */
} gr_embedded_shader;
/* Terminated by an entry whose name is NULL. */
extern const gr_embedded_shader gr_embedded_shaders[];
#endif
