#include "render/gl_api.h"

#include <cstdio>

#include "render/offscreen.h"

namespace arview::render {

GlApi LoadGlApi(const GlProcLoader& loader, const std::string& backend_name) {
  GlApi gl;
#define ARVIEW_GL_LOAD(ret, name, params)                                                    \
  gl.name = reinterpret_cast<ret(APIENTRY*) params>(loader("gl" #name));                     \
  if (gl.name == nullptr) {                                                                  \
    throw RenderError(backend_name + ": OpenGL entry point gl" #name " is not available");   \
  }
  ARVIEW_GL_FUNCTIONS(ARVIEW_GL_LOAD)
#undef ARVIEW_GL_LOAD
  return gl;
}

void CheckGl(const GlApi& gl, const std::string& what) {
  const GLenum error = gl.GetError();
  if (error != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", error);
    throw RenderError("OpenGL error " + std::string(code) + " in " + what);
  }
}

}  // namespace arview::render
