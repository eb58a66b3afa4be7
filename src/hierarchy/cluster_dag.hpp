// Cluster DAG of one large mesh (DESIGN.md, Data model; Nanite / batched multi-triangulation style, seed
// 001's multiresolution DAG built bottom-up):
//   level 0: the mesh split into clusters of at most 128 triangles (clusterize.hpp);
//   each level: the active clusters are partitioned into groups of about 8 neighbours (METIS on the cluster
//   adjacency weighted by shared edges, group_partition.hpp); each group is merged and simplified to about
//   group_ratio (0.4) of its triangles with its outer border locked (positions shared with clusters of other
//   groups, and the mesh's own open boundary), and the result is split into new clusters (once the active
//   clusters hold at most 2 * group_clusters * max_cluster_triangles triangles, they form one group); repeat
//   until the active clusters hold at most `root_triangles` triangles (or one cluster), or no group of a
//   level can be reduced.
// Fallbacks (recorded per group, like meshoptimizer's clusterlod): a group that does not reach 85 % of its
// triangles with attributes is retried positions-only with a looser normal limit, then whole closed
// components without a locked vertex are dropped from its result, nearest first (component_removal.hpp: a
// soup of small closed parts that edge collapse cannot reduce); a group still above 85 % is abandoned and
// its clusters stay active for the next level (with other neighbours); the build always
// terminates because every accepted group removes triangles, and a level where none is accepted ends it.
//
// Errors (totals, object units): every cluster vertex carries the simplifier's radius r_v against the
// full-resolution surface (simplify.hpp's invariant; 0 at level 0), and a group is simplified starting from
// its input clusters' radii (Options::vertex_error), so the result's radii bound its distance to the
// full-resolution surface directly. The clusters made by group g all share (error_g, sphere_g) with
// error_g = max(max over g's input clusters of their error, max over g's result of r_v), rounded up to float:
// monotonic, and a two-sided bound to the full-resolution surface built from per-vertex histories rather
// than a sum of per-level bounds (max input error + g's bound against its input: elephant_1m's 1 px cuts
// drew 10-27 % more triangles with it). sphere_g contains the input clusters' spheres and the output
// geometry. Input radii are raised to a floor first (radii_floor.hpp). Each input cluster of
// g stores (error_g, sphere_g) as its parents' pair. Cut rule (cut.hpp): draw a cluster when its own error
// projects to <= tau and its parents' to > tau; because border positions are locked bit for bit, the selected
// clusters form a crack-free surface.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/mesh.hpp"

