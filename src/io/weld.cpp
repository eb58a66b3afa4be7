#include "io/weld.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <vector>

namespace lodstream {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// Float bits with -0 folded into +0, so that equal values hash and compare equal.
inline uint32_t bits(float f) {
  return std::bit_cast<uint32_t>(f + 0.0f);
}

inline uint64_t mix(uint64_t h, uint32_t v) {
  h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h;
}

inline uint64_t finalize(uint64_t h) {  // splitmix64 finalizer
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebull;
  return h ^ (h >> 31);
}

// Which attributes take part in a vertex's identity.
struct VertexKey {
  const Mesh& mesh;
  bool normals, uvs, colors;
  uint64_t hash(uint32_t v) const {
    const glm::vec3& p = mesh.positions[v];
    uint64_t h = mix(mix(mix(0, bits(p.x)), bits(p.y)), bits(p.z));
    if (normals)
      h = mix(mix(mix(h, bits(mesh.normals[v].x)), bits(mesh.normals[v].y)), bits(mesh.normals[v].z));
    if (uvs) h = mix(mix(h, bits(mesh.uvs[v].x)), bits(mesh.uvs[v].y));
    if (colors)
      for (int k = 0; k < 4; ++k) h = mix(h, bits(mesh.colors[v][k]));
    return finalize(h);
  }
  bool equal(uint32_t a, uint32_t b) const {
    auto same3 = [](const glm::vec3& x, const glm::vec3& y) {
      return bits(x.x) == bits(y.x) && bits(x.y) == bits(y.y) && bits(x.z) == bits(y.z);
    };
    if (!same3(mesh.positions[a], mesh.positions[b])) return false;
    if (normals && !same3(mesh.normals[a], mesh.normals[b])) return false;
    if (uvs && (bits(mesh.uvs[a].x) != bits(mesh.uvs[b].x) || bits(mesh.uvs[a].y) != bits(mesh.uvs[b].y)))
      return false;
    if (colors)
      for (int k = 0; k < 4; ++k)
        if (bits(mesh.colors[a][k]) != bits(mesh.colors[b][k])) return false;
    return true;
  }
};

// For every vertex, the first vertex equal to it under `key` (open addressing, linear probing, load <= 0.5).
std::vector<uint32_t> representatives(const VertexKey& key, size_t n) {
  size_t capacity = 16;
  while (capacity < 2 * n) capacity *= 2;
  std::vector<uint32_t> table(capacity, kNone);
  std::vector<uint32_t> rep(n);
  const size_t mask = capacity - 1;
  for (uint32_t v = 0; v < n; ++v) {
    size_t slot = key.hash(v) & mask;
    for (;;) {
      uint32_t e = table[slot];
      if (e == kNone) {
        table[slot] = v;
        rep[v] = v;
        break;
      }
      if (key.equal(e, v)) {
        rep[v] = e;
        break;
      }
      slot = (slot + 1) & mask;
    }
  }
  return rep;
}

// Keeps the vertices listed in `keep` order; `remap[old]` gives each old vertex's new index.
void compact(Mesh& mesh, const std::vector<uint32_t>& keep) {
  auto pick = [&keep](auto& array) {
    if (array.empty()) return;
    std::remove_reference_t<decltype(array)> out(keep.size());
    for (size_t i = 0; i < keep.size(); ++i) out[i] = array[keep[i]];
    array.swap(out);
  };
  pick(mesh.positions);
  pick(mesh.normals);
  pick(mesh.uvs);
  pick(mesh.colors);
}

void weld_by(Mesh& mesh, const VertexKey& key) {
  const size_t n = mesh.positions.size();
  std::vector<uint32_t> rep = representatives(key, n);
  // Renumber in order of first use by a triangle, which also drops unreferenced vertices.
  std::vector<uint32_t> new_index(n, kNone);
  std::vector<uint32_t> keep;
  keep.reserve(n);
  for (uint32_t& i : mesh.indices) {
    uint32_t r = rep[i];
    if (new_index[r] == kNone) {
      new_index[r] = static_cast<uint32_t>(keep.size());
      keep.push_back(r);
    }
    i = new_index[r];
  }
  if (keep.size() == n) {
    bool identity = true;
    for (size_t i = 0; i < n && identity; ++i) identity = keep[i] == i;
    if (identity) return;
  }
  compact(mesh, keep);
}

}  // namespace

void weld_identical(Mesh& mesh) {
  weld_by(mesh, VertexKey{mesh, mesh.has_normals(), mesh.has_uvs(), mesh.has_colors()});
}

