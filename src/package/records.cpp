#include "package/records.hpp"

#include <array>
#include <cstring>
#include <ranges>

#include "core/error.hpp"
#include "core/representatives.hpp"

namespace lodstream::package {

namespace {

// to[k] = from[order[k]], allocated once and copied without value-initialising `to` first (the view's
// iterators are random access because they yield references). Cost: O(order.size()).
template <class T>
void gather(const std::vector<T>& from, std::span<const uint32_t> order, std::vector<T>& to) {
  auto values = std::views::transform(order, [&from](uint32_t v) -> const T& { return from[v]; });
  to.assign(values.begin(), values.end());
}

// gather of positions and normals in one pass over `order`, straight into m's arrays (their capacity kept
// across calls: a caller that extracts into one DecodedNode allocates once): ~9 instructions a vertex for
// both, where two gathers took ~16 (elephant_1m's bench decode: extract_cluster 157.4 -> 149.8 M).
// With `wide` (every entry of `order` below in's last vertex), a vertex a 16-byte load and store each:
// lanes 0-2 are its x y z, lane 3 the next vertex's x, stored into the next place (the arrays' spare entry
// for the last, dropped after), which the next vertex overwrites: 15 -> 11 instructions a vertex (`bench
// decode --runs 1` under callgrind, decode_node: refined_elephant 46.29 -> 46.02 M, elephant_1m 695.8 ->
// 691.9 M). Cost: O(order.size()).
void gather_positions_normals(const Mesh& in, std::span<const uint32_t> order, bool wide, Mesh& m) {
  // resize zero-fills only beyond the size the arrays had.
  m.positions.resize(order.size() + 1), m.normals.resize(order.size() + 1);
  const glm::vec3 *p = in.positions.data(), *q = in.normals.data();
  glm::vec3 *to_p = m.positions.data(), *to_q = m.normals.data();
  if (wide) {
    for (size_t k = 0; k < order.size(); ++k) {
      std::memcpy(to_p + k, p + order[k], 16);
      std::memcpy(to_q + k, q + order[k], 16);
    }
  } else {
    for (size_t k = 0; k < order.size(); ++k) to_p[k] = p[order[k]], to_q[k] = q[order[k]];
  }
  m.positions.pop_back(), m.normals.pop_back();
}

}  // namespace

RecordMesh weld_record(std::span<const Mesh* const> clusters,
                       std::span<const std::span<const uint8_t>> locked) {
  // The clusters' vertices in order are the items of one weld (core/representatives.hpp), each with its key
  // (the bits of position, normal, UV and colour) and the key's hash computed once. (A hash table of nodes
  // cost an allocation per record vertex: 3.2 % of a refined_elephant bake's instructions.)
  using Key = std::array<uint32_t, 12>;
  size_t total = 0, corners = 0;
  for (const Mesh* m : clusters) total += m->vertex_count(), corners += m->indices.size();
  std::vector<Key> keys(total);
  std::vector<uint64_t> hashes(total);
  for (size_t k = 0, i = 0; k < clusters.size(); ++k) {
    const Mesh& m = *clusters[k];
    for (uint32_t v = 0; v < m.vertex_count(); ++v, ++i) {
      Key& key = keys[i];
      std::memcpy(&key[0], &m.positions[v], 12);
      if (m.has_normals()) std::memcpy(&key[3], &m.normals[v], 12);
      if (m.has_uvs()) std::memcpy(&key[6], &m.uvs[v], 8);
      if (m.has_colors()) std::memcpy(&key[8], &m.colors[v], 16);
      // The key as six 64-bit words, each multiplied by its own odd constant (independent products, not
      // one chain of twelve), summed, then mixed so that the low bits depend on all of them.
      uint64_t words[6];
      std::memcpy(words, key.data(), sizeof words);
      uint64_t h = 0;
      for (int w = 0; w < 6; ++w) h += words[w] * (0x9e3779b97f4a7c15ull + 2 * uint64_t(w));
      h ^= h >> 32, h *= 0xff51afd7ed558ccdull;
      hashes[i] = h ^ (h >> 29);
    }
  }
  const std::vector<uint32_t> first = representatives(
      total, [&](size_t i) { return hashes[i]; }, [&](uint32_t a, uint32_t b) { return keys[a] == keys[b]; });

  // Record vertices in order of first appearance: welded[i], item i's record vertex (first[i] <= i, so its
  // representative's is known by then).
  RecordMesh r;
  Mesh& out = r.mesh;
  out.indices.reserve(corners);
  std::vector<uint32_t> welded(total);
  for (size_t k = 0, base = 0; k < clusters.size(); base += clusters[k]->vertex_count(), ++k) {
    const Mesh& m = *clusters[k];
    out.material = m.material;
    for (uint32_t v = 0; v < m.vertex_count(); ++v) {
      const size_t i = base + v;
      if (first[i] == i) {
        welded[i] = uint32_t(out.positions.size());
        out.positions.push_back(m.positions[v]);
        if (m.has_normals()) out.normals.push_back(m.normals[v]);
        if (m.has_uvs()) out.uvs.push_back(m.uvs[v]);
        if (m.has_colors()) out.colors.push_back(m.colors[v]);
        r.locked.push_back(0);
      } else {
        welded[i] = welded[first[i]];
      }
      if (k < locked.size() && !locked[k].empty() && locked[k][v]) r.locked[welded[i]] = 1;
    }
    for (uint32_t v : m.indices) out.indices.push_back(welded[base + v]);
    r.cluster_triangles.push_back(uint32_t(m.triangle_count()));
  }
  return r;
}

DecodedNode extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where) {
  DecodedNode out;
  extract_cluster(record, cluster, where, out);
  return out;
}

void extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where,
                     DecodedNode& out) {
  const uint32_t clusters = record_clusters(record);
  if (cluster >= clusters) {
    throw Error(where + ": cluster " + std::to_string(cluster) + " out of range (its record holds " +
                std::to_string(clusters) + ")");
  }
  if (clusters == 1) {
    out = record;  // copy-assigned: out's buffers reused
    return;
  }
  size_t first = 0;  // the cluster's first triangle
  for (uint32_t c = 0; c < cluster; ++c) first += record.cluster_triangles[c];
  const size_t count = record.cluster_triangles[cluster];
  const Mesh& in = record.mesh;
  // record vertex -> cluster vertex (UINT32_MAX = not used yet); reset after use, so that each call costs
  // O(the cluster), not O(the record).
  thread_local std::vector<uint32_t> compact, used;  // used[cluster vertex] = record vertex
  if (compact.size() < in.positions.size()) compact.resize(in.positions.size(), UINT32_MAX);
  if (used.size() < in.positions.size()) used.resize(in.positions.size());
  Mesh& m = out.mesh;
  m.material = in.material;
  // What the cluster does not hold cleared (capacity kept); the rest overwritten below.
  m.normals.clear(), m.uvs.clear(), m.colors.clear();
  out.first_vertex = 0, out.vertex_data.clear(), out.extra.clear(), out.cluster_triangles.clear();
  // Copied, then renumbered in place: no value-initialisation of a buffer that is overwritten anyway.
  m.indices.assign(in.indices.begin() + std::ptrdiff_t(3 * first),
                   in.indices.begin() + std::ptrdiff_t(3 * (first + count)));  // < V: the codec checked them
  uint32_t* const map = compact.data();
  uint32_t* const first_use = used.data();
  size_t n = 0;
  // Without a branch (which mispredicted at about every first use, a fifth of the corners): first_use[n] is
  // written every time and kept only when v is new. A triangle a step, the count in 64 bits (no zero
  // extension before it indexes): ~15 -> ~12.5 instructions a corner; the loop by pointer, one counter a
  // triangle fewer (`bench decode --runs 1` under callgrind, decode_node: refined_elephant 44.32 -> 44.18 M,
  // elephant_1m 668.4 -> 666.0 M).
  auto renumber = [&](uint32_t& v) {
    const size_t seen = map[v];
    const size_t fresh = seen >> 31;  // 1 for UINT32_MAX (not used yet): cluster vertices are below 2^31
    first_use[n] = v;
    const uint32_t c = uint32_t(fresh ? n : seen);
    map[v] = c, n += fresh;
    v = c;
  };
  for (uint32_t *t = m.indices.data(), *const end = t + 3 * count; t != end; t += 3)
    renumber(t[0]), renumber(t[1]), renumber(t[2]);
  // Whether the cluster leaves the record's last vertex out: its others are followed by 4 bytes of their
  // arrays (gather_positions_normals' wide form).
  const bool wide = !in.positions.empty() && map[in.positions.size() - 1] == UINT32_MAX;
  for (size_t k = 0; k < n; ++k) map[first_use[k]] = UINT32_MAX;  // before anything may throw
  const std::span<const uint32_t> order(first_use, n);
  if (in.has_normals()) {
    gather_positions_normals(in, order, wide, m);
  } else {
    gather(in.positions, order, m.positions);
  }
  if (in.has_uvs()) gather(in.uvs, order, m.uvs);
  if (in.has_colors()) gather(in.colors, order, m.colors);
  if (!record.vertex_data.empty()) gather(record.vertex_data, order, out.vertex_data);
  out.index_end = uint32_t(n);
}

}  // namespace lodstream::package
