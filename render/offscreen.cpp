#include "render/offscreen.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>

namespace arview::render {
namespace {

constexpr int kMaxThreads = 32;
constexpr int kMaxEglDevices = 64;

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

// Mesa reads LP_NUM_THREADS when it creates its screen, once per process and library: OSMesa
// carries its own gallium, EGL's surfaceless and device platforms share the DRI driver's.
void SetThreadsOnce(bool osmesa, int threads) {
  static std::mutex mutex;
  static std::map<bool, int> fixed;
  std::lock_guard lock(mutex);
  if (threads < 0 || threads > kMaxThreads) {
    throw RenderError("llvmpipe thread count " + std::to_string(threads) + " is outside 0.." +
                      std::to_string(kMaxThreads));
  }
  if (auto it = fixed.find(osmesa); it != fixed.end()) {
    if (it->second != threads) {
      throw RenderError(std::string(osmesa ? "osmesa" : "egl") + ": llvmpipe already runs with " +
                        std::to_string(it->second) + " threads in this process; cannot switch to " +
                        std::to_string(threads));
    }
    return;
  }
  setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  fixed[osmesa] = threads;
}

class OsMesaContext final : public OffscreenContext {
 public:
  explicit OsMesaContext(int threads) : OffscreenContext(GlBackend::kOsMesa, -1, threads) {
    std::string tried;
    void* lib = OpenFirst({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}, &tried);
    if (lib == nullptr) throw RenderError("OSMesa library not found (tried " + tried + ")");
    using CreateFn = OSMesaContext (*)(const int*, OSMesaContext);
    create_ = Symbol<CreateFn>(lib, "OSMesaCreateContextAttribs", "libOSMesa");
    make_current_ = Symbol<decltype(make_current_)>(lib, "OSMesaMakeCurrent", "libOSMesa");
    destroy_ = Symbol<decltype(destroy_)>(lib, "OSMesaDestroyContext", "libOSMesa");
    get_proc_ = Symbol<decltype(get_proc_)>(lib, "OSMesaGetProcAddress", "libOSMesa");

    SetThreadsOnce(true, threads);
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
  void ReleaseCurrent() override { make_current_(nullptr, nullptr, 0, 0, 0); }
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
  static const std::map<EGLint, const char*> names = {
      {EGL_NOT_INITIALIZED, "EGL_NOT_INITIALIZED"}, {EGL_BAD_ACCESS, "EGL_BAD_ACCESS"},
      {EGL_BAD_ALLOC, "EGL_BAD_ALLOC"},             {EGL_BAD_ATTRIBUTE, "EGL_BAD_ATTRIBUTE"},
      {EGL_BAD_CONFIG, "EGL_BAD_CONFIG"},           {EGL_BAD_CONTEXT, "EGL_BAD_CONTEXT"},
      {EGL_BAD_DISPLAY, "EGL_BAD_DISPLAY"},         {EGL_BAD_MATCH, "EGL_BAD_MATCH"},
      {EGL_BAD_PARAMETER, "EGL_BAD_PARAMETER"},     {EGL_BAD_SURFACE, "EGL_BAD_SURFACE"},
      {EGL_CONTEXT_LOST, "EGL_CONTEXT_LOST"}};
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", error);
  const auto it = names.find(error);
  return it == names.end() ? std::string(code) : std::string(it->second) + " " + code;
}

// libEGL (glvnd's, which dispatches to Mesa's and the GPU vendors' drivers), opened once.
struct EglLibrary {
  __eglMustCastToProperFunctionPointerType (*get_proc)(const char*) = nullptr;
  EGLBoolean (*initialize)(EGLDisplay, EGLint*, EGLint*) = nullptr;
  EGLBoolean (*bind_api)(EGLenum) = nullptr;
  EGLBoolean (*choose_config)(EGLDisplay, const EGLint*, EGLConfig*, EGLint, EGLint*) = nullptr;
  EGLContext (*create_context)(EGLDisplay, EGLConfig, EGLContext, const EGLint*) = nullptr;
  EGLSurface (*create_pbuffer)(EGLDisplay, EGLConfig, const EGLint*) = nullptr;
  EGLBoolean (*make_current)(EGLDisplay, EGLSurface, EGLSurface, EGLContext) = nullptr;
  EGLBoolean (*destroy_context)(EGLDisplay, EGLContext) = nullptr;
  EGLBoolean (*destroy_surface)(EGLDisplay, EGLSurface) = nullptr;
  const char* (*query_string)(EGLDisplay, EGLint) = nullptr;
  EGLint (*get_error)() = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = nullptr;
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;              // null without EGL_EXT_device_enumeration
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string = nullptr;   // null without EGL_EXT_device_query
  PFNEGLQUERYDEVICEATTRIBEXTPROC query_device_attrib = nullptr;
  std::string client_extensions;