namespace lodstream::hierarchy {

inline constexpr uint32_t kNoGroup = UINT32_MAX;

struct ClusterDag;

struct DagOptions {
  // The DAG's shape (bake --cluster-triangles, --group-clusters, --group-ratio). A DAG stores about T / (1 -
  // group_ratio) triangles in about log(T / root_triangles) / log(1 / group_ratio) levels; a smaller ratio
  // stores fewer, but a cut then steps further past tau between levels and draws more. Measured (codec 3;
  // package bytes; triangles drawn near / mid / far by render --pixel-error 1 at 1280x720 from eyes
  // (0.5,0.2,0.6) / (1.5,0.5,1.5) / (4,1.5,4) at the origin, motorBike examples/cameras front / side /
  // above; bench stream gen:fly at 10 Mbit/s 80 ms: oracle's mean triangles, push's time to benefit 0.95),
  // ratio 0.5 -> 0.45 (0.4):
  //   elephant_1m 5,382,094 -> 4,834,941 B, -10.2 % (-18.8 %), 14 -> 12 (11) levels, drawn 449k / 221k / 68k
  //   -> 430k / 200k / 74k (443k / 211k / 79k), fly 413k -> 397k (406k), push 1.27 -> 1.23 (1.07) s;
  //   elephant_5m 3.775 -> 3.374 (3.031) B per input triangle, drawn 943k / 317k / 95k -> 885k / 316k / 108k
  //   (916k / 366k / 137k); city 5.852 -> 5.361 (4.966);
  //   motorBike 2,006,676 -> 1,847,461 B, -7.9 % (-14.3 %), drawn 156k / 154k / 155k -> 160k / 155k / 158k
  //   (172k / 172k / 171k), fly 163k -> 169k (180k), push 1.17 -> 1.13 (1.10) s.
  // 0.45 is 8-11 % smaller, streams no slower and draws -10..+14 % per view (-5 / -3 / +2 % over the three
  // views of elephant_1m / elephant_5m / motorBike); 0.4 draws up to +44 % (elephant_5m far), 0.33 up to +74
  // % (elephant_1m far). Clusters of 256 triangles (elephant_1m -9.6 % bytes at 0.5) drew 5-22 % more, groups
  // of 16 clusters (-6.3 %) 21-31 % more: a coarser unit of selection refines more than it needs.
  // Measured again with errors from carried radii (tighter at coarse levels), 0.4 against 0.45 with summed
  // errors: elephant_5m 2.551 -> 2.269 B per input triangle and fewer drawn (1,428k / 642k / 217k -> 1,289k /
  // 538k / 203k), motorBike -6.8 % (+6..+9 % drawn), but the city's push / oracle reach benefit 0.95 at 1.40
  // / 1.37 s instead of 0.93 / 0.87 (its buildings object's errors at levels 4-8 grow to 77-150 against <=
  // 22). The stall was the scheduler's (page_scheduler.cpp: a chain of groups that keep a fallback's error,
  // compared strictly where the carried error comes back 0.002 % lower); with that fixed, 0.4 against 0.45
  // (format 9, bench stream as above, sse-pull / push / oracle to benefit 0.95): city 21,640,103 ->
  // 20,080,919 B, 1.40 / 0.83 / 0.77 -> 1.43 / 0.80 / 0.73 s; motorBike 1,585,487 -> 1,475,160 B, 1.07 / 1.00
  // / 0.93 -> 1.00 / 0.97 / 0.90 s, drawn 155k / 153k / 155k -> 170k / 169k / 170k (PSNR +0.17 / -0.19 /
  // +1.00 dB); elephant_1m 3,600,587 -> 3,227,007 B, 1.20 / 0.90 / 0.83 -> 1.03 / 0.87 / 0.80 s, drawn 498k /
  // 244k / 95k -> 520k / 245k / 103k (PSNR +0.33 / +0.96 / -3.35 dB, far 63.3 -> 60.0 dB); elephant_5m
  // 2.383 -> 2.127 B per input triangle. Fewer bytes and faster streams for up to +11 % drawn: 0.4.
  size_t max_cluster_triangles = 128;  // divisible by 4, at most 512 (meshoptimizer's meshlet limit)
  size_t max_cluster_vertices = 128;   // at most 255
  size_t group_clusters = 8;           // target clusters per group
  double group_ratio = 0.4;            // target triangles after simplifying a group, as a fraction
  double stuck_ratio = 0.85;           // a group above this fraction after the fallbacks is abandoned
  size_t root_triangles = 256;         // stop when the active clusters hold at most this many
  uint32_t max_levels = 48;
  // Lock the mesh's open boundary at every level: its outline stays exact, which makes "the cut's boundary
  // edges are the original boundary edges" an exact test. Costs reduction on meshes with long open borders.
  bool lock_open_boundary = true;
  // Attribute weights of the group simplification (simplify::Options); the fallback uses 0.
  float normal_weight = 0.01f, uv_weight = 0.05f, color_weight = 0.05f;
  // Called with (level, active triangles) after each level.
  std::function<void(uint32_t, size_t)> progress;
  // Called with groups whose input clusters (DagGroup::children) are final (mesh, locked flags, error,
  // sphere and parent fields), each group exactly once, in an order that does not depend on thread timing,
  // at the same time as the next level's grouping (METIS, one core), so that work on them (encoding a page
  // group) fills the other core: a group of level-0 clusters once it is accepted, a coarser group once every
  // group that made one of its inputs has had all its clusters consumed (their locked flags are complete
  // then); what is left when the build ends, at the end. During a call nothing modifies the DAG; the call
  // may use every core (TBB).
  std::function<void(const ClusterDag&, std::span<const uint32_t>)> inputs_final;
};

struct DagCluster {
  Mesh mesh;  // its own vertices (positions and the input's attributes), <= 128 triangles
  // Per vertex: its position is on the border of the group that made or consumes this cluster or one of its
  // siblings (clusters made by the same group). Such positions are shared with clusters of other groups that
  // may be drawn beside it, so a codec must store them exactly (position shift 0 for them).
  std::vector<uint8_t> locked;
  // Per vertex: r_v against the full-resolution surface (model units); empty at level 0 (all 0) and once
  // an accepted group has consumed the cluster.
  std::vector<float> vertex_error;
  uint32_t level = 0;                // 0 = finest
  uint32_t group = kNoGroup;         // the group simplification that made it (kNoGroup at level 0)
  uint32_t parent_group = kNoGroup;  // the group that consumes it (kNoGroup for a root)
  float error = 0.0f;                // its own (error, sphere): its group's
  Sphere sphere;
  float parent_error = std::numeric_limits<float>::infinity();  // its parents' pair; +inf for a root
  Sphere parent_sphere;
};

enum class GroupOutcome : uint8_t {
  halved,              // reached the target with attributes
  partial,             // accepted with less reduction than the target (under stuck_ratio)
  positions_only,      // accepted only by the positions-only fallback
  components_dropped,  // accepted only after dropping whole closed components (component_removal.hpp)
};

struct DagGroup {
  uint32_t level = 1;              // level of the clusters it made
  std::vector<uint32_t> children;  // input clusters
  std::vector<uint32_t> clusters;  // clusters it made
  float error = 0.0f;
  Sphere sphere;
  size_t input_triangles = 0, output_triangles = 0;
  GroupOutcome outcome = GroupOutcome::halved;
};

struct ClusterDag {
  std::vector<DagCluster> clusters;
  std::vector<DagGroup> groups;
  std::vector<uint32_t> roots;  // clusters nobody consumes (the coarsest cut)
  uint32_t levels = 0;          // cluster levels (1 = only the full-resolution clusters)
  size_t input_triangles = 0;
  size_t abandoned_groups = 0;  // groups abandoned (their clusters retried at the next level)
  bool stalled = false;         // the build ended because no group of a level could be reduced
};

// Builds the DAG (options.inputs_final receives its groups as their input clusters become final). Degenerate
// triangles (a repeated index) are dropped; an empty mesh gives an empty DAG. Cost: about twice the cost of
// simplifying the whole mesh once (every level simplifies group_ratio of the previous one), groups of a level
// in parallel (TBB); memory about 60 bytes per input triangle for the clusters. Never throws on odd input
// (non-manifold, many tiny components, degenerate). The mesh is taken by value and released once its level-0
// clusters have their vertex data (copied beside level 1's grouping): move it in to avoid a copy (18 bytes
// per triangle of peak memory).
ClusterDag build_cluster_dag(Mesh mesh, const DagOptions& options = {});

}  // namespace lodstream::hierarchy
