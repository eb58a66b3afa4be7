#include "io/weld.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "core/counting_sort.hpp"
#include "core/prefault.hpp"
#include "core/representatives.hpp"

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

// For every vertex, the first vertex equal to it under `key` (core/representatives.hpp, on every core), its
// hashes computed once (they are looked up three times).
std::vector<uint32_t> representatives(const VertexKey& key, size_t n) {
  auto hashes = std::make_unique_for_overwrite<uint64_t[]>(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v < r.end(); ++v) hashes[v] = key.hash(uint32_t(v));
  });
  return lodstream::representatives(
      n, [&hashes](size_t v) { return hashes[v]; },
      [&key](uint32_t a, uint32_t b) { return key.equal(a, b); });
}

// Keeps the vertices listed in `keep` order; `remap[old]` gives each old vertex's new index. Gathers on
// every core. The arrays allocated here and below are prefaulted (core/prefault.hpp): their zero-fill was
// most of the serial part of importing elephant_5m.
void compact(Mesh& mesh, const std::vector<uint32_t>& keep) {
  auto pick = [&keep](auto& array) {
    if (array.empty()) return;
    std::remove_reference_t<decltype(array)> out;
    resize_prefaulted(out, keep.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, keep.size(), 1 << 14),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i < r.end(); ++i) out[i] = array[keep[i]];
                      });
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
  std::vector<uint32_t> new_index, keep;
  resize_prefaulted(new_index, n, kNone);
  reserve_prefaulted(keep, n);
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

// Flat shading: in at least 90% of the triangles the three corners carry one and the same normal, which is
// the triangle's own (within 1 degree). On a smooth mesh, however dense, the corners of a triangle differ; a
// planar shared-vertex region passes but then recomputing gives the same normals.
bool looks_flat_shaded(const Mesh& mesh) {
  const float cos_tolerance = std::cos(glm::radians(1.0f));
  size_t flat = 0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* v = &mesh.indices[3 * t];
    const glm::vec3& n = mesh.normals[v[0]];
    if (n != mesh.normals[v[1]] || n != mesh.normals[v[2]]) continue;
    const glm::vec3 f =
        glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]], mesh.positions[v[2]] - mesh.positions[v[0]]);
    flat += glm::dot(n, f) > cos_tolerance * glm::length(n) * glm::length(f);
  }
  return 10 * flat >= 9 * mesh.triangle_count();
}

}  // namespace

void weld_identical(Mesh& mesh) {
  weld_by(mesh, VertexKey{mesh, mesh.has_normals(), mesh.has_uvs(), mesh.has_colors()});
}