  // Throws RenderError when there is no usable libEGL; the same answer for the whole process.
  static const EglLibrary& Get() {
    static const auto loaded = []() -> std::pair<std::unique_ptr<EglLibrary>, std::string> {
      try {
        return {std::make_unique<EglLibrary>(Load()), ""};
      } catch (const RenderError& e) {
        return {nullptr, e.what()};
      }
    }();
    if (!loaded.first) throw RenderError(loaded.second);
    return *loaded.first;
  }

  std::string LastError() const { return EglErrorText(get_error()); }

 private:
  static EglLibrary Load() {
    std::string tried;
    void* lib = OpenFirst({"libEGL.so.1", "libEGL.so"}, &tried);
    if (lib == nullptr) throw RenderError("EGL library not found (tried " + tried + ")");
    EglLibrary egl;
    egl.get_proc = Symbol<decltype(egl.get_proc)>(lib, "eglGetProcAddress", "libEGL");
    egl.initialize = Symbol<decltype(egl.initialize)>(lib, "eglInitialize", "libEGL");
    egl.bind_api = Symbol<decltype(egl.bind_api)>(lib, "eglBindAPI", "libEGL");
    egl.choose_config = Symbol<decltype(egl.choose_config)>(lib, "eglChooseConfig", "libEGL");
    egl.create_context = Symbol<decltype(egl.create_context)>(lib, "eglCreateContext", "libEGL");
    egl.create_pbuffer = Symbol<decltype(egl.create_pbuffer)>(lib, "eglCreatePbufferSurface", "libEGL");
    egl.make_current = Symbol<decltype(egl.make_current)>(lib, "eglMakeCurrent", "libEGL");
    egl.destroy_context = Symbol<decltype(egl.destroy_context)>(lib, "eglDestroyContext", "libEGL");
    egl.destroy_surface = Symbol<decltype(egl.destroy_surface)>(lib, "eglDestroySurface", "libEGL");
    egl.query_string = Symbol<decltype(egl.query_string)>(lib, "eglQueryString", "libEGL");
    egl.get_error = Symbol<decltype(egl.get_error)>(lib, "eglGetError", "libEGL");
    const char* client = egl.query_string(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    egl.client_extensions = client != nullptr ? client : "";
    egl.get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(egl.get_proc("eglGetPlatformDisplayEXT"));
    if (HasExtension(client, "EGL_EXT_device_enumeration") || HasExtension(client, "EGL_EXT_device_base")) {
      egl.query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(egl.get_proc("eglQueryDevicesEXT"));
    }
    if (HasExtension(client, "EGL_EXT_device_query") || HasExtension(client, "EGL_EXT_device_base")) {
      egl.query_device_string =
          reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(egl.get_proc("eglQueryDeviceStringEXT"));
      egl.query_device_attrib =
          reinterpret_cast<PFNEGLQUERYDEVICEATTRIBEXTPROC>(egl.get_proc("eglQueryDeviceAttribEXT"));
    }
    return egl;
  }
};

// The EGL devices and their handles, listed once per process (a device appears or goes only
// with a driver's reload).
struct EglDevices {
  std::vector<EglDeviceInfo> info;
  std::vector<EGLDeviceEXT> handles;
  std::string failure;  // why there are none
};

const EglDevices& ListEglDevices() {
  static const EglDevices devices = [] {
    EglDevices out;
    try {
      const EglLibrary& egl = EglLibrary::Get();
      if (egl.query_devices == nullptr || egl.query_device_string == nullptr) {
        out.failure = "EGL offers no device enumeration (EGL_EXT_device_enumeration, EGL_EXT_device_query)";
        return out;
      }
      if (egl.get_platform_display == nullptr || !HasExtension(egl.client_extensions.c_str(), "EGL_EXT_platform_device")) {
        out.failure = "EGL offers no device platform (EGL_EXT_platform_device)";
        return out;
      }
      EGLDeviceEXT handles[kMaxEglDevices];
      EGLint count = 0;
      if (!egl.query_devices(kMaxEglDevices, handles, &count)) {
        out.failure = "eglQueryDevicesEXT failed (" + egl.LastError() + ")";
        return out;
      }
      for (EGLint i = 0; i < count; ++i) {
        EglDeviceInfo d;
        d.index = i;
        const char* extensions = egl.query_device_string(handles[i], EGL_EXTENSIONS);
        d.extensions = extensions != nullptr ? extensions : "";
        if (HasExtension(extensions, "EGL_EXT_device_drm_render_node")) {
          if (const char* node = egl.query_device_string(handles[i], EGL_DRM_RENDER_NODE_FILE_EXT)) d.drm_node = node;
        }
        if (d.drm_node.empty() && HasExtension(extensions, "EGL_EXT_device_drm")) {
          if (const char* node = egl.query_device_string(handles[i], EGL_DRM_DEVICE_FILE_EXT)) d.drm_node = node;
        }
        EGLAttrib cuda = -1;
        if (HasExtension(extensions, "EGL_NV_device_cuda") && egl.query_device_attrib != nullptr &&
            egl.query_device_attrib(handles[i], EGL_CUDA_DEVICE_NV, &cuda)) {
          d.cuda_device = static_cast<int>(cuda);
        }
        out.info.push_back(d);
        out.handles.push_back(handles[i]);
      }
      if (count == 0) out.failure = "EGL lists no device";
    } catch (const RenderError& e) {
      out.failure = e.what();
    }
    return out;
  }();
  return devices;
}

// Why a device's display did not initialise, in words a user can act on where the cause is
// known: a render node the user may not open is the usual one.
std::string DeviceInitFailure(const EglDeviceInfo& device, const std::string& egl_error) {
  std::string text = "its display does not initialise (" + egl_error + ")";
  if (!device.drm_node.empty() && access(device.drm_node.c_str(), R_OK | W_OK) != 0) {
    text += ": " + device.drm_node + " cannot be opened for reading and writing (add the user to the group that owns it, "
            "usually 'render' or 'video')";
  }
  return text;
}

class EglContext final : public OffscreenContext {
 public:
  // device < 0: Mesa's surfaceless platform; else the device platform's device of that index.
  EglContext(int device, int threads, bool with_config_and_pbuffer)
      : OffscreenContext(device < 0 ? GlBackend::kEgl : GlBackend::kEglDevice, device, threads),
        egl_(EglLibrary::Get()) {
    if (egl_.get_platform_display == nullptr) throw RenderError("EGL lacks eglGetPlatformDisplayEXT");
    if (device < 0) {
      if (!HasExtension(egl_.client_extensions.c_str(), "EGL_MESA_platform_surfaceless")) {
        throw RenderError("EGL has no EGL_MESA_platform_surfaceless (not Mesa, or too old)");
      }
      SetThreadsOnce(false, threads);
      display_ = egl_.get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    } else {
      const EglDevices& devices = ListEglDevices();
      if (device >= static_cast<int>(devices.handles.size())) {
        throw RenderError("EGL device " + std::to_string(device) + " does not exist (" +
                          (devices.failure.empty() ? std::to_string(devices.handles.size()) + " listed" : devices.failure) + ")");
      }
      SetThreadsOnce(false, threads);  // read by Mesa's llvmpipe alone; a GPU's driver ignores it
      display_ = egl_.get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices.handles[device], nullptr);
    }
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !egl_.initialize(display_, &major, &minor)) {
      const std::string error = egl_.LastError();
      if (device < 0) throw RenderError("EGL surfaceless display cannot be initialised (error " + error + ")");
      throw RenderError(DeviceInitFailure(ListEglDevices().info[device], error));
    }
    if (!egl_.bind_api(EGL_OPENGL_API)) throw RenderError("EGL cannot bind the desktop OpenGL API (" + egl_.LastError() + ")");
    const char* display_extensions = egl_.query_string(display_, EGL_EXTENSIONS);
    // Configless (EGL_KHR_no_config_context) and surfaceless (EGL_KHR_surfaceless_context): no
    // pbuffer, drawing goes to framebuffer objects. A driver without them gets a chosen config
    // and a 1x1 pbuffer to be current on.
    const bool configless = !with_config_and_pbuffer && (HasExtension(display_extensions, "EGL_KHR_no_config_context") ||
                                                         HasExtension(display_extensions, "EGL_MESA_configless_context"));
    const bool surfaceless = !with_config_and_pbuffer && HasExtension(display_extensions, "EGL_KHR_surfaceless_context");
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!configless || !surfaceless) config = ChooseConfig();
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = egl_.create_context(display_, configless ? EGL_NO_CONFIG_KHR : config, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT) {
      throw RenderError("EGL cannot create an OpenGL 4.5 core context (error " + egl_.LastError() + ")");
    }
    if (!surfaceless) {
      const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      surface_ = egl_.create_pbuffer(display_, config, size);
      if (surface_ == EGL_NO_SURFACE) throw RenderError("EGL cannot create a 1x1 pbuffer (" + egl_.LastError() + ")");
    }
    MakeCurrent();
    LoadApi([this](const char* name) { return reinterpret_cast<void*>(egl_.get_proc(name)); });
  }
  ~EglContext() override {
    if (context_ != EGL_NO_CONTEXT) {
      egl_.make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      egl_.destroy_context(display_, context_);
    }
    if (surface_ != EGL_NO_SURFACE) egl_.destroy_surface(display_, surface_);
    // The display stays initialised: other contexts of this process may share it.
  }
  void ReleaseCurrent() override { egl_.make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }
  void MakeCurrent() override {
    if (!egl_.make_current(display_, surface_, surface_, context_)) {
      throw RenderError("eglMakeCurrent failed (error " + egl_.LastError() + ")");
    }
  }

