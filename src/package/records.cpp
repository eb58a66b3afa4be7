#include "package/records.hpp"

#include <array>
#include <cstring>
#include <ranges>
#include <unordered_map>

#include "core/error.hpp"

namespace lodstream::package {

namespace {

// to[k] = from[order[k]], allocated once and copied without value-initialising `to` first (the view's
// iterators are random access because they yield references). Cost: O(order.size()).
template <class T>
void gather(const std::vector<T>& from, std::span<const uint32_t> order, std::vector<T>& to) {
  auto values = std::views::transform(order, [&from](uint32_t v) -> const T& { return from[v]; });
  to.assign(values.begin(), values.end());
}

}  // namespace

RecordMesh weld_record(std::span<const Mesh* const> clusters,
                       std::span<const std::span<const uint8_t>> locked) {
  using Key = std::array<uint32_t, 12>;  // the bits of position, normal, UV and colour
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = 0x9e3779b97f4a7c15ull;
      for (uint32_t x : k) h = (h ^ x) * 0xff51afd7ed558ccdull;
      return size_t(h ^ (h >> 32));
    }
  };
  RecordMesh r;
  Mesh& out = r.mesh;
  std::unordered_map<Key, uint32_t, KeyHash> welded;
  std::vector<uint32_t> remap;
  std::vector<uint8_t> seen;
  for (size_t k = 0; k < clusters.size(); ++k) {
    const Mesh& m = *clusters[k];
    out.material = m.material;
    remap.resize(m.vertex_count());
    for (uint32_t v = 0; v < m.vertex_count(); ++v) {
      Key key{};
      std::memcpy(&key[0], &m.positions[v], 12);
      if (m.has_normals()) std::memcpy(&key[3], &m.normals[v], 12);
      if (m.has_uvs()) std::memcpy(&key[6], &m.uvs[v], 8);
      if (m.has_colors()) std::memcpy(&key[8], &m.colors[v], 16);
      const auto [it, added] = welded.emplace(key, uint32_t(out.positions.size()));
      remap[v] = it->second;
      if (added) {
        out.positions.push_back(m.positions[v]);
        if (m.has_normals()) out.normals.push_back(m.normals[v]);
        if (m.has_uvs()) out.uvs.push_back(m.uvs[v]);
        if (m.has_colors()) out.colors.push_back(m.colors[v]);
        r.locked.push_back(0);
      }
      if (k < locked.size() && !locked[k].empty() && locked[k][v]) r.locked[remap[v]] = 1;
    }
    seen.assign(out.positions.size(), 0);
    uint32_t distinct = 0;
    for (uint32_t i : m.indices) {
      out.indices.push_back(remap[i]);
      distinct += seen[remap[i]] == 0, seen[remap[i]] = 1;
    }
    r.cluster_vertices.push_back(distinct);
    r.cluster_triangles.push_back(uint32_t(m.triangle_count()));
  }
  return r;
}

DecodedNode extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where) {
  const uint32_t clusters = record_clusters(record);
  if (cluster >= clusters) {
    throw Error(where + ": cluster " + std::to_string(cluster) + " out of range (its record holds " +
                std::to_string(clusters) + ")");
  }
  if (clusters == 1) return record;
  size_t first = 0;  // the cluster's first triangle
  for (uint32_t c = 0; c < cluster; ++c) first += record.cluster_triangles[c];
  const size_t count = record.cluster_triangles[cluster];
  const Mesh& in = record.mesh;
  // record vertex -> cluster vertex (UINT32_MAX = not used yet); reset after use, so that each call costs
  // O(the cluster), not O(the record).
  thread_local std::vector<uint32_t> compact, used;  // used[cluster vertex] = record vertex
  if (compact.size() < in.positions.size()) compact.resize(in.positions.size(), UINT32_MAX);
  if (used.size() < in.positions.size()) used.resize(in.positions.size());
  DecodedNode out;
  Mesh& m = out.mesh;
  m.material = in.material;
  // Copied, then renumbered in place: no value-initialisation of a buffer that is overwritten anyway.
  m.indices.assign(in.indices.begin() + std::ptrdiff_t(3 * first),
                   in.indices.begin() + std::ptrdiff_t(3 * (first + count)));  // < V: the codec checked them
  uint32_t* const map = compact.data();
  uint32_t* const first_use = used.data();
  size_t n = 0;
  // Without a branch (which mispredicted at about every first use, a fifth of the corners): first_use[n] is
  // written every time and kept only when v is new. A triangle a step, the count in 64 bits (no zero
  // extension before it indexes): ~15 -> ~12.5 instructions a corner.
  auto renumber = [&](uint32_t& v) {
    const size_t seen = map[v];
    const size_t fresh = seen >> 31;  // 1 for UINT32_MAX (not used yet): cluster vertices are below 2^31
    first_use[n] = v;
    const uint32_t c = uint32_t(fresh ? n : seen);
    map[v] = c, n += fresh;
    v = c;
  };
  uint32_t* const corners = m.indices.data();
  for (size_t i = 0; i < 3 * count; i += 3)
    renumber(corners[i]), renumber(corners[i + 1]), renumber(corners[i + 2]);
  for (size_t k = 0; k < n; ++k) map[first_use[k]] = UINT32_MAX;  // before anything may throw
  const std::span<const uint32_t> order(first_use, n);
  gather(in.positions, order, m.positions);
  if (in.has_normals()) gather(in.normals, order, m.normals);
  if (in.has_uvs()) gather(in.uvs, order, m.uvs);
  if (in.has_colors()) gather(in.colors, order, m.colors);
  if (!record.vertex_data.empty()) gather(record.vertex_data, order, out.vertex_data);
  out.index_end = uint32_t(n);
  return out;
}

}  // namespace lodstream::package