void weld_with_crease_normals(Mesh& mesh, float crease_angle_degrees) {
  mesh.normals.clear();
  weld_by(mesh, VertexKey{mesh, false, mesh.has_uvs(), mesh.has_colors()});
  const size_t nv = mesh.positions.size(), nt = mesh.triangle_count(), nc = mesh.indices.size();

  // Position classes: vertices that differ only in UV or colour share a normal. Without UVs and colours every
  // vertex is its own class already.
  std::vector<uint32_t> position;
  if (mesh.has_uvs() || mesh.has_colors()) {
    position = representatives(VertexKey{mesh, false, false, false}, nv);
  } else {
    reserve_prefaulted(position, nv);
    for (uint32_t v = 0; v < nv; ++v) position.push_back(v);
  }

  // Corners grouped by position class, increasing within each (a stable counting sort), on every core: dealt
  // by their position's high bits into 1024-2047 slices of consecutive positions (core/counting_sort.hpp),
  // then each slice counting-sorted by position in cache, in place through a per-thread copy (was two serial
  // passes with a cache miss per corner). start[p]: the first of position p's corners in `corners`.
  const int slice_bits = std::max(0, int(std::bit_width(nv)) - 11);
  const size_t slices = ((nv - 1) >> slice_bits) + 1;
  std::vector<uint32_t> corners, slice_begin;
  resize_prefaulted(corners, nc);
  counting_sort(
      nc, uint32_t(slices), [&](size_t c) { return uint32_t(position[mesh.indices[c]] >> slice_bits); },
      [&](size_t c, uint32_t at) { corners[at] = uint32_t(c); }, &slice_begin);
  std::vector<uint32_t> start;
  resize_prefaulted(start, nv + 1);
  tbb::parallel_for(size_t(0), slices, [&](size_t s) {
    const size_t lo = s << slice_bits, hi = std::min(nv, (s + 1) << slice_bits);
    thread_local std::vector<uint32_t> slice;
    slice.assign(corners.begin() + slice_begin[s], corners.begin() + slice_begin[s + 1]);
    for (uint32_t c : slice) ++start[position[mesh.indices[c]]];
    uint32_t running = slice_begin[s];
    for (size_t p = lo; p < hi; ++p) {
      const uint32_t count = start[p];
      start[p] = running;
      running += count;
    }
    std::vector<uint32_t> fill(start.begin() + lo, start.begin() + hi);
    for (uint32_t c : slice) corners[fill[position[mesh.indices[c]] - lo]++] = c;
  });
  start[nv] = uint32_t(nc);

  // Face normals, unnormalized (their length is twice the area, which weights the sums), and their unit
  // vectors (zero for a zero normal), each computed once per face rather than at each of its three corners.
  struct Face {
    glm::vec3 normal, unit;
  };
  auto face = std::make_unique_for_overwrite<Face[]>(nt);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nt, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); ++t) {
      const uint32_t* v = &mesh.indices[3 * t];
      const glm::vec3 n = glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]],
                                     mesh.positions[v[2]] - mesh.positions[v[0]]);
      const float len = glm::length(n);
      face[t] = {n, len > 0 ? n / len : glm::vec3(0.0f)};
    }
  });
  constexpr uint32_t kAhead = 16;  // prefetch distance where corners are gathered in random order

  // Per position: group its corners by crease, then give each (welded vertex, group) pair one output vertex.
  // A welded vertex belongs to exactly one position, so all its corners are handled here and the indices can
  // be rewritten in place. Runs of positions go to every core; each run numbers its output vertices from 0
  // and is then shifted by the outputs of the runs before it, which gives the serial numbering (position
  // order) whatever the timing.
  const float cos_crease = std::cos(glm::radians(crease_angle_degrees));
  struct Group {
    glm::vec3 seed;  // unit normal of the group's first triangle
    glm::vec3 sum;   // area-weighted normal sum
  };
  struct Output {
    uint32_t vertex, group, out;
  };
  // A group's normal: its sum normalized (+z when zero).
  auto group_normal = [](const Group& g) {
    const float len = glm::length(g.sum);
    return len > 0 ? g.sum / len : glm::vec3(0.0f, 0.0f, 1.0f);
  };
  // Without UVs and colours every position class is one vertex (above), so a position's corners are all of
  // it.
  const bool one_vertex_per_position = !(mesh.has_uvs() || mesh.has_colors());
  struct Run {
    std::vector<uint32_t> keep;
    std::vector<glm::vec3> normals;
  };
  constexpr size_t kRunPositions = size_t(1) << 15;
  std::vector<Run> runs((nv + kRunPositions - 1) / kRunPositions);
  tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
    std::vector<Group> groups;
    std::vector<uint32_t> corner_group;
    std::vector<Output> outputs;
    Run& run = runs[r];
    const size_t run_begin = r * kRunPositions,
                 positions = std::min(nv, run_begin + kRunPositions) - run_begin;
    const uint32_t run_end = start[run_begin + positions];
    // About one output a position (more at creases and seams): reserved, not regrown.
    run.keep.reserve(positions), run.normals.reserve(positions);
    for (size_t p = run_begin; p < run_begin + positions; ++p) {
      const uint32_t begin = start[p], end = start[p + 1];
      if (begin == end) continue;
      groups.clear();
      corner_group.clear();
      for (uint32_t k = begin; k < end; ++k) {
        if (k + kAhead < run_end) {  // corners are gathered in random order: keep misses in flight
          __builtin_prefetch(&face[corners[k + kAhead] / 3]);
          __builtin_prefetch(&mesh.indices[corners[k + kAhead]]);
        }
        const glm::vec3 &n = face[corners[k] / 3].normal, &unit = face[corners[k] / 3].unit;
        size_t g = 0;
        while (g < groups.size() && glm::dot(groups[g].seed, unit) < cos_crease) ++g;
        if (g == groups.size()) groups.push_back({unit, glm::vec3(0.0f)});
        groups[g].sum += n;
        corner_group.push_back(static_cast<uint32_t>(g));
      }
      if (one_vertex_per_position) {
        // Every corner here is of vertex p, and groups were numbered in order of their first corner: the
        // pairs (p, g) are the groups in order, and the search below would number them so.
        const uint32_t first = static_cast<uint32_t>(run.keep.size());
        for (const Group& g : groups)
          run.keep.push_back(static_cast<uint32_t>(p)), run.normals.push_back(group_normal(g));
        for (uint32_t k = begin; k < end; ++k) mesh.indices[corners[k]] = first + corner_group[k - begin];
        continue;
      }
      outputs.clear();
      for (uint32_t k = begin; k < end; ++k) {
        const uint32_t c = corners[k], w = mesh.indices[c], g = corner_group[k - begin];
        // Distinct (vertex, group) pairs at one position are few (seams, creases): a linear search is enough.
        size_t o = 0;
        while (o < outputs.size() && (outputs[o].vertex != w || outputs[o].group != g)) ++o;
        if (o == outputs.size()) {
          const uint32_t out = static_cast<uint32_t>(run.keep.size());
          run.keep.push_back(w);
          run.normals.push_back(group_normal(groups[g]));
          outputs.push_back({w, g, out});
        }
        mesh.indices[c] = outputs[o].out;
      }
    }
  });
  std::vector<uint32_t> first_output(runs.size() + 1, 0);
  for (size_t r = 0; r < runs.size(); ++r)
    first_output[r + 1] = first_output[r] + uint32_t(runs[r].keep.size());
  std::vector<uint32_t> keep;
  std::vector<glm::vec3> normals;
  resize_prefaulted(keep, first_output.back()), resize_prefaulted(normals, first_output.back());
  tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
    const uint32_t shift = first_output[r];
    for (uint32_t k = start[r * kRunPositions]; k < start[std::min(nv, (r + 1) * kRunPositions)]; ++k)
      mesh.indices[corners[k]] += shift;
    std::copy(runs[r].keep.begin(), runs[r].keep.end(), keep.begin() + shift);
    std::copy(runs[r].normals.begin(), runs[r].normals.end(), normals.begin() + shift);
  });
  compact(mesh, keep);
  mesh.normals = std::move(normals);
}

WeldResult weld(Mesh& mesh, float crease_angle_degrees) {
  WeldResult r;
  r.vertices_before = mesh.vertex_count();
  if (!mesh.has_normals()) {
    weld_with_crease_normals(mesh, crease_angle_degrees);  // welds by position, UV and colour first
    r.normals_recomputed = true;
    r.vertices_after = mesh.vertex_count();
    return r;
  }
  weld_identical(mesh);
  const bool flat = looks_flat_shaded(mesh);
  if (flat) {
    weld_with_crease_normals(mesh, crease_angle_degrees);
    r.normals_recomputed = true;
  }
  r.vertices_after = mesh.vertex_count();
  return r;
}

}  // namespace lodstream
