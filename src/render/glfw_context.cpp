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
    glfwSetWindowUserPointer(window_, this);
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
      static_cast<GlfwContext*>(glfwGetWindowUserPointer(w))->scroll_ += dy;
    });
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
    scroll_ = 0.0;
    glfwPollEvents();
    auto held = [&](int a, int b = GLFW_KEY_UNKNOWN) {
      return glfwGetKey(window_, a) == GLFW_PRESS ||
             (b != GLFW_KEY_UNKNOWN && glfwGetKey(window_, b) == GLFW_PRESS);
    };
    input_ = WindowInput{};
    input_.forward = held(GLFW_KEY_W, GLFW_KEY_UP);
    input_.back = held(GLFW_KEY_S, GLFW_KEY_DOWN);
    input_.left = held(GLFW_KEY_A, GLFW_KEY_LEFT);
    input_.right = held(GLFW_KEY_D, GLFW_KEY_RIGHT);
    input_.down = held(GLFW_KEY_Q);
    input_.up = held(GLFW_KEY_E);
    input_.fast = held(GLFW_KEY_LEFT_SHIFT, GLFW_KEY_RIGHT_SHIFT);
    input_.quit = held(GLFW_KEY_ESCAPE);
    input_.scroll = scroll_;
    double x = 0.0, y = 0.0;
    glfwGetCursorPos(window_, &x, &y);
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && dragging_) {
      input_.look_x = x - cursor_x_;
      input_.look_y = y - cursor_y_;
    }
    dragging_ = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    cursor_x_ = x;
    cursor_y_ = y;
    return !glfwWindowShouldClose(window_);
  }
  WindowInput input() const override { return input_; }
  std::pair<int, int> framebuffer_size() const override {
    int width = 0, height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    return {width, height};
  }
  void set_title(const std::string& title) override { glfwSetWindowTitle(window_, title.c_str()); }

 private:
  GLFWwindow* window_ = nullptr;
  WindowInput input_;
  double scroll_ = 0.0;  // wheel steps during the current poll_events()
  double cursor_x_ = 0.0, cursor_y_ = 0.0;
  bool dragging_ = false;
};

}  // namespace

std::unique_ptr<WindowContext> create_window_context(int width, int height, const std::string& title,
                                                     bool visible) {
  return std::make_unique<GlfwContext>(width, height, title, visible);
}

}  // namespace lodstream::render