 private:
  EGLConfig ChooseConfig() const {
    const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                             EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!egl_.choose_config(display_, wanted, &config, 1, &count) || count < 1) {
      throw RenderError("EGL has no desktop-OpenGL config with a pbuffer (" + egl_.LastError() + ")");
    }
    return config;
  }

  const EglLibrary& egl_;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;
};

std::unique_ptr<OffscreenContext> CreateCandidate(const GlCandidate& candidate, const OffscreenOptions& options) {
  switch (candidate.kind) {
    case GlCandidateKind::kOsMesa: return std::make_unique<OsMesaContext>(options.threads);
    case GlCandidateKind::kEglSurfaceless:
      return std::make_unique<EglContext>(-1, options.threads, options.egl_config_and_pbuffer);
    case GlCandidateKind::kEglDevice:
      return std::make_unique<EglContext>(candidate.device, options.threads, options.egl_config_and_pbuffer);
  }
  throw RenderError("unknown GL candidate");
}

bool IsSoftwareRenderer(const std::string& renderer) {
  std::string lower = renderer;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* cpu : {"llvmpipe", "softpipe", "swrast", "software rasterizer"})
    if (lower.find(cpu) != std::string::npos) return true;
  return false;
}

}  // namespace

GlBackend ParseGlBackend(const std::string& name) { return ParseEnum<GlBackend, RenderError>(name, "GL backend"); }

