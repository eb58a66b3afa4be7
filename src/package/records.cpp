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

// Resizes `v` to n entries without value-initialising new ones: they are copied from `junk` (at least
// n - v.size() entries, which the caller overwrites next), one memmove where resize stored each glm::vec3
// alone (~5 instructions an entry, and a caller that extracts clusters of varying sizes into one DecodedNode
// grows its arrays at about every other call: elephant_1m's `bench decode --runs 1` under callgrind spent
// 14.0 M instructions there). Cost: O(the growth).
template <class T>
void resize_for_overwrite(std::vector<T>& v, size_t n, const T* junk) {
  if (v.size() >= n)
    v.resize(n);  // shrinking writes nothing
  else
    v.insert(v.end(), junk, junk + (n - v.size()));
}

// m.positions[k] = in.positions[order[k]] and likewise the normals, in one pass over `order` that also
// resets map[order[k]] to UINT32_MAX (extract_cluster's table, left as it found it, where a loop of its own
// took ~2.6 instructions a vertex more); m's arrays sized first (their capacity kept across calls: a caller
// that extracts into one DecodedNode allocates once), the only step that may throw, after which the map is
// reset too. Two gathers took ~16 instructions a vertex (elephant_1m's bench decode: extract_cluster 157.4 ->
// 149.8 M). With `wide` (every entry of `order` below in's last vertex), a vertex a 16-byte load and store
// each: lanes 0-2 are its x y z, lane 3 the next vertex's x, stored into the next place (the arrays' spare
// entry for the last, dropped after), which the next vertex overwrites: ~11 instructions a vertex with the
// reset (`bench decode --runs 1` under callgrind, elephant_1m: 17.6 M for 1.59 M vertices); two vertices a
// step, ~9 (motorBike: extract_cluster 21.12 -> 20.42 M, with its callees). Cost: O(order.size()).
void gather_positions_normals(const Mesh& in, std::span<const uint32_t> order, bool wide, uint32_t* map,
                              Mesh& m) {
  const size_t n = order.size() + (wide ? 1 : 0);  // wide: n <= in's vertices, as `order` leaves one out
  try {
    resize_for_overwrite(m.positions, n, in.positions.data());
    resize_for_overwrite(m.normals, n, in.normals.data());
  } catch (...) {
    for (uint32_t v : order) map[v] = UINT32_MAX;
    throw;
  }
  const glm::vec3 *p = in.positions.data(), *q = in.normals.data();
  glm::vec3 *to_p = m.positions.data(), *to_q = m.normals.data();
  if (wide) {
#pragma GCC unroll 2
    for (size_t k = 0; k < order.size(); ++k) {
      const uint32_t v = order[k];
      std::memcpy(to_p + k, p + v, 16);
      std::memcpy(to_q + k, q + v, 16);
      map[v] = UINT32_MAX;
    }
    m.positions.pop_back(), m.normals.pop_back();
  } else {
    for (size_t k = 0; k < order.size(); ++k) {
      const uint32_t v = order[k];
      to_p[k] = p[v], to_q[k] = q[v], map[v] = UINT32_MAX;
    }
  }
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

void cluster_firsts(const DecodedNode& record, std::vector<size_t>& firsts) {
  firsts.resize(record_clusters(record));
  size_t first = 0;
  for (size_t c = 0; c < firsts.size(); ++c) {
    firsts[c] = first;
    if (c < record.cluster_triangles.size()) first += record.cluster_triangles[c];
  }
}

void extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where,
                     DecodedNode& out) {
  thread_local std::vector<size_t> firsts;
  cluster_firsts(record, firsts);
  extract_cluster(record, cluster, cluster < firsts.size() ? firsts[cluster] : 0, where, out);
}