void weld_with_crease_normals(Mesh& mesh, float crease_angle_degrees) {
  mesh.normals.clear();
  weld_by(mesh, VertexKey{mesh, false, mesh.has_uvs(), mesh.has_colors()});
  const size_t nv = mesh.positions.size(), nt = mesh.triangle_count(), nc = mesh.indices.size();

  // Position classes: vertices that differ only in UV or colour share a normal.
  std::vector<uint32_t> position = representatives(VertexKey{mesh, false, false, false}, nv);

  // Face normals: unnormalized (area-weighted) for the sums, unit for the crease test.
  std::vector<glm::vec3> face(nt), unit(nt);
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t* v = &mesh.indices[3 * t];
    face[t] =
        glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]], mesh.positions[v[2]] - mesh.positions[v[0]]);
    float len = glm::length(face[t]);
    unit[t] = len > 0 ? face[t] / len : glm::vec3(0.0f);
  }

  // Corners grouped by position class (counting sort).
  std::vector<uint32_t> start(nv + 1, 0), corners(nc);
  for (uint32_t i : mesh.indices) ++start[position[i] + 1];
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t c = 0; c < nc; ++c) corners[fill[position[mesh.indices[c]]]++] = c;
  }

  // Crease groups per position: corner_group[c] is a global group id, group_sum its normal sum.
  const float cos_crease = std::cos(glm::radians(crease_angle_degrees));
  std::vector<uint32_t> corner_group(nc);
  std::vector<glm::vec3> group_sum;
  std::vector<uint32_t> seeds;  // seed triangle of each group of the current position
  for (size_t p = 0; p < nv; ++p) {
    if (start[p] == start[p + 1]) continue;
    const uint32_t first_group = static_cast<uint32_t>(group_sum.size());
    seeds.clear();
    for (uint32_t k = start[p]; k < start[p + 1]; ++k) {
      const uint32_t c = corners[k], t = c / 3;
      size_t g = 0;
      while (g < seeds.size() && glm::dot(unit[seeds[g]], unit[t]) < cos_crease) ++g;
      if (g == seeds.size()) {
        seeds.push_back(t);
        group_sum.push_back(glm::vec3(0.0f));
      }
      corner_group[c] = first_group + static_cast<uint32_t>(g);
      group_sum[first_group + g] += face[t];
    }
  }

  // One output vertex per (welded vertex, crease group); most vertices have one group, kept in flat arrays,
  // the few extra (vertices on a crease) in a hash map.
  std::vector<uint32_t> slot_group(nv, kNone), slot_vertex(nv, kNone);
  std::unordered_map<uint64_t, uint32_t> extra;
  std::vector<uint32_t> keep;
  std::vector<glm::vec3> normals;
  keep.reserve(nv);
  normals.reserve(nv);
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t w = mesh.indices[c], g = corner_group[c];
    uint32_t out;
    if (slot_group[w] == g) {
      out = slot_vertex[w];
    } else {
      uint32_t* found = nullptr;
      if (slot_group[w] != kNone) {
        auto [it, inserted] = extra.try_emplace((uint64_t(w) << 32) | g, kNone);
        found = &it->second;
        if (!inserted) {
          mesh.indices[c] = it->second;
          continue;
        }
      }
      out = static_cast<uint32_t>(keep.size());
      keep.push_back(w);
      float len = glm::length(group_sum[g]);
      normals.push_back(len > 0 ? group_sum[g] / len : glm::vec3(0.0f, 0.0f, 1.0f));
      if (found) {
        *found = out;
      } else {
        slot_group[w] = g;
        slot_vertex[w] = out;
      }
    }
    mesh.indices[c] = out;
  }
  compact(mesh, keep);
  mesh.normals = std::move(normals);
}

WeldResult weld(Mesh& mesh, float crease_angle_degrees) {
  WeldResult r;
  r.vertices_before = mesh.vertex_count();
  weld_identical(mesh);
  // Mean triangles per vertex is 3T/V: about 6 on a shared-vertex surface, 1 when every triangle has its own.
  const bool flat = mesh.has_normals() && 3 * mesh.triangle_count() < 2 * mesh.vertex_count();
  if (!mesh.has_normals() || flat) {
    weld_with_crease_normals(mesh, crease_angle_degrees);
    r.normals_recomputed = true;
  }
  r.vertices_after = mesh.vertex_count();
  return r;
}

}  // namespace lodstream
