// OpenGL contexts: where the renderer's GL calls go. A headless context (EGL, no window, no X) for the
// command line, tests and benchmarks; a window context (GLFW) for the interactive viewer. Both give
// OpenGL 4.5 core and are current on the creating thread until destroyed. GL functions are resolved through
// libepoxy.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace lodstream::render {

// The EGL platforms a headless context can come from, in the order create_headless_context() tries them.
enum class EglPlatform {
  device,  // EGL_EXT_platform_device over eglQueryDevicesEXT: real GPUs first, then Mesa's software device
  surfaceless,  // EGL_MESA_platform_surfaceless (Mesa llvmpipe without a GPU)
};

const char* platform_name(EglPlatform platform);

class Context {
 public:
  virtual ~Context() = default;
  Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  // Makes this context current on the calling thread (it already is after creation).
  virtual void make_current() = 0;
  // How the context was made, e.g. "egl-device", "egl-surfaceless", "glfw".
  virtual std::string platform() const = 0;

  // GL_RENDERER and GL_VERSION of the current context ("llvmpipe (LLVM 15.0.6, 256 bits)" without a GPU).
  std::string renderer() const;
  std::string version() const;
};

// An offscreen OpenGL 4.5 core context with no default framebuffer (draw into framebuffer objects). Tries
// each platform of `order` in turn and returns the first that gives a context; on a machine with a GPU the
// device platform finds it, without one Mesa's software device (llvmpipe). Needs no environment variable
// (EGL_PLATFORM is not read). Throws lodstream::Error, one line naming every platform tried and EGL's error
// code for each, when none does. Cost: 30-60 ms with llvmpipe.
std::unique_ptr<Context> create_headless_context(const std::vector<EglPlatform>& order = {
                                                     EglPlatform::device, EglPlatform::surfaceless});

// What a fly camera reads of the keyboard and mouse (window_input()): keys held now, and what accumulated
// since the previous poll_events().
struct WindowInput {
  bool forward = false, back = false, left = false, right = false;  // W S A D (or the arrow keys)
  bool down = false, up = false;                                    // Q E
  bool fast = false;                                                // a Shift key
  bool quit = false;                                                // Escape
  double look_x = 0.0, look_y = 0.0;  // cursor motion while the left mouse button is held, pixels
  double scroll = 0.0;                // wheel steps (positive: away from the user)
};

// A window of width x height pixels (hidden when `visible` is false) with an OpenGL 4.5 core context, through
// GLFW (X11; needs DISPLAY). Throws lodstream::Error with GLFW's reason when no window can be made.
class WindowContext : public Context {
 public:
  // Presents the back buffer (the frame drawn into framebuffer 0).
  virtual void swap_buffers() = 0;
  // Processes pending window events; returns false once the user asked to close the window.
  virtual bool poll_events() = 0;
  // The input as of the last poll_events() (motion and scroll since the one before).
  virtual WindowInput input() const = 0;
  // The default framebuffer's size in pixels (what to draw at; it follows the window's size).
  virtual std::pair<int, int> framebuffer_size() const = 0;
  virtual void set_title(const std::string& title) = 0;
};

std::unique_ptr<WindowContext> create_window_context(int width, int height, const std::string& title,
                                                     bool visible = true);

}  // namespace lodstream::render
