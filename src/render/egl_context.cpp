// Headless OpenGL through EGL: the device platform (every EGL device, GPUs before Mesa's software device),
// then Mesa's surfaceless platform. Both are asked for explicitly with eglGetPlatformDisplayEXT, so the
// result does not depend on the EGL_PLATFORM environment variable (eglGetDisplay(EGL_DEFAULT_DISPLAY) would
// need it without X).
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

#include "core/error.hpp"
#include "render/context.hpp"

namespace lodstream::render {

const char* platform_name(EglPlatform platform) {
  return platform == EglPlatform::device ? "egl-device" : "egl-surfaceless";
}

std::string Context::renderer() const {
  const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return s ? s : "";
}

std::string Context::version() const {
  const auto* s = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return s ? s : "";
}

namespace {

std::string egl_error_text(EGLint code) {
  const char* name = "unknown";
  switch (code) {
    case EGL_SUCCESS:
      name = "EGL_SUCCESS";
      break;
    case EGL_NOT_INITIALIZED:
      name = "EGL_NOT_INITIALIZED";
      break;
    case EGL_BAD_ACCESS:
      name = "EGL_BAD_ACCESS";
      break;
    case EGL_BAD_ALLOC:
      name = "EGL_BAD_ALLOC";
      break;
    case EGL_BAD_ATTRIBUTE:
      name = "EGL_BAD_ATTRIBUTE";
      break;
    case EGL_BAD_CONFIG:
      name = "EGL_BAD_CONFIG";
      break;
    case EGL_BAD_CONTEXT:
      name = "EGL_BAD_CONTEXT";
      break;
    case EGL_BAD_DISPLAY:
      name = "EGL_BAD_DISPLAY";
      break;
    case EGL_BAD_MATCH:
      name = "EGL_BAD_MATCH";
      break;
    case EGL_BAD_PARAMETER:
      name = "EGL_BAD_PARAMETER";
      break;
    case EGL_BAD_SURFACE:
      name = "EGL_BAD_SURFACE";
      break;
  }
  char code_text[16];
  std::snprintf(code_text, sizeof code_text, "0x%04X", unsigned(code));
  return std::string(name) + " " + code_text;
}

// Thrown inside this file when one display cannot give a context; create_headless_context() collects them.
struct Attempt {
  std::string reason;
};

[[noreturn]] void fail(const char* call) {
  throw Attempt{std::string(call) + " failed (" + egl_error_text(eglGetError()) + ")"};
}

// EGL hands out one EGLDisplay per device (or platform) per process and eglTerminate() is not
// reference-counted, so contexts sharing a display count its users and the last one terminates it.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

// One user of a display: initialises it for the first user, terminates it after the last.
class DisplayUse {
 public:
  explicit DisplayUse(EGLDisplay display) : display_(display) {
    std::lock_guard lock(display_mutex);
    EGLint major = 0, minor = 0;
    if (display_users[display_] == 0 && !eglInitialize(display_, &major, &minor)) {
      display_users.erase(display_);
      fail("eglInitialize");
    }
    ++display_users[display_];
  }
  ~DisplayUse() {
    std::lock_guard lock(display_mutex);
    if (--display_users[display_] == 0) {
      display_users.erase(display_);
      eglTerminate(display_);
    }
  }
  DisplayUse(const DisplayUse&) = delete;
  DisplayUse& operator=(const DisplayUse&) = delete;
  EGLDisplay get() const { return display_; }

 private:
  EGLDisplay display_;
};

class EglContext final : public Context {
 public:
  EglContext(EGLDisplay display, std::string platform) : display_(display), platform_(std::move(platform)) {
    if (!epoxy_has_egl_extension(display, "EGL_KHR_surfaceless_context"))
      throw Attempt{"display lacks EGL_KHR_surfaceless_context"};
    if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI(EGL_OPENGL_API)");
    const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(display, config_attributes, &config, 1, &configs)) fail("eglChooseConfig");
    if (configs == 0) throw Attempt{"no EGL config renders OpenGL"};
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         4,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
    context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context_ == EGL_NO_CONTEXT) fail("eglCreateContext(OpenGL 4.5 core)");
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      std::string reason = "eglMakeCurrent failed (" + egl_error_text(eglGetError()) + ")";
      eglDestroyContext(display, context_);
      throw Attempt{reason};
    }
  }

  ~EglContext() override {
    eglMakeCurrent(display_.get(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_.get(), context_);
  }

  void make_current() override {
    if (!eglMakeCurrent(display_.get(), EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error(platform_ + ": eglMakeCurrent failed (" + egl_error_text(eglGetError()) + ")");
  }

  std::string platform() const override { return platform_; }

 private:
  DisplayUse display_;  // first member: released last, and released when the constructor throws
  std::string platform_;
  EGLContext context_ = EGL_NO_CONTEXT;
};

// A context from one display; the display's failure reason is appended to `tried` on failure.
std::unique_ptr<Context> try_display(EGLDisplay display, const std::string& platform, std::string& reason) {
  if (display == EGL_NO_DISPLAY) {
    reason = "eglGetPlatformDisplayEXT failed (" + egl_error_text(eglGetError()) + ")";
    return nullptr;
  }
  try {
    return std::make_unique<EglContext>(display, platform);
  } catch (const Attempt& a) {
    reason = a.reason;
    return nullptr;
  }
}

std::unique_ptr<Context> try_devices(std::string& reason) {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_device_enumeration") ||
      !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_device")) {
    reason = "EGL lacks EGL_EXT_device_enumeration / EGL_EXT_platform_device";
    return nullptr;
  }
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count == 0) {
    reason = "eglQueryDevicesEXT found no device (" + egl_error_text(eglGetError()) + ")";
    return nullptr;
  }
  std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
  eglQueryDevicesEXT(count, devices.data(), &count);
  // Hardware devices first: Mesa lists its software rasterizer as a device with EGL_MESA_device_software.
  auto is_software = [](EGLDeviceEXT d) {
    const char* ext = eglQueryDeviceStringEXT(d, EGL_EXTENSIONS);
    return ext && std::strstr(ext, "EGL_MESA_device_software");
  };
  std::stable_partition(devices.begin(), devices.end(), [&](EGLDeviceEXT d) { return !is_software(d); });
  std::string reasons;
  for (size_t i = 0; i < devices.size(); ++i) {
    std::string why;
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (auto context = try_display(display, platform_name(EglPlatform::device), why)) return context;
    reasons += (reasons.empty() ? "" : ", ") + ("device " + std::to_string(i) + ": " + why);
  }
  reason = reasons;
  return nullptr;
}

std::unique_ptr<Context> try_surfaceless(std::string& reason) {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
    reason = "EGL lacks EGL_MESA_platform_surfaceless";
    return nullptr;
  }
  EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  return try_display(display, platform_name(EglPlatform::surfaceless), reason);
}

}  // namespace

std::unique_ptr<Context> create_headless_context(const std::vector<EglPlatform>& order) {
  std::string tried;
  for (EglPlatform platform : order) {
    std::string reason;
    auto context = platform == EglPlatform::device ? try_devices(reason) : try_surfaceless(reason);
    if (context) return context;
    tried += (tried.empty() ? "" : "; ") + std::string(platform_name(platform)) + ": " + reason;
  }
  if (order.empty()) tried = "no platform was asked for";
  throw Error("cannot create an OpenGL 4.5 core context (tried " + tried +
              "; without a GPU EGL needs Mesa's libgl1-mesa-dri)");
}

}  // namespace lodstream::render