void extract_cluster(const DecodedNode& record, uint32_t cluster, size_t first, const std::string& where,
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
  const size_t count = record.cluster_triangles[cluster];
  const Mesh& in = record.mesh;
  if (first > in.triangle_count() || count > in.triangle_count() - first)
    throw Error(where + ": cluster " + std::to_string(cluster) + " ends past its record's triangles");
  // record vertex -> cluster vertex (UINT32_MAX = not used yet); reset after use, so that each call costs
  // O(the cluster), not O(the record).
  thread_local std::vector<uint32_t> compact, used;  // used[cluster vertex] = record vertex
  if (compact.size() < in.positions.size()) compact.resize(in.positions.size(), UINT32_MAX);
  if (used.size() < in.positions.size()) used.resize(in.positions.size());
  Mesh& m = out.mesh;
  m.material = in.material;
  // What the cluster does not hold cleared (capacity kept); the rest overwritten below (positions and normals
  // resized without clearing: only their growth is written twice).
  if (!in.has_normals()) m.normals.clear();
  m.uvs.clear(), m.colors.clear();
  out.first_vertex = 0, out.vertex_data.clear(), out.extra.clear(), out.cluster_triangles.clear();
  // Sized without value-initialisation (only its growth copied first), then each index renumbered from the
  // record's (< V: the codec checked them) into it: no copy of the indices before the renumbering (`bench
  // decode --runs 1` under callgrind: elephant_1m's memcpy from extract_cluster 3.28 M instructions).
  const uint32_t* const from = in.indices.data() + 3 * first;
  resize_for_overwrite(m.indices, 3 * count, from);
  uint32_t* const map = compact.data();
  uint32_t* const first_use = used.data();
  size_t n = 0;
  const uint32_t V = uint32_t(in.positions.size());
  // The last corner of each triangle without a branch (which mispredicted at about every first use, a
  // fifth of the corners): first_use[n] is written every time and kept only when v is new. A triangle a
  // step, the count in 64 bits (no zero extension before it indexes): ~15 -> ~12.5 instructions a corner; the
  // loop by pointer, one counter a triangle fewer (`bench decode --runs 1` under callgrind, decode_node:
  // refined_elephant 44.32 -> 44.18 M, elephant_1m 668.4 -> 666.0 M). first_use written before the look-up:
  // GCC 12 then keeps no copy of v, 11 -> 10 instructions a corner (elephant_1m: extract_cluster 113.5 ->
  // 106.4 M). A new vertex told by a compare with V (GCC 12: cmp, cmov, sbb; seen >> 31 took a copy and a
  // shift for the compare): 10 -> 9 (motorBike: extract_cluster 23.66 -> 21.12 M, with its callees).
  // Tried: the number as min(seen, n) and n += (seen > n) (a compare, cmov and adc), as few instructions, but
  // n's chain through the compare and the adc is two cycles a corner where this one's is one: the extraction
  // alone took 1.3-1.8 % longer (two runs of 12 interleaved pairs, 20 passes over elephant_1m's records
  // each, thread CPU time). A byte a vertex marking its first use, so that the compare does not wait on the
  // map's store of n: 1.22x the time (motorBike and refined_elephant, the same kind of pairs).
  auto renumber = [&](uint32_t v) {
    first_use[n] = v;
    const uint32_t seen = map[v];
    const bool fresh = seen >= V;  // UINT32_MAX (not used yet): cluster vertices are below V
    const uint32_t c = fresh ? uint32_t(n) : seen;
    map[v] = c, n += fresh;
    return c;
  };
  // The first two corners looked up first: in a decoded record a triangle rarely meets a vertex new to its
  // cluster there (the traversal's kVertex triangle is (b, a, c) with c new: 5 % of the triangles at corner
  // 0 and 5 % at corner 1, 60 % at corner 2, on motorBike, refined_elephant and elephant_1m), so one branch
  // a triangle, taken by 7-8 % of them, leaves both as they are, without the stores of a first use, and only
  // the last corner is renumbered. Two triangles a step. `bench decode --runs 1` under callgrind,
  // extract_cluster with its callees: motorBike 20.42 -> 17.94 M instructions (~9.7 -> ~8.1 a corner),
  // refined_elephant 5.74 -> 5.05 M; the extraction alone 0.92x, 0.82x and 0.86x the time (motorBike,
  // refined_elephant, elephant_1m: medians of 31-101 interleaved pairs over every record's clusters, thread
  // CPU time).
  const uint32_t* f = from;
#pragma GCC unroll 2
  for (uint32_t *t = m.indices.data(), *const end = t + 3 * count; t != end; t += 3, f += 3) {
    uint32_t c0 = map[f[0]], c1 = map[f[1]];
    if (int32_t(c0 | c1) < 0) [[unlikely]]  // either UINT32_MAX: new to the cluster
      c0 = renumber(f[0]), c1 = renumber(f[1]);
    t[0] = c0, t[1] = c1, t[2] = renumber(f[2]);
  }
  // Whether the cluster leaves the record's last vertex out: its others are followed by 4 bytes of their
  // arrays (gather_positions_normals' wide form).
  const bool wide = !in.positions.empty() && map[in.positions.size() - 1] == UINT32_MAX;
  const std::span<const uint32_t> order(first_use, n);
  if (in.has_normals()) {
    gather_positions_normals(in, order, wide, map, m);  // resets the map
  } else {
    for (size_t k = 0; k < n; ++k) map[first_use[k]] = UINT32_MAX;  // before anything may throw
    gather(in.positions, order, m.positions);
  }
  if (in.has_uvs()) gather(in.uvs, order, m.uvs);
  if (in.has_colors()) gather(in.colors, order, m.colors);
  if (!record.vertex_data.empty()) gather(record.vertex_data, order, out.vertex_data);
  out.index_end = uint32_t(n);
}

}  // namespace lodstream::package
