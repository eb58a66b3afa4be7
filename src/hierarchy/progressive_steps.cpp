#include "hierarchy/progressive_steps.hpp"

#include <meshoptimizer.h>

#include <algorithm>

#include "hierarchy/bounding_sphere.hpp"
#include "simplify/progressive.hpp"

namespace lodstream::hierarchy {

namespace {

// The step ends (vertex counts v_1 < v_2 < ... = V) of the header's rule.
std::vector<size_t> step_ends(const simplify::ProgressiveMesh& pm, const StepOptions& options) {
  const size_t V = pm.mesh.vertex_count();
  std::vector<size_t> ends{pm.base_vertices};
  while (ends.back() < V) {
    const size_t nv = ends.back(), t = simplify::triangle_count_for(pm, nv);
    const size_t add = std::clamp(t, options.min_step_triangles, options.max_step_triangles);
    size_t next = std::max(simplify::vertex_count_for(pm, t + add), nv + 1);
    while (next < V && !pm.boundary[next]) ++next;  // never between a seam collapse's two wedges
    ends.push_back(next);
  }
  return ends;
}

}  // namespace

ProgressiveSteps build_progressive_steps(const Mesh& mesh, const StepOptions& options) {
  ProgressiveSteps out;
  if (mesh.triangle_count() == 0) return out;
  const simplify::ProgressiveMesh pm = simplify::build_progressive(mesh, options.simplify);
  const Mesh& m = pm.mesh;
  const size_t V = m.vertex_count();
  if (V == 0 || m.triangle_count() == 0) return out;  // nothing left after welding
  out.vertices = uint32_t(V);
  out.sphere = sphere_of_points(m.positions);
  out.base = simplify::extract(pm, pm.base_vertices);
  const std::vector<size_t> ends = step_ends(pm, options);
  std::vector<uint8_t> carried(V, 0);
  size_t first_vertex = 0, first_triangle = 0;
  for (size_t end : ends) {
    ProgressiveStep& s = out.steps.emplace_back();
    const size_t t_end = simplify::triangle_count_for(pm, end);
    s.first_vertex = uint32_t(first_vertex);
    s.first_triangle = uint32_t(first_triangle);
    s.error = end < V ? pm.error[end] : 0.0f;
    s.mesh.material = m.material;
    auto part = [&](const auto& all, auto& dst) {
      if (!all.empty()) dst.assign(all.begin() + first_vertex, all.begin() + end);
    };
    part(m.positions, s.mesh.positions);
    part(m.normals, s.mesh.normals);
    part(m.uvs, s.mesh.uvs);
    part(m.colors, s.mesh.colors);
    // Inside a step the triangle order is free (a prefix ends at a step's end): meshopt's vertex-cache order,
    // which its index codec compresses best.
    s.mesh.indices.resize(3 * (t_end - first_triangle));
    meshopt_optimizeVertexCache(s.mesh.indices.data(), m.indices.data() + 3 * first_triangle,
                                s.mesh.indices.size(), V);
    for (uint32_t c : s.mesh.indices)
      for (uint32_t x = c; x >= end && !carried[x]; x = pm.parent[x]) {
        carried[x] = 1;
        s.chains.push_back({x, pm.parent[x]});
      }
    std::sort(s.chains.begin(), s.chains.end());
    first_vertex = end, first_triangle = t_end;
  }
  return out;
}

}  // namespace lodstream::hierarchy
