// Totally ordered meshes: the build and traversal rules of the seed 002 digest (§2.3 BUILD_TOM, §2.5
// DEATH_FROM_CHAINS and TRAVERSE). Hand-written: no Debian library builds TOMs.
#include "simplify/progressive.hpp"

#include <algorithm>
#include <numeric>

namespace lodstream::simplify {
namespace {

constexpr uint32_t kNone = UINT32_MAX;
constexpr uint64_t kNever = 0;  // death key of base triangles: they sort first

// The vertex index whose removal degenerates triangle (a, b, c), plus one; kNever when it survives
// (DEATH_FROM_CHAINS: substitute the largest corner until two corners meet).
uint64_t death_key(const std::vector<uint32_t>& parent, uint32_t a, uint32_t b, uint32_t c) {
  for (;;) {
    uint32_t m = std::max({a, b, c});
    if (parent[m] == kNone) return kNever;
    uint32_t to = parent[m];
    if (a == m) a = to;
    if (b == m) b = to;
    if (c == m) c = to;
    if (a == b || b == c || a == c) return uint64_t(m) + 1;
  }
}

uint32_t resolve(const std::vector<uint32_t>& parent, uint32_t x, size_t nv) {
  while (x >= nv) x = parent[x];
  return x;
}

}  // namespace

ProgressiveMesh build_progressive(const Mesh& mesh, Options options) {
  options.half_edge = true;
  options.record_collapses = true;
  Result r = simplify_mesh(mesh, options);

  // The welded mesh the collapses refer to: welded vertex w takes the attributes of its first input vertex.
  const size_t n_in = mesh.vertex_count();
  size_t n_welded = 0;
  for (uint32_t w : r.weld_remap) n_welded = std::max<size_t>(n_welded, size_t(w) + 1);
  std::vector<uint32_t> source(n_welded, kNone);
  for (uint32_t v = 0; v < n_in; ++v)
    if (source[r.weld_remap[v]] == kNone) source[r.weld_remap[v]] = v;
  std::vector<uint32_t> tris;
  std::vector<uint8_t> used(n_welded, 0);
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (a >= n_in || b >= n_in || c >= n_in) continue;
    a = r.weld_remap[a], b = r.weld_remap[b], c = r.weld_remap[c];
    if (a == b || b == c || a == c) continue;
    tris.insert(tris.end(), {a, b, c});
    used[a] = used[b] = used[c] = 1;
  }

  // Vertex order: used base vertices first (input order), then u_s at V - 1 - s.
  std::vector<uint8_t> removed(n_welded, 0);
  for (const Collapse& c : r.collapses) removed[c.removed] = 1;
  std::vector<uint32_t> order;  // new index -> welded vertex
  for (uint32_t w = 0; w < n_welded; ++w)
    if (used[w] && !removed[w]) order.push_back(w);
  ProgressiveMesh pm;
  pm.base_vertices = order.size();
  for (auto it = r.collapses.rbegin(); it != r.collapses.rend(); ++it) order.push_back(it->removed);
  const size_t V = order.size();
  std::vector<uint32_t> new_index(n_welded, kNone);
  for (uint32_t i = 0; i < V; ++i) new_index[order[i]] = i;

  pm.parent.assign(V, kNone);
  pm.error.assign(V, 0.0f);
  pm.boundary.assign(V, 1);
  for (const Collapse& c : r.collapses) {
    pm.parent[new_index[c.removed]] = new_index[c.kept];
    pm.error[new_index[c.removed]] = c.error_bound;
  }
  // u_s sits at V - 1 - s: a seam collapse's second record is the vertex just below its first.
  for (size_t s = 1; s < r.collapses.size(); ++s)
    if (r.collapses[s].step == r.collapses[s - 1].step) pm.boundary[V - s] = 0;

  Mesh& out = pm.mesh;
  out.material = mesh.material;
  for (uint32_t w : order) {
    uint32_t v = source[w];
    out.positions.push_back(mesh.positions[v]);
    if (mesh.has_normals()) out.normals.push_back(mesh.normals[v]);
    if (mesh.has_uvs()) out.uvs.push_back(mesh.uvs[v]);
    if (mesh.has_colors()) out.colors.push_back(mesh.colors[v]);
  }

  // Triangle order: stable by death, survivors first.
  const size_t T = tris.size() / 3;
  std::vector<uint64_t> key(T);
  for (size_t t = 0; t < T; ++t) {
    for (int k = 0; k < 3; ++k) tris[3 * t + k] = new_index[tris[3 * t + k]];
    key[t] = death_key(pm.parent, tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]);
  }
  std::vector<uint32_t> by_death(T);
  std::iota(by_death.begin(), by_death.end(), 0u);
  std::stable_sort(by_death.begin(), by_death.end(), [&](uint32_t x, uint32_t y) { return key[x] < key[y]; });
  out.indices.resize(tris.size());
  for (size_t i = 0; i < T; ++i)
    for (int k = 0; k < 3; ++k) out.indices[3 * i + k] = tris[3 * size_t(by_death[i]) + k];
  return pm;
}

size_t vertex_count_for(const ProgressiveMesh& pm, size_t max_triangles) {
  const auto& idx = pm.mesh.indices;
  if (max_triangles >= pm.mesh.triangle_count()) return pm.mesh.vertex_count();
  // Triangle `max_triangles` (0-based) and every later one are dead below its death vertex.
  uint64_t k =
      death_key(pm.parent, idx[3 * max_triangles], idx[3 * max_triangles + 1], idx[3 * max_triangles + 2]);
  return std::max(pm.base_vertices, k == kNever ? pm.base_vertices : size_t(k - 1));
}

size_t triangle_count_for(const ProgressiveMesh& pm, size_t vertex_count) {
  const size_t nv = std::clamp(vertex_count, pm.base_vertices, pm.mesh.vertex_count());
  const auto& idx = pm.mesh.indices;
  // Triangles are sorted by death key; those alive with nv vertices have a key <= nv.
  size_t lo = 0, hi = pm.mesh.triangle_count();
  while (lo < hi) {
    const size_t mid = (lo + hi) / 2;
    if (death_key(pm.parent, idx[3 * mid], idx[3 * mid + 1], idx[3 * mid + 2]) <= nv)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

Mesh extract(const ProgressiveMesh& pm, size_t vertex_count) {
  const size_t nv = std::clamp(vertex_count, pm.base_vertices, pm.mesh.vertex_count());
  const Mesh& m = pm.mesh;
  Mesh out;
  out.material = m.material;
  out.positions.assign(m.positions.begin(), m.positions.begin() + nv);
  if (m.has_normals()) out.normals.assign(m.normals.begin(), m.normals.begin() + nv);
  if (m.has_uvs()) out.uvs.assign(m.uvs.begin(), m.uvs.begin() + nv);
  if (m.has_colors()) out.colors.assign(m.colors.begin(), m.colors.begin() + nv);
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    uint32_t a = resolve(pm.parent, m.indices[3 * t], nv), b = resolve(pm.parent, m.indices[3 * t + 1], nv),
             c = resolve(pm.parent, m.indices[3 * t + 2], nv);
    if (a == b || b == c || a == c) break;  // the first dead triangle: every later one is dead too
    out.indices.insert(out.indices.end(), {a, b, c});
  }
  return out;
}

}  // namespace lodstream::simplify
