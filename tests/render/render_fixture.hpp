// Shared by the render tests: one headless context for the whole test program, and small image helpers.
#pragma once

#include <glm/glm.hpp>

#include "core/camera.hpp"
#include "core/image.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"

namespace lodstream::test {

// The process's headless context (created on first use; llvmpipe without a GPU).
render::Context& headless_context();

Camera camera_at(glm::vec3 eye, glm::vec3 target, int width, int height, float fov_y_degrees = 60.0f);

bool is_background(const Image& image, int x, int y);
size_t covered_pixels(const Image& image);

// The pixel (column, row from the top) where `world` projects for `camera`.
glm::ivec2 project_to_pixel(const Camera& camera, glm::vec3 world);

}  // namespace lodstream::test
