#include "support/shapes.hpp"

#include <cmath>
#include <glm/gtc/constants.hpp>

namespace lodstream::test {

namespace {
Mesh sphere_impl(float r, int rings, int segments, bool with_uvs) {
  Mesh m;
  // With UVs each ring has segments + 1 vertices: the first and last share a position (the UV seam).
  const int ring_verts = with_uvs ? segments + 1 : segments;
  m.positions.push_back({0, r, 0});
  m.normals.push_back({0, 1, 0});
  if (with_uvs) m.uvs.push_back({0.5f, 1.0f});
  for (int i = 1; i < rings; ++i) {
    float theta = glm::pi<float>() * float(i) / float(rings);
    for (int j = 0; j < ring_verts; ++j) {
      float phi = 2.0f * glm::pi<float>() * float(j % segments) / float(segments);
      glm::vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
      m.positions.push_back(n * r);
      m.normals.push_back(n);
      if (with_uvs) m.uvs.push_back({float(j) / float(segments), 1.0f - float(i) / float(rings)});
    }
  }
  const uint32_t south = uint32_t(m.positions.size());
  m.positions.push_back({0, -r, 0});
  m.normals.push_back({0, -1, 0});
  if (with_uvs) m.uvs.push_back({0.5f, 0.0f});
  auto ring = [&](int i, int j) {
    return uint32_t(1 + (i - 1) * ring_verts + (with_uvs ? j : j % segments));
  };
  for (int j = 0; j < segments; ++j) {
    m.indices.insert(m.indices.end(), {0u, ring(1, j + 1), ring(1, j)});
    m.indices.insert(m.indices.end(), {south, ring(rings - 1, j), ring(rings - 1, j + 1)});
  }
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      uint32_t a = ring(i, j), b = ring(i, j + 1), c = ring(i + 1, j), d = ring(i + 1, j + 1);
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  return m;
}
}  // namespace

Mesh sphere(float r, int rings, int segments) {
  return sphere_impl(r, rings, segments, false);
}
Mesh uv_sphere(float r, int rings, int segments) {
  return sphere_impl(r, rings, segments, true);
}

Mesh grid(int n, float z0) {
  Mesh m;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      m.positions.push_back({float(x) / float(n), float(y) / float(n), z0});
      m.normals.push_back({0, 0, 1});
    }
  auto at = [n](int x, int y) { return uint32_t(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      m.indices.insert(m.indices.end(),
                       {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
  return m;
}

Mesh cube_with_seams(int s) {
  Mesh m;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      glm::vec3 n(0.0f);
      n[axis] = float(sign);
      // u, v span the face so that u x v = n (counter-clockwise seen from outside).
      glm::vec3 u(0.0f), v(0.0f);
      u[(axis + 1) % 3] = 1.0f;
      v[(axis + 2) % 3] = 1.0f;
      if (sign < 0) std::swap(u, v);
      uint32_t base = uint32_t(m.positions.size());
      for (int j = 0; j <= s; ++j)
        for (int i = 0; i <= s; ++i) {
          float a = -1.0f + 2.0f * float(i) / float(s), b = -1.0f + 2.0f * float(j) / float(s);
          m.positions.push_back(n + a * u + b * v);
          m.normals.push_back(n);
        }
      auto at = [&](int i, int j) { return base + uint32_t(j * (s + 1) + i); };
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i)
          m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j),
                                             at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

Mesh non_manifold() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}, {0.5f, 0, 1},  // fan of 3 on edge 0-1
                 {2, 0, 0}, {3, 1, 0}, {3, -1, 0},   {1, 1, 1},     {1, -1, 1}};   // bowtie at vertex 1
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 1, 5, 6, 1, 7, 5, 1, 8, 9};
  return m;
}

}  // namespace lodstream::test
