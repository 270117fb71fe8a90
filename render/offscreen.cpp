#include "render/offscreen.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <vector>

namespace arview::render {
namespace {

constexpr int kMaxThreads = 32;

void* OpenFirst(const std::vector<const char*>& names, std::string* tried) {
  for (const char* name : names) {
    if (void* handle = dlopen(name, RTLD_NOW | RTLD_LOCAL)) return handle;
    *tried += std::string(tried->empty() ? "" : ", ") + name;
  }
  return nullptr;
}

template <typename Fn>
Fn Symbol(void* handle, const char* name, const std::string& library) {
  void* p = dlsym(handle, name);
  if (p == nullptr) throw RenderError(library + " lacks " + name);
  return reinterpret_cast<Fn>(p);
}

// Mesa reads LP_NUM_THREADS when it creates its screen, once per process and backend.
void SetThreadsOnce(GlBackend backend, int threads) {
  static std::mutex mutex;
  static std::map<GlBackend, int> fixed;
  std::lock_guard lock(mutex);
  if (threads < 0 || threads > kMaxThreads) {
    throw RenderError("llvmpipe thread count " + std::to_string(threads) + " is outside 0.." +
                      std::to_string(kMaxThreads));
  }
  if (auto it = fixed.find(backend); it != fixed.end()) {
    if (it->second != threads) {
      throw RenderError(ToString(backend) + ": llvmpipe already runs with " +
                        std::to_string(it->second) + " threads in this process; cannot switch to " +
                        std::to_string(threads));
    }
    return;
  }
  setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  fixed[backend] = threads;
}

class OsMesaContext final : public OffscreenContext {
 public:
  explicit OsMesaContext(int threads) : OffscreenContext(GlBackend::kOsMesa, threads) {
    std::string tried;
    void* lib = OpenFirst({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}, &tried);
    if (lib == nullptr) throw RenderError("OSMesa library not found (tried " + tried + ")");
    using CreateFn = OSMesaContext (*)(const int*, OSMesaContext);
    create_ = Symbol<CreateFn>(lib, "OSMesaCreateContextAttribs", "libOSMesa");
    make_current_ = Symbol<decltype(make_current_)>(lib, "OSMesaMakeCurrent", "libOSMesa");
    destroy_ = Symbol<decltype(destroy_)>(lib, "OSMesaDestroyContext", "libOSMesa");
    get_proc_ = Symbol<decltype(get_proc_)>(lib, "OSMesaGetProcAddress", "libOSMesa");

    SetThreadsOnce(GlBackend::kOsMesa, threads);
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                              OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    context_ = create_(attributes, nullptr);
    if (context_ == nullptr) throw RenderError("OSMesa cannot create an OpenGL 4.5 core context");
    MakeCurrent();
    LoadApi([this](const char* name) { return reinterpret_cast<void*>(get_proc_(name)); });
  }
  ~OsMesaContext() override {
    if (context_ != nullptr) destroy_(context_);
  }
  void MakeCurrent() override {
    // OSMesa needs a client buffer to be current; drawing goes to framebuffer objects, so a
    // single pixel suffices.
    if (!make_current_(context_, &pixel_, GL_UNSIGNED_BYTE, 1, 1)) {
      throw RenderError("OSMesaMakeCurrent failed");
    }
  }

 private:
  OSMesaContext (*create_)(const int*, OSMesaContext) = nullptr;
  GLboolean (*make_current_)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*destroy_)(OSMesaContext) = nullptr;
  OSMESAproc (*get_proc_)(const char*) = nullptr;
  OSMesaContext context_ = nullptr;
  unsigned char pixel_[4] = {0, 0, 0, 0};
};

std::string EglErrorText(EGLint error) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%04x", error);
  return text;
}

