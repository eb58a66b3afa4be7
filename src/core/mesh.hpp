// Indexed triangle mesh with optional per-vertex attributes: the one mesh type every module exchanges.
// Attribute arrays are either empty (absent) or exactly as long as `positions`. A vertex is a unique
// combination of attributes: where two vertices share a position but differ in normal or UV, that is a seam.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/bounds.hpp"

namespace lodstream {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // unit length, or empty
  std::vector<glm::vec2> uvs;      // texture coordinates of the base-colour texture, or empty
  std::vector<glm::vec4> colors;   // linear RGBA in [0,1], or empty
  std::vector<uint32_t> indices;   // three per triangle, counter-clockwise front faces
  uint32_t material = 0;           // index into Scene::materials

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
  bool has_normals() const { return !normals.empty(); }
  bool has_uvs() const { return !uvs.empty(); }
  bool has_colors() const { return !colors.empty(); }
  Bounds bounds() const { return Bounds::of(positions); }
};

// Area-weighted smooth vertex normals from the triangles (replaces `normals`). Cost: O(V + T).
void compute_smooth_normals(Mesh& mesh);

// Twice the area of triangle t (the length of its cross product).
float triangle_double_area(const Mesh& mesh, size_t t);

}  // namespace lodstream
