#include "glcontext/gl_context.h"
#include "glcontext/gl_program.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <atomic>
#include <map>
#include <cstdio>
#include <cstring>

#include "common/error.h"
#include "common/log.h"

namespace irbake {

namespace {

const char* kHint = " (use --backend embree to bake without OpenGL)";

[[noreturn]] void fail(const std::string& message) {
  throw Error(ErrorCode::Gl, "", "OpenGL unavailable: " + message + kHint);
}

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string hex(unsigned v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", v);
  return buf;
}

}  // namespace

const char* toString(EglPlatform platform) {
  return platform == EglPlatform::Surfaceless ? "EGL surfaceless" : "EGL device";
}

struct GlContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EglPlatform platform = EglPlatform::Surfaceless;
  std::string renderer, version, vendor;
  std::atomic<int> messages{0}, errors{0};
  std::unique_ptr<GlProgramCache> programs = std::make_unique<GlProgramCache>();
  std::map<std::string, std::shared_ptr<void>> resources;

  static void GLAPIENTRY onDebug(GLenum /*source*/, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                 const GLchar* message, const void* user) {
    auto* self = static_cast<Impl*>(const_cast<void*>(user));
    ++self->messages;
    if (type == GL_DEBUG_TYPE_ERROR) ++self->errors;
    std::string text = "GL [" + hex(id) + "] " + std::string(message, length < 0 ? std::strlen(message) : length);
    if (severity == GL_DEBUG_SEVERITY_HIGH || type == GL_DEBUG_TYPE_ERROR)
      log::warn(text);
    else
      log::debug(text);
  }

  // Opens and initialises a display on one platform; returns EGL_NO_DISPLAY (and why) on failure.
  EGLDisplay open(EglPlatform p, std::string& why) {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!hasExtension(client, "EGL_EXT_platform_base") && !hasExtension(client, "EGL_KHR_platform_base")) {
      why = "EGL has no platform_base extension";
      return EGL_NO_DISPLAY;
    }
    std::vector<EGLDisplay> candidates;
    if (p == EglPlatform::Surfaceless) {
      if (!hasExtension(client, "EGL_MESA_platform_surfaceless")) {
        why = "no EGL_MESA_platform_surfaceless";
        return EGL_NO_DISPLAY;
      }
      candidates.push_back(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
    } else {
      if (!hasExtension(client, "EGL_EXT_device_enumeration") && !hasExtension(client, "EGL_EXT_device_base")) {
        why = "no EGL_EXT_device_enumeration";
        return EGL_NO_DISPLAY;
      }
      EGLint count = 0;
      EGLDeviceEXT devices[16];
      if (!eglQueryDevicesEXT(16, devices, &count) || count == 0) {
        why = "no EGL device";
        return EGL_NO_DISPLAY;
      }
      // Devices in enumeration order (GPUs usually first); the first that initialises wins.
      for (EGLint i = 0; i < count; ++i)
        candidates.push_back(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
    }
    for (EGLDisplay d : candidates) {
      if (d == EGL_NO_DISPLAY) continue;
      EGLint major = 0, minor = 0;
      if (!eglInitialize(d, &major, &minor)) continue;
      const char* ext = eglQueryString(d, EGL_EXTENSIONS);
      if (!hasExtension(ext, "EGL_KHR_surfaceless_context")) {
        eglTerminate(d);
        why = "display lacks EGL_KHR_surfaceless_context";
        continue;
      }
      return d;
    }
    if (why.empty()) why = "eglInitialize failed (" + hex(eglGetError()) + ")";
    return EGL_NO_DISPLAY;
  }

  EGLContext create(EGLDisplay d, const GlContextOptions& o, std::string& why) {
    if (!eglBindAPI(EGL_OPENGL_API)) {
      why = "eglBindAPI(EGL_OPENGL_API) failed";
      return EGL_NO_CONTEXT;
    }
    EGLConfig config = nullptr;
    const char* ext = eglQueryString(d, EGL_EXTENSIONS);
    if (!hasExtension(ext, "EGL_KHR_no_config_context")) {
      const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLint n = 0;
      if (!eglChooseConfig(d, want, &config, 1, &n) || n < 1) {
        why = "no EGL config with OpenGL";
        return EGL_NO_CONTEXT;
      }
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, o.glMajor,
                              EGL_CONTEXT_MINOR_VERSION, o.glMinor,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_CONTEXT_OPENGL_DEBUG, o.debugContext ? EGL_TRUE : EGL_FALSE,
                              EGL_NONE};
    EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, attribs);
    if (c == EGL_NO_CONTEXT)
      why = "no OpenGL " + std::to_string(o.glMajor) + "." + std::to_string(o.glMinor) + " core context (" +
            hex(eglGetError()) + ")";
    return c;
  }
};

