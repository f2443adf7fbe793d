/* The one header that gives OpenGL 4.5 core-profile prototypes to the project.
 * Entry points link directly against GLVND's libOpenGL (which exports every core function up
 * to 4.6 and dispatches to the vendor of the current EGL context), so no loader is needed.
 * Include this instead of <GL/gl.h> or <GL/glext.h>: mixing them with glcorearb.h clashes.
 * Every call needs a context current on the calling thread (gr_gl_create, src/gl/glctx.h). */
#ifndef GR_GL_H
#define GR_GL_H

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#endif
