#pragma once
// The OpenGL 4.5 core entry points render/ uses, loaded through the backend's
// GetProcAddress (OSMesaGetProcAddress or eglGetProcAddress).
//
// Why not call gl* symbols directly: libOSMesa exports its own gl* functions (dispatched
// through Mesa's libglapi) while the EGL path goes through glvnd's libOpenGL (dispatched
// through libGLdispatch). Linking both would bind each gl* symbol to only one of them, so
// one backend would silently call into a context that is not current. Loading every entry
// point from the backend that created the context is correct for both.

#include <GL/glcorearb.h>

#include <functional>
#include <string>

namespace arview::render {

// X-macro: (return type, name without the "gl" prefix, parameter list).
#define ARVIEW_GL_FUNCTIONS(X)                                                                        \
  X(void, Viewport, (GLint, GLint, GLsizei, GLsizei))                                                 \
  X(void, Scissor, (GLint, GLint, GLsizei, GLsizei))                                                  \
  X(void, Clear, (GLbitfield))                                                                        \
  X(void, ClearColor, (GLfloat, GLfloat, GLfloat, GLfloat))                                           \
  X(void, ClearDepth, (GLdouble))                                                                     \
  X(void, Enable, (GLenum))                                                                           \
  X(void, Disable, (GLenum))                                                                          \
  X(void, DepthFunc, (GLenum))                                                                        \
  X(void, DepthMask, (GLboolean))                                                                     \
  X(void, ColorMask, (GLboolean, GLboolean, GLboolean, GLboolean))                                    \
  X(void, BlendFunc, (GLenum, GLenum))                                                                \
  X(void, BlendFuncSeparate, (GLenum, GLenum, GLenum, GLenum))                                        \
  X(void, CullFace, (GLenum))                                                                         \
  X(void, FrontFace, (GLenum))                                                                        \
  X(void, PolygonOffset, (GLfloat, GLfloat))                                                          \
  X(const GLubyte*, GetString, (GLenum))                                                              \
  X(void, GetIntegerv, (GLenum, GLint*))                                                              \
  X(void, GetFloatv, (GLenum, GLfloat*))                                                              \
  X(GLenum, GetError, ())                                                                             \
  X(void, ReadPixels, (GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*))                        \
  X(void, ReadBuffer, (GLenum))                                                                       \
  X(void, DrawBuffers, (GLsizei, const GLenum*))                                                      \
  X(void, PixelStorei, (GLenum, GLint))                                                               \
  X(void, Finish, ())                                                                                 \
  X(void, GenTextures, (GLsizei, GLuint*))                                                            \
  X(void, DeleteTextures, (GLsizei, const GLuint*))                                                   \
  X(void, BindTexture, (GLenum, GLuint))                                                              \
  X(void, ActiveTexture, (GLenum))                                                                    \
  X(void, TexImage2D, (GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*))   \
  X(void, TexSubImage2D, (GLenum, GLint, GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, const void*)) \
  X(void, TexParameteri, (GLenum, GLenum, GLint))                                                     \
  X(void, TexParameterf, (GLenum, GLenum, GLfloat))                                                   \
  X(void, GenerateMipmap, (GLenum))                                                                   \
  X(void, GenBuffers, (GLsizei, GLuint*))                                                             \
  X(void, DeleteBuffers, (GLsizei, const GLuint*))                                                    \
  X(void, BindBuffer, (GLenum, GLuint))                                                               \
  X(void, BufferData, (GLenum, GLsizeiptr, const void*, GLenum))                                      \
  X(void, BufferSubData, (GLenum, GLintptr, GLsizeiptr, const void*))                                 \
  X(void*, MapBufferRange, (GLenum, GLintptr, GLsizeiptr, GLbitfield))                                \
  X(GLboolean, UnmapBuffer, (GLenum))                                                                 \
  X(GLsync, FenceSync, (GLenum, GLbitfield))                                                          \
  X(GLenum, ClientWaitSync, (GLsync, GLbitfield, GLuint64))                                           \
  X(void, DeleteSync, (GLsync))                                                                       \
  X(void, GenVertexArrays, (GLsizei, GLuint*))                                                        \
  X(void, DeleteVertexArrays, (GLsizei, const GLuint*))                                               \
  X(void, BindVertexArray, (GLuint))                                                                  \
  X(void, EnableVertexAttribArray, (GLuint))                                                          \
  X(void, VertexAttribPointer, (GLuint, GLint, GLenum, GLboolean, GLsizei, const void*))              \
  X(void, VertexAttribIPointer, (GLuint, GLint, GLenum, GLsizei, const void*))                        \
  X(void, DrawArrays, (GLenum, GLint, GLsizei))                                                       \
  X(void, DrawElements, (GLenum, GLsizei, GLenum, const void*))                                       \
  X(GLuint, CreateShader, (GLenum))                                                                   \
  X(void, ShaderSource, (GLuint, GLsizei, const GLchar* const*, const GLint*))                        \
  X(void, CompileShader, (GLuint))                                                                    \
  X(void, GetShaderiv, (GLuint, GLenum, GLint*))                                                      \
  X(void, GetShaderInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                     \
  X(void, DeleteShader, (GLuint))                                                                     \
  X(GLuint, CreateProgram, ())                                                                        \
  X(void, AttachShader, (GLuint, GLuint))                                                             \
  X(void, LinkProgram, (GLuint))                                                                      \
  X(void, GetProgramiv, (GLuint, GLenum, GLint*))                                                     \
  X(void, GetProgramInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                    \
  X(void, DeleteProgram, (GLuint))                                                                    \
  X(void, UseProgram, (GLuint))                                                                       \
  X(GLint, GetUniformLocation, (GLuint, const GLchar*))                                               \
  X(void, Uniform1i, (GLint, GLint))                                                                  \
  X(void, Uniform1f, (GLint, GLfloat))                                                                \
  X(void, Uniform1iv, (GLint, GLsizei, const GLint*))                                                 \
  X(void, Uniform1fv, (GLint, GLsizei, const GLfloat*))                                               \
  X(void, TexBuffer, (GLenum, GLenum, GLuint))                                                        \
  X(void, Uniform2f, (GLint, GLfloat, GLfloat))                                                       \
  X(void, Uniform3f, (GLint, GLfloat, GLfloat, GLfloat))                                              \
  X(void, Uniform4f, (GLint, GLfloat, GLfloat, GLfloat, GLfloat))                                     \
  X(void, Uniform3fv, (GLint, GLsizei, const GLfloat*))                                               \
  X(void, Uniform4fv, (GLint, GLsizei, const GLfloat*))                                               \
  X(void, UniformMatrix3fv, (GLint, GLsizei, GLboolean, const GLfloat*))                              \
  X(void, UniformMatrix4fv, (GLint, GLsizei, GLboolean, const GLfloat*))                              \
  X(void, GenFramebuffers, (GLsizei, GLuint*))                                                        \
  X(void, DeleteFramebuffers, (GLsizei, const GLuint*))                                               \
  X(void, BindFramebuffer, (GLenum, GLuint))                                                          \
  X(GLenum, CheckFramebufferStatus, (GLenum))                                                         \
  X(void, FramebufferRenderbuffer, (GLenum, GLenum, GLenum, GLuint))                                  \
  X(void, FramebufferTexture2D, (GLenum, GLenum, GLenum, GLuint, GLint))                              \
  X(void, GenRenderbuffers, (GLsizei, GLuint*))                                                       \
  X(void, DeleteRenderbuffers, (GLsizei, const GLuint*))                                              \
  X(void, BindRenderbuffer, (GLenum, GLuint))                                                         \
  X(void, RenderbufferStorageMultisample, (GLenum, GLsizei, GLenum, GLsizei, GLsizei))                \
  X(void, BlitFramebuffer, (GLint, GLint, GLint, GLint, GLint, GLint, GLint, GLint, GLbitfield, GLenum))

class SceneFences;

struct GlApi {
#define ARVIEW_GL_MEMBER(ret, name, params) ret(APIENTRY* name) params = nullptr;
  ARVIEW_GL_FUNCTIONS(ARVIEW_GL_MEMBER)
#undef ARVIEW_GL_MEMBER
  // The context's fences held for its read-backs (render/gl_objects.h), set by OffscreenContext;
  // null where the entry points were loaded otherwise: each RenderTarget then holds its own.
  SceneFences* scene_fences = nullptr;
};

using GlProcLoader = std::function<void*(const char* name)>;

// Loads every entry point; throws RenderError naming the first one the backend lacks.
GlApi LoadGlApi(const GlProcLoader& loader, const std::string& backend_name);

// Throws RenderError naming `what` when glGetError reports an error.
void CheckGl(const GlApi& gl, const std::string& what);

}  // namespace arview::render
