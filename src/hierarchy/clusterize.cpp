#include "hierarchy/clusterize.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <span>

#include "hierarchy/spatial_sort.hpp"

namespace lodstream::hierarchy {

namespace {

// Greedy region growing over shared vertices (the rule of meshoptimizer's meshlet builder, without its
// k-d tree and per-step rescan of the cluster's vertices): a cluster starts at the first unused triangle of
// the spatial order and repeatedly takes, among the unused triangles touching its vertices (its frontier),
// the one that adds the fewest new vertices, ties to the one nearest the cluster's centroid; it closes at
// `max_triangles`, or when no frontier triangle fits `max_vertices`, and when its frontier runs dry (a
// component used up) it continues from the next unused triangle of the spatial order, which is near.
// `indices` are over `positions` (a run of the spatial order, compact vertex numbers); clusters are
// appended to `parts`. Cost: O(T * frontier) with a frontier of a few dozen triangles; memory O(V + T).
template <bool kDegenerate>
void grow(std::span<const glm::vec3> positions, std::span<const uint32_t> indices, size_t max_vertices,
          size_t max_triangles, std::vector<ClusterPart>& parts) {
  const size_t triangles = indices.size() / 3, vertices = positions.size();
  // Corner k of triangle t counts unless it repeats an earlier corner (only a mesh with degenerate triangles
  // pays for the test).
  auto distinct = [&](size_t t, int k) {
    const uint32_t* c = &indices[3 * t];
    return !kDegenerate || k == 0 || (c[k] != c[0] && (k == 1 || c[2] != c[1]));
  };
  // Vertex -> triangles (CSR), and per vertex its unused triangles.
  std::vector<uint32_t> offsets(vertices + 1, 0), adjacent(indices.size()), remaining(vertices, 0);
  for (size_t t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k)
      if (distinct(t, k)) ++offsets[indices[3 * t + k] + 1], ++remaining[indices[3 * t + k]];
  for (size_t v = 0; v < vertices; ++v) offsets[v + 1] += offsets[v];
  {
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (size_t t = 0; t < triangles; ++t)
      for (int k = 0; k < 3; ++k)
        if (distinct(t, k)) adjacent[fill[indices[3 * t + k]]++] = uint32_t(t);
  }
  // Per triangle, in one record (a step reads several fields of each triangle it touches; in separate
  // arrays each was a cache miss of its own on a level-0 chunk): used, its distinct corners, corners already
  // in the current cluster (valid while listed in its frontier), flags (it is the last unused triangle of one
  // of its vertices; it is listed in `near` or `last`; in `last`: both valid while listed in the frontier),
  // the cluster that listed it in its frontier, its place in the order of listing (which breaks ties as one
  // list would), its centroid.
  constexpr uint8_t kLast = 1, kNear = 2, kInLast = 4;
  constexpr uint32_t kUnset = UINT32_MAX;
  struct State {
    uint8_t used = 0, corners = 0, shared = 0, flags = 0;
    uint32_t in_frontier = UINT32_MAX, listed = 0;  // kUnset
    glm::vec3 centroid{0.0f};
  };
  std::vector<State> state(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    const uint32_t* c = &indices[3 * t];
    state[t].centroid = (positions[c[0]] + positions[c[1]] + positions[c[2]]) * (1.0f / 3.0f);
    for (int k = 0; k < 3; ++k)
      if (distinct(t, k)) ++state[t].corners, state[t].flags |= remaining[c[k]] == 1 ? kLast : 0;
  }

  std::vector<uint32_t> local(vertices, kUnset);  // vertex -> cluster vertex number, current cluster only
  // The frontier, by priority (below): ready, adding no vertex; last, the last unused triangle of one of its
  // vertices; near, adding one; far, the rest (adding two). An entry that moves up a list (to near or last)
  // stays behind in the one it left, which skips it.
  std::vector<uint32_t> ready, last, near, far;
  uint32_t listings = 0;
  size_t cursor = 0;  // every triangle before it is used
  for (uint32_t cluster = 0;; ++cluster) {
    while (cursor < triangles && state[cursor].used) ++cursor;
    if (cursor == triangles) break;
    ClusterPart& part = parts.emplace_back();
    part.vertices.reserve(max_vertices), part.indices.reserve(3 * max_triangles);  // no regrowth
    ready.clear(), last.clear(), near.clear(), far.clear();
    size_t next_ready = 0;
    glm::vec3 sum(0.0f);
    auto add = [&](uint32_t t) {
      state[t].used = 1;
      sum += state[t].centroid;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = indices[3 * size_t(t) + k];
        if (distinct(t, k)) {
          if (--remaining[v] == 1)
            for (uint32_t s = offsets[v]; s < offsets[v + 1]; ++s) {
              State& st = state[adjacent[s]];
              st.flags |= kLast;
              if (!st.used && st.in_frontier == cluster && !(st.flags & kInLast))
                st.flags |= kNear | kInLast, last.push_back(adjacent[s]);
            }
          if (local[v] == kUnset) {
            local[v] = uint32_t(part.vertices.size());
            part.vertices.push_back(v);
            for (uint32_t s = offsets[v]; s < offsets[v + 1]; ++s) {
              const uint32_t n = adjacent[s];
              State& st = state[n];
              if (st.used) continue;
              const bool first = st.in_frontier != cluster;
              if (first)
                st.in_frontier = cluster, st.shared = 0, st.flags &= ~(kNear | kInLast),
                st.listed = listings++;
              if (++st.shared == st.corners)
                ready.push_back(n);
              else if (st.flags & kLast) {
                if (!(st.flags & kInLast)) st.flags |= kNear | kInLast, last.push_back(n);
              } else if (!(st.flags & kNear) && st.corners - st.shared == 1)
                st.flags |= kNear, near.push_back(n);
              else if (first)
                far.push_back(n);
            }
          }
        }
        part.indices.push_back(local[v]);
      }
    };
    add(uint32_t(cursor));
    while (part.indices.size() < 3 * max_triangles) {
      // A triangle that adds no vertex is taken first, in the order they became so (no frontier scan).
      while (next_ready < ready.size() && state[ready[next_ready]].used) ++next_ready;
      if (next_ready < ready.size()) {
        add(ready[next_ready++]);
        continue;
      }
      const glm::vec3 center = sum / float(part.indices.size() / 3);
      // Priority (lower first): is the last unused triangle of one of its vertices (left out, it would start
      // a ragged cluster later); adds 1, 2 vertices. Ties: nearest the centroid. (Adding none came first,
      // above: such a triangle lies within the cluster's vertices, so which one matters little.)
      uint32_t best = kUnset, best_priority = UINT32_MAX;
      float best_distance = 0.0f;
      // Every last entry comes before every near one, and every near one before every far one, so a list is
      // scanned only when no entry of the ones before fits. `moved`: the flag of the entries that moved to a
      // list before it.
      auto scan = [&](std::vector<uint32_t>& list, uint8_t moved) {
        size_t kept = 0;
        for (size_t i = 0; i < list.size(); ++i) {  // drops used and moved entries while scanning
          const uint32_t t = list[i];
          const State& st = state[t];
          if (st.used || (st.flags & moved)) continue;
          list[kept++] = t;
          const size_t added = size_t(st.corners - st.shared);
          if (part.vertices.size() + added > max_vertices) continue;
          const uint32_t priority = (st.flags & kLast) ? 1 : uint32_t(added) + 1;
          if (priority > best_priority) continue;
          const glm::vec3 d = st.centroid - center;
          const float distance = glm::dot(d, d);
          if (priority < best_priority || distance < best_distance ||
              (distance == best_distance && st.listed < state[best].listed))
            best = t, best_priority = priority, best_distance = distance;
        }
        list.resize(kept);
      };
      scan(last, 0);
      if (best == kUnset) scan(near, kInLast);
      if (best == kUnset) scan(far, kNear);
      if (best == kUnset) {
        if (!last.empty() || !near.empty() || !far.empty()) break;
        // The component is used up (no unused triangle touches the cluster): continue with the unused
        // triangle nearest the centroid among the next kJumpWindow of the spatial order (near each other).
        constexpr size_t kJumpWindow = 64;
        while (cursor < triangles && state[cursor].used) ++cursor;
        for (size_t t = cursor, seen = 0; t < triangles && seen < kJumpWindow; ++t) {
          if (state[t].used) continue;
          ++seen;
          const glm::vec3 d = state[t].centroid - center;
          if (best == kUnset || glm::dot(d, d) < best_distance)
            best = uint32_t(t), best_distance = glm::dot(d, d);
        }
        if (best == kUnset || part.vertices.size() + state[best].corners > max_vertices) break;
      }
      add(best);
    }
    for (uint32_t v : part.vertices) local[v] = kUnset;
  }
}

// The DAG drops degenerate triangles first, so there every corner counts without the per-corner test.
void grow_clusters(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                   size_t max_vertices, size_t max_triangles, std::vector<ClusterPart>& parts) {
  bool degenerate = false;
  for (size_t t = 0; t + 2 < indices.size() && !degenerate; t += 3) {
    const uint32_t* c = &indices[t];
    degenerate = c[0] == c[1] || c[1] == c[2] || c[0] == c[2];
  }
  if (degenerate)
    grow<true>(positions, indices, max_vertices, max_triangles, parts);
  else
    grow<false>(positions, indices, max_vertices, max_triangles, parts);
}

}  // namespace

