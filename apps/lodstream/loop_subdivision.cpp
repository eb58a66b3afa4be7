#include "loop_subdivision.hpp"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>

#include "core/error.hpp"

namespace lodstream::cli {

namespace {
struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3f;
  VertexAttributes(OpenMesh::Attributes::None);
  FaceAttributes(OpenMesh::Attributes::None);
  EdgeAttributes(OpenMesh::Attributes::None);
  HalfedgeAttributes(OpenMesh::Attributes::None);
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;
}  // namespace

Mesh loop_subdivide(const Mesh& mesh, int levels) {
  TriMesh om;
  om.reserve(mesh.positions.size(), mesh.positions.size() * 3, mesh.triangle_count());
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(mesh.positions.size());
  for (const auto& p : mesh.positions) handles.push_back(om.add_vertex(TriMesh::Point(p.x, p.y, p.z)));
  size_t rejected = 0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* v = &mesh.indices[3 * t];
    // OpenMesh refuses faces that would make the mesh non-manifold; they are left out.
    if (!om.add_face(handles[v[0]], handles[v[1]], handles[v[2]]).is_valid()) ++rejected;
  }
  if (rejected * 100 > mesh.triangle_count())
    throw Error("subdivide: " + std::to_string(rejected) +
                " triangles are non-manifold; Loop subdivision needs a manifold mesh");
  OpenMesh::Subdivider::Uniform::LoopT<TriMesh> loop;
  loop.attach(om);
  loop(size_t(levels));
  loop.detach();

  Mesh out;
  out.positions.reserve(om.n_vertices());
  for (auto v : om.vertices()) {
    const auto& p = om.point(v);
    out.positions.push_back({p[0], p[1], p[2]});
  }
  out.indices.reserve(om.n_faces() * 3);
  for (auto f : om.faces())
    for (auto v : om.fv_range(f)) out.indices.push_back(uint32_t(v.idx()));
  return out;
}

}  // namespace lodstream::cli
