#include "hierarchy/cluster_dag.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/error.hpp"
#include "core/prefault.hpp"
#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/clusterize.hpp"
#include "hierarchy/component_removal.hpp"
#include "hierarchy/group_partition.hpp"
#include "hierarchy/position_index.hpp"
#include "hierarchy/radii_floor.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::hierarchy {
namespace {

// Build state: the DAG plus, per cluster, the position id of each vertex (ids equal <=> positions equal).
struct Builder {
  const DagOptions& options;
  ClusterDag dag{};
  std::vector<std::vector<uint32_t>> position_ids{};  // by cluster
  uint32_t next_position_id = 0;
  // The input and its level-0 clusters' vertices until their vertex data is copied (beside level 1's
  // grouping, which needs only the clusters' indices, position ids and spheres).
  Mesh input{};
  std::vector<ClusterPart> input_parts{};
  // The active clusters' boundary edges, per level, reused (fresh pages cost 4 s/GB to touch).
  std::vector<ClusterEdge> edges{};
  // By position id, one word: kOpenBoundary when it lies on the mesh's open boundary (set at level 1), and
  // below that bit its claim (claim_base + the group that claimed it first this level, or the level's border
  // mark claim_base + groups when a second group claimed it). A claim below claim_base is an earlier level's
  // and counts as none, so nothing is reset between levels. One word read per group vertex: the open
  // boundary and the borders in two arrays of bytes beside the claims were two cache misses, and resetting
  // the claims and borders a second random pass over every active position each level (refined_elephant
  // bake, callgrind's cache simulation: L1 read misses of simplify_group and the claim passes 97.1 k ->
  // 83.1 k; instructions about the same).
  std::vector<uint32_t> claims{};
  uint32_t claim_base = 1;  // 0, a fresh entry's claim, is below it
};

constexpr uint32_t kOpenBoundary = 0x80000000u;

// Positions a group simplification creates get ids kNewId | k while groups run in parallel; the ids are made
// final (next_position_id onwards, in group order) once the level's groups are done, so that ids, and with
// them the edge order METIS sees, do not depend on thread timing: the same input bakes the same package.
constexpr uint32_t kNewId = 0x80000000u;

uint64_t edge_key(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return uint64_t(a) << 32 | b;
}

// Edges of a cluster used by exactly one of its triangles (by position id), as keys in no particular order
// (the callers sort them with the cluster index). Vertices that share a position id (seams) are first merged
// into one local vertex; each edge between local vertices is then counted (1, or 2 for more) in a per-thread
// table of V x V cells of which only the touched ones are read back and cleared (V <= max_cluster_vertices
// <= 255: at most 64 KB per thread). Cost: O(V + T), against O(T log T) for sorting the 3T edge keys (that
// sort was ~2 % of a bake).
std::vector<uint64_t> cluster_boundary(const Mesh& mesh, const std::vector<uint32_t>& ids) {
  const size_t nv = ids.size();
  // Local vertex -> the first local vertex of its position id, through a per-thread open-addressing table of
  // at least 2V slots (cleared after use).
  thread_local std::vector<uint64_t> slots;
  size_t capacity = 64;
  while (capacity < 2 * nv) capacity *= 2;
  if (slots.size() < capacity) slots.assign(capacity, 0);
  std::vector<uint32_t> merged(nv);
  for (uint32_t v = 0; v < nv; ++v) {
    size_t slot = (ids[v] * 0x9E3779B97F4A7C15ull) >> 40 & (capacity - 1);
    while (slots[slot] != 0 && uint32_t(slots[slot] >> 32) != ids[v]) slot = (slot + 1) & (capacity - 1);
    if (slots[slot] == 0) slots[slot] = uint64_t(ids[v]) << 32 | (v + 1);  // low half: v + 1, never 0
    merged[v] = uint32_t(slots[slot]) - 1;
  }
  for (uint32_t v = 0; v < nv; ++v) {  // clear what was set: probe runs hold only ids of this cluster
    size_t slot = (ids[v] * 0x9E3779B97F4A7C15ull) >> 40 & (capacity - 1);
    while (slots[slot] != 0) slots[slot] = 0, slot = (slot + 1) & (capacity - 1);
  }
  thread_local std::vector<uint8_t> count;
  if (count.size() < nv * nv) count.assign(nv * nv, 0);
  // Each corner's edge (to the next corner) as its cell's index, kept for the second pass.
  const size_t corners = mesh.indices.size() / 3 * 3;
  thread_local std::vector<uint32_t> cell;
  cell.resize(corners);
  for (size_t t = 0; t < corners; t += 3) {
    const uint32_t m[3] = {merged[mesh.indices[t]], merged[mesh.indices[t + 1]], merged[mesh.indices[t + 2]]};
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m[k], b = m[k == 2 ? 0 : k + 1];
      cell[t + k] = uint32_t(std::min(a, b) * nv + std::max(a, b));
      count[cell[t + k]] = uint8_t(std::min(count[cell[t + k]] + 1, 2));
    }
  }
  // The key is built only for the edges used once.
  std::vector<uint64_t> once;
  for (size_t c = 0; c < corners; ++c) {
    if (count[cell[c]] == 1)
      once.push_back(edge_key(ids[mesh.indices[c]], ids[mesh.indices[c % 3 == 2 ? c - 2 : c + 1]]));
    count[cell[c]] = 0;
  }
  return once;
}