OffscreenContext::OffscreenContext(GlBackend backend, int device, int threads) {
  info_.backend = backend;
  info_.device = device;
  info_.threads = threads;
}

void OffscreenOptions::Check(const OptionNames& names) const {
  // Only auto and egl-device choose among EGL's devices: taken with another, it would be ignored.
  if (device && backend != GlBackend::kAuto && backend != GlBackend::kEglDevice) {
    throw OptionError(names("device") + " " + std::to_string(*device) + " picks an EGL device: it needs " +
                      names("backend") + " auto or egl-device (" + names("backend") + " " + ToString(backend) +
                      " renders without one)");
  }
  RequireOption(threads >= 0, names("threads"), "0 (the calling thread) or more", threads);
}

std::unique_ptr<OffscreenContext> OffscreenContext::Create(const OffscreenOptions& options) {
  options.Check(OptionNames().Nested("gl"));
  const bool uses_devices = options.backend == GlBackend::kAuto || options.backend == GlBackend::kEglDevice;
  const char* environment = std::getenv("ARVIEW_GL_DEVICE");
  const std::optional<int> requested = uses_devices ? RequestedGlDevice(options.device, environment) : std::nullopt;
  const std::string requested_by = options.device ? "--gl-device " + std::to_string(*options.device)
                                   : environment  ? "ARVIEW_GL_DEVICE=" + std::string(environment)
                                                  : "";
  const EglDevices* devices = uses_devices ? &ListEglDevices() : nullptr;
  const std::vector<GlCandidate> plan = PlanGlCandidates(
      options.backend, devices ? devices->info : std::vector<EglDeviceInfo>{}, requested, requested_by);
  std::unique_ptr<OffscreenContext> context;
  std::vector<GlAttempt> attempts;
  try {
    attempts = TryGlCandidates(
        plan, [&](const GlCandidate& c) { context = CreateCandidate(c, options); },
        devices && !devices->failure.empty() ? "no EGL device: " + devices->failure : "");
  } catch (const RenderError& e) {
    if (options.backend != GlBackend::kAuto) throw;
    throw RenderError(std::string(e.what()) + "; install Mesa's libegl-mesa0 or libosmesa6, or a GPU vendor's EGL driver");
  }
  for (const GlAttempt& a : attempts) {
    const bool asked_for = a.candidate.kind == GlCandidateKind::kEglDevice && a.candidate.device == requested;
    if (!a.failure.empty() && options.on_note && (options.verbose || asked_for)) {
      options.on_note(a.candidate.Name() + " not used" + (asked_for ? " (asked for)" : "") + ": " + a.failure);
    }
  }
  context->attempts_ = std::move(attempts);
  return context;
}