std::vector<ClusterPart> clusterize(const Mesh& mesh, size_t max_vertices, size_t max_triangles) {
  std::vector<ClusterPart> parts;
  if (mesh.indices.empty()) return parts;
  const std::vector<uint32_t> sorted = spatial_sort_triangles(mesh.positions, mesh.indices);
  const size_t chunk_indices = 3 * kChunkClusters * max_triangles;
  if (sorted.size() <= chunk_indices) {
    grow_clusters(mesh.positions, sorted, max_vertices, max_triangles, parts);
    return parts;
  }
  // Runs of the spatial order in parallel, each over its own compact vertex range (the meshlet builder's
  // set-up is linear in the vertex count it is given).
  const size_t chunks = (sorted.size() + chunk_indices - 1) / chunk_indices;
  std::vector<std::vector<ClusterPart>> chunk_parts(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    const size_t begin = c * chunk_indices, end = std::min(sorted.size(), begin + chunk_indices);
    // mesh -> local vertex numbers in a per-thread table, reset after use (first use order).
    thread_local std::vector<uint32_t> local_of;
    if (local_of.size() < mesh.positions.size()) local_of.assign(mesh.positions.size(), UINT32_MAX);
    std::vector<uint32_t> local_to_mesh, indices(end - begin);
    for (size_t i = begin; i < end; ++i) {
      uint32_t& local = local_of[sorted[i]];
      if (local == UINT32_MAX) local = uint32_t(local_to_mesh.size()), local_to_mesh.push_back(sorted[i]);
      indices[i - begin] = local;
    }
    std::vector<glm::vec3> positions(local_to_mesh.size());
    for (size_t v = 0; v < local_to_mesh.size(); ++v) {
      positions[v] = mesh.positions[local_to_mesh[v]];
      local_of[local_to_mesh[v]] = UINT32_MAX;
    }
    grow_clusters(positions, indices, max_vertices, max_triangles, chunk_parts[c]);
    for (ClusterPart& part : chunk_parts[c])
      for (uint32_t& v : part.vertices) v = local_to_mesh[v];
  });
  for (auto& cp : chunk_parts)
    for (ClusterPart& part : cp) parts.push_back(std::move(part));
  return parts;
}

Mesh cluster_mesh(const Mesh& mesh, const ClusterPart& part) {
  Mesh c;
  c.indices = part.indices;
  copy_cluster_vertices(mesh, part.vertices, c);
  return c;
}

void copy_cluster_vertices(const Mesh& mesh, std::span<const uint32_t> vertices, Mesh& cluster) {
  cluster.material = mesh.material;
  auto gather = [vertices](const auto& from, auto& to) {
    to.clear();
    if (from.empty()) return;
    to.reserve(vertices.size());
    for (uint32_t v : vertices) to.push_back(from[v]);
  };
  gather(mesh.positions, cluster.positions);
  gather(mesh.normals, cluster.normals);
  gather(mesh.uvs, cluster.uvs);
  gather(mesh.colors, cluster.colors);
}

}  // namespace lodstream::hierarchy