float round_up(double x) {
  float f = float(x);
  return double(f) < x ? std::nextafter(f, INFINITY) : f;
}

// Level 0: the input (without degenerate triangles) split into clusters; position ids by exact welding.
void build_level0(Builder& b, Mesh mesh) {
  // Import drops zero-area triangles already, so there is usually none to drop: the first one is searched
  // for on every core, and only the triangles from it on are compacted (on one core).
  const size_t triangles = mesh.indices.size() / 3;
  auto degenerate = [&](size_t t) {
    const uint32_t* c = &mesh.indices[3 * t];
    return c[0] == c[1] || c[1] == c[2] || c[0] == c[2];
  };
  const size_t first = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, triangles), triangles,
      [&](const tbb::blocked_range<size_t>& r, size_t found) {
        for (size_t t = r.begin(); t < std::min(r.end(), found); ++t)
          if (degenerate(t)) return t;
        return found;
      },
      [](size_t x, size_t y) { return std::min(x, y); });
  size_t kept = 3 * first;
  for (size_t t = first; t < triangles; ++t)
    if (!degenerate(t))
      for (int k = 0; k < 3; ++k) mesh.indices[kept++] = mesh.indices[3 * t + k];
  mesh.indices.resize(kept);
  b.dag.input_triangles = mesh.triangle_count();
  if (mesh.indices.empty()) return;

  // Welding runs beside the clusterizer (both on every core).
  std::vector<uint32_t> vertex_id;
  std::vector<ClusterPart> parts;
  tbb::parallel_invoke(
      [&] { vertex_id = weld_positions(mesh.positions, b.next_position_id); },
      [&] { parts = clusterize(mesh, b.options.max_cluster_vertices, b.options.max_cluster_triangles); });
  resize_prefaulted(b.dag.clusters, parts.size());
  b.position_ids.resize(parts.size());
  tbb::parallel_for(size_t(0), parts.size(), [&](size_t c) {
    DagCluster& cluster = b.dag.clusters[c];
    cluster.mesh.indices = std::move(parts[c].indices);
    thread_local std::vector<glm::vec3> points;
    points.clear();
    for (uint32_t v : parts[c].vertices) points.push_back(mesh.positions[v]);
    cluster.sphere = sphere_of_points(points);
    auto& ids = b.position_ids[c];
    for (uint32_t v : parts[c].vertices) ids.push_back(vertex_id[v]);
  });
  b.input = std::move(mesh);
  b.input_parts = std::move(parts);
}

// The level-0 clusters' positions, attributes and (cleared) locked flags, from the input, which is then
// released; nothing once done. Clusters on every core.
void copy_level0_vertices(Builder& b) {
  tbb::parallel_for(size_t(0), b.input_parts.size(), [&](size_t c) {
    DagCluster& cluster = b.dag.clusters[c];
    copy_cluster_vertices(b.input, b.input_parts[c].vertices, cluster.mesh);
    cluster.locked.assign(cluster.mesh.positions.size(), 0);
  });
  b.input = Mesh{};
  b.input_parts = {};
}

// Marks the positions of edges that no other cluster shares (the mesh's open boundary) in b.claims (sized to
// every id); `edges` sorted.
void mark_open_boundary(Builder& b, std::span<const ClusterEdge> edges) {
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 1) {
      b.claims[uint32_t(edges[i].first >> 32)] |= kOpenBoundary;
      b.claims[uint32_t(edges[i].first)] |= kOpenBoundary;
    }
    i = j;
  }
}

