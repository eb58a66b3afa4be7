#include "render_fixture.hpp"

#include <cmath>
#include <memory>

namespace lodstream::test {

render::Context& headless_context() {
  static std::unique_ptr<render::Context> context = render::create_headless_context();
  context->make_current();
  return *context;
}

Camera camera_at(glm::vec3 eye, glm::vec3 target, int width, int height, float fov_y_degrees) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.width = width;
  c.height = height;
  c.fov_y_degrees = fov_y_degrees;
  return c;
}

bool is_background(const Image& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  for (int i = 0; i < 4; ++i)
    if (p[i] != render::kBackground[size_t(i)]) return false;
  return true;
}

size_t covered_pixels(const Image& image) {
  size_t n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) n += is_background(image, x, y) ? 0 : 1;
  return n;
}

glm::ivec2 project_to_pixel(const Camera& camera, glm::vec3 world) {
  glm::vec4 clip = camera.projection(0.1f, 100.0f) * camera.view() * glm::vec4(world, 1.0f);
  glm::vec2 ndc = glm::vec2(clip) / clip.w;
  return {int(std::floor((ndc.x * 0.5f + 0.5f) * float(camera.width))),
          int(std::floor((0.5f - ndc.y * 0.5f) * float(camera.height)))};
}

}  // namespace lodstream::test