GlContext::GlContext(const GlContextOptions& options) : impl_(std::make_unique<Impl>()) {
  if (options.platforms.empty()) fail("no EGL platform allowed");
  std::string reasons;
  for (EglPlatform p : options.platforms) {
    std::string why;
    EGLDisplay d = impl_->open(p, why);
    if (d != EGL_NO_DISPLAY) {
      EGLContext c = impl_->create(d, options, why);
      if (c != EGL_NO_CONTEXT) {
        impl_->display = d;
        impl_->context = c;
        impl_->platform = p;
        break;
      }
      eglTerminate(d);
    }
    reasons += std::string(reasons.empty() ? "" : "; ") + toString(p) + ": " + why;
  }
  if (impl_->context == EGL_NO_CONTEXT) fail(reasons);
  makeCurrent();
  auto str = [](GLenum e) {
    const GLubyte* s = glGetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  impl_->renderer = str(GL_RENDERER);
  impl_->version = str(GL_VERSION);
  impl_->vendor = str(GL_VENDOR);
  if (epoxy_gl_version() < options.glMajor * 10 + options.glMinor) {
    const std::string have = impl_->version;
    eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl_->display, impl_->context);
    impl_->context = EGL_NO_CONTEXT;
    fail("OpenGL " + have + " is older than " + std::to_string(options.glMajor) + "." +
         std::to_string(options.glMinor));
  }
  if (options.routeDebugMessages &&
      (epoxy_gl_version() >= 43 || epoxy_has_gl_extension("GL_KHR_debug"))) {
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);  // messages arrive on the calling thread, with the failing call
    glDebugMessageCallback(&Impl::onDebug, impl_.get());
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
  }
  log::debug("GL context: " + description());
}

GlContext::~GlContext() {
  if (!impl_ || impl_->display == EGL_NO_DISPLAY) return;
  if (((impl_->programs && impl_->programs->size() > 0) || !impl_->resources.empty()) &&
      impl_->context != EGL_NO_CONTEXT) {
    // Resources and programs are deleted on this context; whatever context the thread had current is restored.
    const EGLContext previous = eglGetCurrentContext();
    const EGLDisplay previousDisplay = eglGetCurrentDisplay();
    const EGLSurface draw = eglGetCurrentSurface(EGL_DRAW), read = eglGetCurrentSurface(EGL_READ);
    if (previous != impl_->context) eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context);
    impl_->resources.clear();
    impl_->programs.reset();
    if (previous != impl_->context && previous != EGL_NO_CONTEXT) eglMakeCurrent(previousDisplay, draw, read, previous);
  }
  if (eglGetCurrentContext() == impl_->context) {
    if (impl_->context != EGL_NO_CONTEXT) glDebugMessageCallback(nullptr, nullptr);
    eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  if (impl_->context != EGL_NO_CONTEXT) eglDestroyContext(impl_->display, impl_->context);
  // The display is not terminated: EGL displays are per-process singletons, and terminating one
  // would pull it away from another GlContext (the viewer and a bake) alive on it.
}

GlProgramCache& GlContext::programs() const { return *impl_->programs; }

std::shared_ptr<void>& GlContext::resource(const std::string& key) const { return impl_->resources[key]; }

void GlContext::makeCurrent() const {
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context))
    throw Error(ErrorCode::Gl, "", "eglMakeCurrent failed (" + hex(eglGetError()) + ")");
}

const std::string& GlContext::renderer() const { return impl_->renderer; }
const std::string& GlContext::version() const { return impl_->version; }
const std::string& GlContext::vendor() const { return impl_->vendor; }
EglPlatform GlContext::platform() const { return impl_->platform; }
std::string GlContext::description() const {
  return impl_->renderer + " | " + impl_->version + " | " + toString(impl_->platform);
}
bool GlContext::softwareRenderer() const {
  for (const char* s : {"llvmpipe", "softpipe", "swrast", "SwiftShader"})
    if (impl_->renderer.find(s) != std::string::npos) return true;
  return false;
}
int GlContext::debugMessageCount() const { return impl_->messages; }
int GlContext::debugErrorCount() const { return impl_->errors; }

void checkGlError(const char* what) {
  GLenum first = glGetError();
  if (first == GL_NO_ERROR) return;
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
  }
  throw Error(ErrorCode::Gl, "", std::string(what) + ": GL error " + hex(first));
}

}  // namespace irbake