struct NewCluster {
  Mesh mesh;
  std::vector<uint32_t> ids;
  std::vector<uint8_t> locked;
  std::vector<float> vertex_error;
  Sphere sphere;
};

struct GroupResult {
  bool accepted = false;
  DagGroup group;
  std::vector<NewCluster> clusters;
  uint32_t new_ids = 0;  // ids kNewId | [0, new_ids) in `clusters`
};

// Merges, simplifies with the border locked and re-splits one group (formula of error_g in the header); once
// accepted, flags the locked positions of its input clusters. `border_mark`: the level's claim of positions
// held by several groups (Builder::claims).
GroupResult simplify_group(Builder& b, const std::vector<uint32_t>& members, uint32_t border_mark,
                           uint32_t level) {
  const DagOptions& o = b.options;
  const uint32_t open_lock = o.lock_open_boundary ? kOpenBoundary : 0;
  GroupResult out;
  Mesh merged;
  std::vector<uint32_t> merged_ids;
  simplify::Options so;
  const Mesh& first = b.dag.clusters[members[0]].mesh;
  merged.material = first.material;
  size_t vertices = 0, corners = 0;
  for (uint32_t c : members)
    vertices += b.dag.clusters[c].mesh.positions.size(), corners += b.dag.clusters[c].mesh.indices.size();
  merged.positions.reserve(vertices), merged.indices.reserve(corners);
  if (first.has_normals()) merged.normals.reserve(vertices);
  if (first.has_uvs()) merged.uvs.reserve(vertices);
  if (first.has_colors()) merged.colors.reserve(vertices);
  merged_ids.reserve(vertices), so.locked.reserve(vertices);
  const bool carries_error = std::any_of(members.begin(), members.end(),
                                         [&](uint32_t c) { return !b.dag.clusters[c].vertex_error.empty(); });
  if (carries_error) so.vertex_error.reserve(vertices);
  for (uint32_t c : members) {
    const Mesh& m = b.dag.clusters[c].mesh;
    const uint32_t base = uint32_t(merged.positions.size());
    merged.positions.insert(merged.positions.end(), m.positions.begin(), m.positions.end());
    merged.normals.insert(merged.normals.end(), m.normals.begin(), m.normals.end());
    merged.uvs.insert(merged.uvs.end(), m.uvs.begin(), m.uvs.end());
    merged.colors.insert(merged.colors.end(), m.colors.begin(), m.colors.end());
    for (uint32_t i : m.indices) merged.indices.push_back(base + i);
    if (carries_error) {
      const std::vector<float>& e = b.dag.clusters[c].vertex_error;
      if (e.empty())
        so.vertex_error.resize(so.vertex_error.size() + m.positions.size(), 0.0f);
      else
        so.vertex_error.insert(so.vertex_error.end(), e.begin(), e.end());
    }
    for (uint32_t id : b.position_ids[c]) {
      merged_ids.push_back(id);
      const uint32_t claim = b.claims[id];
      so.locked.push_back((claim & ~kOpenBoundary) == border_mark || (claim & open_lock) != 0);
    }
  }
  floor_radii(so.vertex_error);
  const size_t input_triangles = merged.triangle_count();
  so.target_triangles = std::max<size_t>(1, size_t(double(input_triangles) * o.group_ratio));
  so.normal_weight = o.normal_weight, so.uv_weight = o.uv_weight, so.color_weight = o.color_weight;
  simplify::Result r = simplify::simplify_mesh(merged, so);
  GroupOutcome outcome = r.mesh.triangle_count() <= size_t(double(input_triangles) * o.group_ratio * 1.1)
                             ? GroupOutcome::halved
                             : GroupOutcome::partial;
  const auto stuck = [&](const simplify::Result& res) {
    return double(res.mesh.triangle_count()) > double(input_triangles) * o.stuck_ratio;
  };
  if (stuck(r)) {  // fallback: positions only, looser fold-over limit (attribute seams no longer matter)
    so.normal_weight = so.uv_weight = so.color_weight = 0.0f;
    so.max_normal_change_deg = 120.0f;
    r = simplify::simplify_mesh(merged, so);
    outcome = GroupOutcome::positions_only;
  }

  // Position ids of the result: a position of the group's input keeps the id of its first input vertex and
  // is locked when any input vertex there is (locked ones never move); a new position gets a new id, in
  // result order (seam vertices share one). The result's positions are indexed (about half as many as the
  // input's) and each input vertex is looked up there.
  const Mesh& result = r.mesh;
  PositionIndex local(result.positions.size());
  std::vector<uint32_t> result_local(result.positions.size());
  for (size_t v = 0; v < result.positions.size(); ++v) result_local[v] = local.insert(result.positions[v]);
  constexpr uint32_t kNoId = UINT32_MAX;
  std::vector<uint32_t> local_to_id(local.size(), kNoId);
  std::vector<uint8_t> local_locked(local.size(), 0);
  for (size_t v = 0; v < merged.positions.size(); ++v) {
    const uint32_t l = local.find(merged.positions[v]);
    if (l == PositionIndex::kMissing) continue;
    if (local_to_id[l] == kNoId) local_to_id[l] = merged_ids[v];
    local_locked[l] |= so.locked[v];
  }
  std::vector<uint32_t> result_ids(result.positions.size());
  std::vector<uint8_t> result_locked(result.positions.size());
  for (size_t v = 0; v < result.positions.size(); ++v) {
    const uint32_t l = result_local[v];
    if (local_to_id[l] == kNoId) local_to_id[l] = kNewId | out.new_ids++;
    result_ids[v] = local_to_id[l];
    result_locked[v] = local_locked[l];
  }
  if (stuck(r)) {  // last fallback: whole closed components dropped (component_removal.hpp)
    // A dropped component's full-resolution points are within its largest radius + e_C of the nearest kept
    // vertex: every kept vertex's radius is raised to that, so the invariant covers them too.
    const double dropped = r.error_bound + remove_components(r.mesh, result_locked, so.target_triangles);
    for (float& e : r.vertex_error) e = std::max(e, round_up(dropped));
    r.error_bound = dropped;
    outcome = GroupOutcome::components_dropped;
  }
  if (stuck(r)) return out;

  DagGroup& g = out.group;
  g.level = level;
  g.children = members;
  g.input_triangles = input_triangles;
  g.output_triangles = result.triangle_count();
  g.outcome = outcome;
  double child_error = 0.0;
  std::vector<Sphere> spheres;
  for (uint32_t c : members) {
    child_error = std::max(child_error, double(b.dag.clusters[c].error));
    spheres.push_back(b.dag.clusters[c].sphere);
  }
  g.error = round_up(std::max(child_error, r.error_bound));
  g.sphere = sphere_of_spheres(spheres, result.positions);

  for (const ClusterPart& part : clusterize(result, o.max_cluster_vertices, o.max_cluster_triangles)) {
    NewCluster nc;
    nc.mesh = cluster_mesh(result, part);
    for (uint32_t v : part.vertices) {
      nc.ids.push_back(result_ids[v]);
      nc.locked.push_back(result_locked[v]);
      nc.vertex_error.push_back(r.vertex_error[v]);
    }
    out.clusters.push_back(std::move(nc));
  }
  // Positions locked in this simplification are shared with other groups' clusters: codec-locked in the
  // input clusters (each is consumed by this group alone, so groups running in parallel set their own).
  size_t offset = 0;
  for (uint32_t c : members) {
    std::vector<uint8_t>& locked = b.dag.clusters[c].locked;
    for (size_t v = 0; v < locked.size(); ++v) locked[v] |= so.locked[offset + v];
    offset += locked.size();
    std::vector<float>().swap(b.dag.clusters[c].vertex_error);  // consumed: its radii live on in the result's
  }
  out.accepted = true;
  return out;
}

