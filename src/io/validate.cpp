#include "io/validate.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace lodstream {

ValidationCounts validate_mesh(Mesh& mesh, const std::string& what) {
  ValidationCounts counts;
  const size_t nv = mesh.positions.size();
  if ((!mesh.normals.empty() && mesh.normals.size() != nv) || (!mesh.uvs.empty() && mesh.uvs.size() != nv) ||
      (!mesh.colors.empty() && mesh.colors.size() != nv))
    throw Error(what + ": attribute arrays differ in length from the " + std::to_string(nv) + " positions");
  if (mesh.indices.size() % 3 != 0) throw Error(what + ": index count is not a multiple of 3");
  for (size_t v = 0; v < nv; ++v) {
    const glm::vec3& p = mesh.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(what + ": vertex " + std::to_string(v) + " has a non-finite coordinate (" +
                  std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
  }
  for (const auto& n : mesh.normals)
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z) ||
        (n.x == 0 && n.y == 0 && n.z == 0)) {
      mesh.normals.clear();
      counts.dropped_normals = true;
      break;
    }
  for (size_t v = 0; v < mesh.uvs.size(); ++v)
    if (!std::isfinite(mesh.uvs[v].x) || !std::isfinite(mesh.uvs[v].y))
      throw Error(what + ": vertex " + std::to_string(v) + " has a non-finite texture coordinate");
  for (size_t v = 0; v < mesh.colors.size(); ++v)
    if (!std::isfinite(mesh.colors[v].r) || !std::isfinite(mesh.colors[v].g) ||
        !std::isfinite(mesh.colors[v].b) || !std::isfinite(mesh.colors[v].a))
      throw Error(what + ": vertex " + std::to_string(v) + " has a non-finite colour");

  size_t out = 0;
  for (size_t t = 0; t < mesh.indices.size() / 3; ++t) {
    const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
    if (a >= nv || b >= nv || c >= nv)
      throw Error(what + ": triangle " + std::to_string(t) + " references vertex " +
                  std::to_string(std::max({a, b, c})) + ", but there are only " + std::to_string(nv) +
                  " vertices");
    const glm::dvec3 pa(mesh.positions[a]), pb(mesh.positions[b]), pc(mesh.positions[c]);
    const glm::dvec3 cross = glm::cross(pb - pa, pc - pa);
    if (pa == pb || pb == pc || pa == pc || (cross.x == 0 && cross.y == 0 && cross.z == 0)) {
      ++counts.degenerate_triangles;
      continue;
    }
    mesh.indices[3 * out] = a;
    mesh.indices[3 * out + 1] = b;
    mesh.indices[3 * out + 2] = c;
    ++out;
  }
  mesh.indices.resize(3 * out);
  return counts;
}

}  // namespace lodstream
