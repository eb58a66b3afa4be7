// Window contexts through GLFW 3.3 (X11). GLFW is initialised on the first window and terminated with the
// last.
#include <epoxy/gl.h>
// GLFW after epoxy, and without its own GL header, so that epoxy alone declares the GL functions.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <mutex>

#include "core/error.hpp"
#include "render/context.hpp"

namespace lodstream::render {

namespace {

std::mutex glfw_mutex;
int glfw_windows = 0;  // windows alive; GLFW is initialised while this is positive

std::string glfw_reason() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown GLFW error";
}

class GlfwContext final : public WindowContext {
 public:
  GlfwContext(int width, int height, const std::string& title, bool visible) {
    std::lock_guard lock(glfw_mutex);
    if (glfw_windows == 0 && !glfwInit()) throw Error("cannot open a window: " + glfw_reason());
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
      std::string reason = glfw_reason();
      if (glfw_windows == 0) glfwTerminate();
      throw Error("cannot open a " + std::to_string(width) + "x" + std::to_string(height) +
                  " OpenGL 4.5 core window: " + reason);
    }
    ++glfw_windows;
    glfwMakeContextCurrent(window_);
  }

  ~GlfwContext() override {
    std::lock_guard lock(glfw_mutex);
    glfwDestroyWindow(window_);
    if (--glfw_windows == 0) glfwTerminate();
  }

  void make_current() override { glfwMakeContextCurrent(window_); }
  std::string platform() const override { return "glfw"; }
  void swap_buffers() override { glfwSwapBuffers(window_); }
  bool poll_events() override {
    glfwPollEvents();
    return !glfwWindowShouldClose(window_);
  }

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace

std::unique_ptr<WindowContext> create_window_context(int width, int height, const std::string& title,
                                                     bool visible) {
  return std::make_unique<GlfwContext>(width, height, title, visible);
}

}  // namespace lodstream::render