// A position locked in one cluster of a group is locked in every cluster of that group holding it: the
// group's clusters share one position shift, so a vertex they share must decode the same way in all. Run
// once every cluster of the group has been consumed (or the build ended), when its flags are complete. Each
// consumed cluster is then final: its consumer's `pending` count (inputs not yet final) drops, and a consumer
// whose inputs are all final is appended to `ready`.
void finish_groups(Builder& b, const std::vector<uint32_t>& groups, std::vector<uint32_t>& pending,
                   std::vector<uint32_t>& ready) {
  ClusterDag& dag = b.dag;
  tbb::parallel_for(size_t(0), groups.size(), [&](size_t i) {
    const DagGroup& group = dag.groups[groups[i]];
    std::vector<uint32_t> locked_ids;
    for (uint32_t c : group.clusters)
      for (size_t v = 0; v < b.position_ids[c].size(); ++v)
        if (dag.clusters[c].locked[v]) locked_ids.push_back(b.position_ids[c][v]);
    std::sort(locked_ids.begin(), locked_ids.end());
    for (uint32_t c : group.clusters)
      for (size_t v = 0; v < b.position_ids[c].size(); ++v)
        if (std::binary_search(locked_ids.begin(), locked_ids.end(), b.position_ids[c][v]))
          dag.clusters[c].locked[v] = 1;
  });
  for (uint32_t g : groups)
    for (uint32_t c : dag.groups[g].clusters) {
      const uint32_t consumer = dag.clusters[c].parent_group;
      if (consumer != kNoGroup && --pending[consumer] == 0) ready.push_back(consumer);
    }
}

}  // namespace