class EglContext final : public OffscreenContext {
 public:
  explicit EglContext(int threads) : OffscreenContext(GlBackend::kEgl, threads) {
    std::string tried;
    void* lib = OpenFirst({"libEGL.so.1", "libEGL.so"}, &tried);
    if (lib == nullptr) throw RenderError("EGL library not found (tried " + tried + ")");
    get_proc_ = Symbol<decltype(get_proc_)>(lib, "eglGetProcAddress", "libEGL");
    initialize_ = Symbol<decltype(initialize_)>(lib, "eglInitialize", "libEGL");
    bind_api_ = Symbol<decltype(bind_api_)>(lib, "eglBindAPI", "libEGL");
    create_ = Symbol<decltype(create_)>(lib, "eglCreateContext", "libEGL");
    make_current_ = Symbol<decltype(make_current_)>(lib, "eglMakeCurrent", "libEGL");
    destroy_ = Symbol<decltype(destroy_)>(lib, "eglDestroyContext", "libEGL");
    query_ = Symbol<decltype(query_)>(lib, "eglQueryString", "libEGL");
    get_error_ = Symbol<decltype(get_error_)>(lib, "eglGetError", "libEGL");

    const char* client = query_(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client == nullptr || std::string(client).find("EGL_MESA_platform_surfaceless") == std::string::npos) {
      throw RenderError("EGL has no EGL_MESA_platform_surfaceless (not Mesa, or too old)");
    }
    auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(get_proc_("eglGetPlatformDisplayEXT"));
    if (get_display == nullptr) throw RenderError("EGL lacks eglGetPlatformDisplayEXT");

    SetThreadsOnce(GlBackend::kEgl, threads);
    display_ = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !initialize_(display_, &major, &minor)) {
      throw RenderError("EGL surfaceless display cannot be initialised (error " + EglErrorText(get_error_()) + ")");
    }
    if (!bind_api_(EGL_OPENGL_API)) throw RenderError("EGL cannot bind the desktop OpenGL API");
    // Configless (EGL_KHR_no_config_context) and surfaceless (EGL_KHR_surfaceless_context):
    // no pbuffer, drawing goes to framebuffer objects.
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = create_(display_, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT) {
      throw RenderError("EGL cannot create an OpenGL 4.5 core context (error " + EglErrorText(get_error_()) + ")");
    }
    MakeCurrent();
    LoadApi([this](const char* name) { return reinterpret_cast<void*>(get_proc_(name)); });
  }
  ~EglContext() override {
    if (context_ != EGL_NO_CONTEXT) {
      make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      destroy_(display_, context_);
    }
    // The display stays initialised: other contexts of this process may share it.
  }
  void MakeCurrent() override {
    if (!make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      throw RenderError("eglMakeCurrent failed (error " + EglErrorText(get_error_()) + ")");
    }
  }

 private:
  __eglMustCastToProperFunctionPointerType (*get_proc_)(const char*) = nullptr;
  EGLBoolean (*initialize_)(EGLDisplay, EGLint*, EGLint*) = nullptr;
  EGLBoolean (*bind_api_)(EGLenum) = nullptr;
  EGLContext (*create_)(EGLDisplay, EGLConfig, EGLContext, const EGLint*) = nullptr;
  EGLBoolean (*make_current_)(EGLDisplay, EGLSurface, EGLSurface, EGLContext) = nullptr;
  EGLBoolean (*destroy_)(EGLDisplay, EGLContext) = nullptr;
  const char* (*query_)(EGLDisplay, EGLint) = nullptr;
  EGLint (*get_error_)() = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

std::unique_ptr<OffscreenContext> CreateOne(GlBackend backend, int threads) {
  if (backend == GlBackend::kOsMesa) return std::make_unique<OsMesaContext>(threads);
  return std::make_unique<EglContext>(threads);
}

}  // namespace

GlBackend ParseGlBackend(const std::string& name) { return ParseEnum<GlBackend, RenderError>(name, "GL backend"); }

std::unique_ptr<OffscreenContext> OffscreenContext::Create(const OffscreenOptions& options) {
  if (options.backend != GlBackend::kAuto) {
    try {
      return CreateOne(options.backend, options.threads);
    } catch (const RenderError& e) {
      throw RenderError("no OpenGL: " + std::string(e.what()));
    }
  }
  std::string failures;
  for (GlBackend backend : {GlBackend::kOsMesa, GlBackend::kEgl}) {
    try {
      return CreateOne(backend, options.threads);
    } catch (const RenderError& e) {
      failures += (failures.empty() ? "" : "; ") + ToString(backend) + ": " + e.what();
    }
  }
  throw RenderError("no OpenGL 4.5 offscreen context (" + failures +
                    "); install Mesa's libosmesa6 or libegl-mesa0");
}

void OffscreenContext::LoadApi(const GlProcLoader& loader) { gl_ = LoadGlApi(loader, ToString(backend_)); }

std::string OffscreenContext::Description() const {
  auto text = [this](GLenum name) {
    const GLubyte* s = gl_.GetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return ToString(backend_) + ": " + text(GL_RENDERER) + ", OpenGL " + text(GL_VERSION) + ", " +
         std::to_string(threads_) + " llvmpipe threads";
}

int OffscreenContext::MaxSamples() const {
  GLint samples = 0;
  gl_.GetIntegerv(GL_MAX_SAMPLES, &samples);
  return samples;
}

}  // namespace arview::render
