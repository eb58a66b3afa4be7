#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render_fixture.hpp"
#include "support/shapes.hpp"
#include "support/xvfb.hpp"

using namespace lodstream;
using namespace lodstream::render;

namespace {

std::pair<int, int> gl_version() {
  int major = 0, minor = 0;
  std::string v = test::headless_context().version();
  std::sscanf(v.c_str(), "%d.%d", &major, &minor);
  return {major, minor};
}

Image render_sphere(Context& context) {
  Renderer renderer(context);
  DrawItem item{renderer.upload_mesh(test::sphere(1.0f, 24, 48)), glm::mat4(1.0f), {}};
  renderer.draw(test::camera_at({0.5f, 1, 4}, {0, 0, 0}, 80, 60), std::span(&item, 1));
  return renderer.read_pixels();
}

// The same GL implementation draws bit-identical images whatever the context; a different one (a GPU's device
// platform next to Mesa's surfaceless one) draws the same shape, so the covered areas agree closely.
void expect_same_image(const Image& a, const std::string& renderer_a, const Image& b,
                       const std::string& renderer_b) {
  const double covered = double(test::covered_pixels(a));
  EXPECT_GT(covered, 100.0);
  if (renderer_a == renderer_b)
    EXPECT_EQ(a.rgba, b.rgba) << renderer_a;
  else
    EXPECT_NEAR(double(test::covered_pixels(b)), covered, 0.02 * covered)
        << renderer_a << " vs " << renderer_b;
}

}  // namespace

TEST(Context, HeadlessGivesOpenGL45Core) {
  auto [major, minor] = gl_version();
  EXPECT_GE(major * 10 + minor, 45) << test::headless_context().version();
  EXPECT_FALSE(test::headless_context().renderer().empty());
  std::printf("headless context: %s, %s, %s\n", test::headless_context().platform().c_str(),
              test::headless_context().renderer().c_str(), test::headless_context().version().c_str());
}

TEST(Context, NeedsNoEglPlatformVariable) {
  unsetenv("EGL_PLATFORM");
  auto context = create_headless_context();
  EXPECT_FALSE(context->renderer().empty());
}

TEST(Context, EachEglPlatformWorksAndDrawsTheSameImage) {
  auto device = create_headless_context({EglPlatform::device});
  EXPECT_EQ(device->platform(), "egl-device");
  Image a = render_sphere(*device);
  auto surfaceless = create_headless_context({EglPlatform::surfaceless});
  EXPECT_EQ(surfaceless->platform(), "egl-surfaceless");
  Image b = render_sphere(*surfaceless);
  expect_same_image(a, device->renderer(), b, surfaceless->renderer());
}

TEST(Context, NoPlatformIsAClearError) {
  try {
    create_headless_context({});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create an OpenGL 4.5 core context"), std::string::npos);
  }
}

TEST(WindowContext, WithoutDisplayIsAClearError) {
  const char* display = std::getenv("DISPLAY");
  std::string saved = display ? display : "";
  unsetenv("DISPLAY");
  try {
    create_window_context(64, 64, "test", false);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("DISPLAY"), std::string::npos) << e.what();
  }
  if (display) setenv("DISPLAY", saved.c_str(), 1);
}

TEST(WindowContext, UnderXvfbDrawsWhatHeadlessDraws) {
  test::Xvfb server;
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start (scripts/setup installs xvfb)";
  setenv("DISPLAY", server.display().c_str(), 1);
  Image windowed;
  std::string window_renderer;
  {
    auto window = create_window_context(80, 60, "lodstream test", false);
    EXPECT_EQ(window->platform(), "glfw");
    EXPECT_TRUE(window->poll_events());
    windowed = render_sphere(*window);
    window->swap_buffers();
    window_renderer = window->renderer();
  }
  unsetenv("DISPLAY");
  expect_same_image(windowed, window_renderer, render_sphere(test::headless_context()),
                    test::headless_context().renderer());
}