ClusterDag build_cluster_dag(Mesh mesh, const DagOptions& options) {
  Builder b{options};
  build_level0(b, std::move(mesh));
  ClusterDag& dag = b.dag;
  if (dag.clusters.empty()) return std::move(dag);
  dag.levels = 1;

  std::vector<uint32_t> active(dag.clusters.size());
  for (uint32_t c = 0; c < active.size(); ++c) active[c] = c;
  std::vector<uint32_t> unconsumed;  // by group: its clusters no accepted group has consumed yet
  std::vector<uint32_t> pending;     // by group: its input clusters not yet final
  std::vector<uint32_t> ready;       // groups whose inputs are final, not yet handed to options.inputs_final
  for (uint32_t level = 1; level <= options.max_levels; ++level) {
    size_t active_triangles = 0;
    for (uint32_t c : active) active_triangles += dag.clusters[c].mesh.triangle_count();
    if (options.progress) options.progress(level - 1, active_triangles);
    if (active.size() <= 1 || active_triangles <= options.root_triangles) break;

    // Boundary edges of the active clusters -> adjacency (and, at level 0, the open boundary).
    std::vector<std::vector<uint64_t>> boundary(active.size());
    tbb::parallel_for(size_t(0), active.size(), [&](size_t i) {
      boundary[i] = cluster_boundary(dag.clusters[active[i]].mesh, b.position_ids[active[i]]);
    });
    std::vector<ClusterEdge>& edges = b.edges;
    size_t boundary_edges = 0;
    for (const std::vector<uint64_t>& once : boundary) boundary_edges += once.size();
    edges.clear();
    reserve_prefaulted(edges, boundary_edges);  // filled on this thread below
    for (uint32_t i = 0; i < active.size(); ++i)
      for (uint64_t e : boundary[i]) edges.emplace_back(e, i);
    boundary.clear();
    std::vector<uint32_t> triangles(active.size());
    std::vector<glm::vec3> centroids(active.size());
    for (size_t i = 0; i < active.size(); ++i) {
      triangles[i] = uint32_t(dag.clusters[active[i]].mesh.triangle_count());
      centroids[i] = dag.clusters[active[i]].sphere.center;
    }
    // Near the root, one group takes everything: no border left to lock, so small meshes with thin parts
    // still reach a small root.
    const bool last = active_triangles <= 2 * options.group_clusters * options.max_cluster_triangles;
    // Sorting the edges, the open boundary (level 1) and the grouping (METIS) run on one core; beside them,
    // the level-0 clusters' vertex data is copied (level 1) and the groups whose inputs became final are
    // handed over.
    std::vector<std::vector<uint32_t>> groups;
    std::vector<uint32_t>& claims = b.claims;
    if (claims.size() < b.next_position_id) {
      if (claims.capacity() < b.next_position_id) {  // ids grow by about half the active positions a level
        claims.reserve(b.next_position_id * 3 / 2);
        prefault(claims.data(), claims.capacity() * sizeof(uint32_t));  // filled on this thread below
      }
      claims.resize(b.next_position_id, 0);
    }
    tbb::parallel_invoke(
        [&] {
          sort_edges(edges, b.next_position_id);
          if (level == 1) mark_open_boundary(b, edges);
          groups =
              partition_clusters(triangles, centroids, edges, last ? active.size() : options.group_clusters);
        },
        [&] {
          copy_level0_vertices(b);
          if (options.inputs_final && !ready.empty()) options.inputs_final(dag, ready);
        });
    ready.clear();
    for (auto& g : groups)
      for (uint32_t& i : g) i = active[i];  // active position -> cluster id

    // Group borders: positions used by clusters of more than one group. Groups on every core (these
    // scattered reads of every active position, on one core, left the other idle): the first group to claim
    // a position owns it, and a claim by any other marks it a border, so the borders do not depend on the
    // order of the claims.
    const uint32_t base = b.claim_base, border_mark = base + uint32_t(groups.size());
    if (uint64_t(border_mark) >= kOpenBoundary) throw Error("cluster DAG: more than 2^31 group claims");
    tbb::parallel_for(size_t(0), groups.size(), [&](size_t g) {
      const uint32_t mine = base + uint32_t(g);
      for (uint32_t c : groups[g])
        for (uint32_t id : b.position_ids[c]) {
          std::atomic_ref<uint32_t> claim(claims[id]);
          uint32_t seen = claim.load(std::memory_order_relaxed);
          while (
              (seen & ~kOpenBoundary) < base &&
              !claim.compare_exchange_weak(seen, (seen & kOpenBoundary) | mine, std::memory_order_relaxed)) {
          }
          const uint32_t owner = seen & ~kOpenBoundary;  // before this claim
          if (owner >= base && owner != mine && owner != border_mark)
            claim.store((seen & kOpenBoundary) | border_mark, std::memory_order_relaxed);
        }
    });
    b.claim_base = border_mark + 1;

    std::vector<GroupResult> results(groups.size());
    tbb::parallel_for(size_t(0), groups.size(), [&](size_t g) {
      // A group of one cluster at a level with several groups cannot change its (locked) border: skip it.
      if (groups[g].size() > 1 || groups.size() == 1)
        results[g] = simplify_group(b, groups[g], border_mark, level);
    });

    std::vector<uint32_t> next, completed_groups;
    bool any = false;
    for (size_t g = 0; g < groups.size(); ++g) {
      GroupResult& r = results[g];
      if (!r.accepted) {
        if (groups[g].size() > 1) ++dag.abandoned_groups;
        next.insert(next.end(), groups[g].begin(), groups[g].end());
        continue;
      }
      any = true;
      const uint32_t first_new_id = b.next_position_id;
      if (uint64_t(first_new_id) + r.new_ids >= kNewId) throw Error("cluster DAG: more than 2^31 positions");
      b.next_position_id += r.new_ids;
      for (NewCluster& nc : r.clusters)
        for (uint32_t& id : nc.ids)
          if (id & kNewId) id = first_new_id + (id & ~kNewId);
      const uint32_t gid = uint32_t(dag.groups.size());
      uint32_t inputs = 0;  // of its children, those not final yet
      for (uint32_t c : r.group.children) {
        DagCluster& child = dag.clusters[c];
        child.parent_group = gid;
        child.parent_error = r.group.error;
        child.parent_sphere = r.group.sphere;
        if (child.group != kNoGroup && --unconsumed[child.group] == 0)
          completed_groups.push_back(child.group);
        inputs += child.group != kNoGroup;  // level-0 clusters are final once consumed
      }
      pending.push_back(inputs);
      if (inputs == 0) ready.push_back(gid);
      for (NewCluster& nc : r.clusters) {
        const uint32_t cid = uint32_t(dag.clusters.size());
        DagCluster cluster;
        cluster.mesh = std::move(nc.mesh);
        cluster.locked = std::move(nc.locked);
        cluster.vertex_error = std::move(nc.vertex_error);
        cluster.level = level;
        cluster.group = gid;
        cluster.error = r.group.error;
        cluster.sphere = r.group.sphere;
        dag.clusters.push_back(std::move(cluster));
        b.position_ids.push_back(std::move(nc.ids));
        r.group.clusters.push_back(cid);
        next.push_back(cid);
      }
      unconsumed.push_back(uint32_t(r.group.clusters.size()));
      dag.groups.push_back(std::move(r.group));
      dag.levels = std::max(dag.levels, level + 1);
    }
    finish_groups(b, completed_groups, pending, ready);
    active = std::move(next);
    if (!any) {
      dag.stalled = true;
      break;
    }
  }
  copy_level0_vertices(b);  // when the build ended before level 1's grouping
  // The rest: the groups that made a root.
  std::vector<uint32_t> open_groups;
  for (uint32_t g = 0; g < dag.groups.size(); ++g)
    if (unconsumed[g] > 0) open_groups.push_back(g);
  finish_groups(b, open_groups, pending, ready);
  for (uint32_t c : active) {
    DagCluster& root = dag.clusters[c];
    root.parent_group = kNoGroup;
    root.parent_error = std::numeric_limits<float>::infinity();
    root.parent_sphere = root.sphere;
  }
  dag.roots = std::move(active);
  if (options.inputs_final && !ready.empty()) options.inputs_final(dag, ready);
  return std::move(dag);
}

}  // namespace lodstream::hierarchy