void OffscreenContext::LoadApi(const GlProcLoader& loader) {
  gl_ = LoadGlApi(loader, ToString(info_.backend));
  scene_fences_ = std::make_unique<SceneFences>(gl_, SceneFences::Lifetime::kFreedWithTheContext);
  gl_.scene_fences = scene_fences_.get();
  auto text = [this](GLenum name) {
    const GLubyte* s = gl_.GetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  info_.vendor = text(GL_VENDOR);
  info_.renderer = text(GL_RENDERER);
  info_.version = text(GL_VERSION);
  info_.software = IsSoftwareRenderer(info_.renderer);
  if (!info_.software) info_.threads = 0;
}

std::string OffscreenContext::Description() const {
  std::string name = ToString(info_.backend);
  if (info_.device >= 0) name += " " + std::to_string(info_.device);
  std::string text = name + ": " + info_.renderer + " by " + info_.vendor + ", OpenGL " + info_.version;
  if (info_.software) text += ", " + std::to_string(info_.threads) + " llvmpipe threads";
  return text;
}

int OffscreenContext::MaxSamples() const {
  GLint samples = 0;
  gl_.GetIntegerv(GL_MAX_SAMPLES, &samples);
  return samples;
}

GlProbe ProbeGl(const OffscreenOptions& options) {
  GlProbe probe;
  const EglDevices& devices = ListEglDevices();
  probe.egl_failure = devices.failure;
  auto try_create = [&options](const GlCandidate& candidate, std::optional<RendererInfo>* info, std::string* failure) {
    try {
      *info = CreateCandidate(candidate, options)->info();
    } catch (const RenderError& e) {
      *failure = e.what();
    }
  };
  for (const EglDeviceInfo& device : devices.info) {
    GlProbe::Device d{device, std::nullopt, ""};
    try_create({GlCandidateKind::kEglDevice, device.index, device.software()}, &d.renderer, &d.failure);
    probe.devices.push_back(std::move(d));
  }
  try_create({GlCandidateKind::kEglSurfaceless}, &probe.surfaceless, &probe.surfaceless_failure);
  try_create({GlCandidateKind::kOsMesa}, &probe.osmesa, &probe.osmesa_failure);
  try {
    OffscreenOptions automatic = options;
    automatic.backend = GlBackend::kAuto;
    automatic.on_note = nullptr;
    probe.auto_attempts = OffscreenContext::Create(automatic)->attempts();
  } catch (const RenderError& e) {
    probe.auto_failure = e.what();
  }
  return probe;
}

}  // namespace arview::render
