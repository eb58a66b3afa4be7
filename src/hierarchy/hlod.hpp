// HLOD (DESIGN.md, Data model; LOD book, glossary "hierarchical LOD"): a bounding-volume hierarchy over a
// scene's objects whose nodes carry a merged, simplified proxy of the objects below, so that a distant part
// of a scene with many objects is drawn as a few proxies instead of every object's coarsest nodes.
//   BVH: top-down over the objects' world bounds; a node of more than `leaf_objects` objects is split into
//   `branching` parts by repeatedly halving its largest part at the median of the object centres along the
//   longest axis of their extent (a median split keeps the tree balanced: depth log_b(objects / leaf)).
//   Proxies, bottom-up (nodes of one level in parallel): a leaf proxy merges its objects' coarsest
//   representations (in world space, as the caller gives them), an inner proxy merges its children's proxies;
//   the merge is simplified (quadric edge collapse with vertex clustering allowed, so separate parts may
//   fuse; the default attribute weights, so UVs and colours are interpolated) to min(max_proxy_triangles,
//   ratio x its input).
// Materials: a proxy whose parts share one material keeps it, with the parts' UVs (when all have them: their
//   texture applies as on the objects) and colours. Parts of several materials make a proxy of
//   `mixed_material` (the caller's untextured white material) whose vertex colours are each part's material
//   base colour times its vertex colours; a textured part then shows its base colour factor only.
// Errors are totals in world units with the cluster DAG's semantics, from carried radii as in the DAG: each
// coarse vertex carries r_v against its object's full resolution (HlodObject::coarse_error), a proxy is
// simplified from its parts' radii (floored, radii_floor.hpp) and its vertices carry the result's;
// error(node) = max(errors of what it replaces (its children's proxies, or its objects' coarsest
// representations), largest result radius + `position_tolerance` (what the package's quantization adds)),
// rounded up to float; so errors are monotonic up the tree and across HLOD -> object roots. (The sum of the
// largest replaced error and the proxy's own bound, used before, counts both maxima where they rarely meet.)
// sphere(node) contains the spheres of what it replaces and its own proxy's vertices. The cut rule (draw a
// node when its own error projects to <= tau and its parent's to > tau) then extends from the HLOD root down
// to each object's roots. Coarse objects stay out of the HLOD (drawn from their own roots, never under a
// proxy): those whose coarse error exceeds both `coarse_median_factor` x the median of the objects' coarse
// errors and `coarse_scene_fraction` of the scene's diagonal. A proxy's error is at least its objects', so
// one such object would make every proxy above it as coarse as it is, and its neighbours drawn at that error
// until it is refined: the city's two buildings objects have root errors 91 and 75 where the median of its
// 806 objects is 0.055 and the largest of the 804 motorbike parts 1.86 (34 x the median); a layout of copies
// of one model (all errors equal) keeps every object. A scene of at most one object (after that) has no HLOD
// (an empty result): a proxy would only duplicate that object.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "core/bounds.hpp"
#include "core/mesh.hpp"

namespace lodstream::hierarchy {

inline constexpr uint32_t kNoHlodNode = UINT32_MAX;

// One object as the HLOD sees it, in world space.
struct HlodObject {
  Bounds bounds;  // of the whole object (its centre orders the BVH split)
  // Its coarsest representation (e.g. its cluster DAG's roots), transformed to world space; normals optional
  // (computed from the triangles when absent).
  Mesh coarse;
  float error = 0.0f;  // of `coarse` against the object's full resolution, world units
  // Per vertex of `coarse`: r_v against the object's full resolution, world units (a cluster DAG's roots'
  // DagCluster::vertex_error scaled); empty: `error` at every vertex.
  std::vector<float> coarse_error;
  Sphere sphere;  // contains `coarse` and everything the object's own cut may draw (its roots' spheres)
};

struct HlodOptions {
  size_t leaf_objects = 4;              // objects per leaf, at most
  size_t branching = 4;                 // children per inner node, at most
  size_t max_proxy_triangles = 2048;    // budget of one proxy
  double ratio = 0.5;                   // a proxy keeps at most this fraction of its merged input
  float position_tolerance = 0.0f;      // added to every error and radius (the package's rounding)
  double coarse_median_factor = 100.0;  // coarse objects stay out (above): error > this x the median
  double coarse_scene_fraction = 0.01;  // and > this fraction of the scene's diagonal
  // Base colour (linear RGBA) of each material the objects use; empty: a proxy of several materials takes
  // the most used one, positions and normals only.
  std::vector<glm::vec4> material_colors;
  uint32_t mixed_material = 0;  // material of proxies of several materials (white, untextured)
};

struct HlodNode {
  Mesh mesh;  // the proxy: world space, normals, UVs / colours as the header says, one material
  float error = 0.0f;
  Sphere sphere;
  uint32_t level = 1;  // 1 = leaf (its children are objects), parents one more than their highest child
  uint32_t parent = kNoHlodNode;
  std::vector<uint32_t> children;     // HLOD nodes; empty for a leaf
  std::vector<uint32_t> objects;      // every object below, sorted (a leaf: the objects it replaces)
  double simplification_bound = 0.0;  // this proxy's own simplification bound
  std::vector<float> vertex_error;    // per proxy vertex: r_v against the full resolution, world units
};

struct Hlod {
  std::vector<HlodNode> nodes;  // nodes[root] first; parents before children (breadth-first)
  uint32_t root = kNoHlodNode;  // kNoHlodNode when there is no HLOD
  uint32_t levels = 0;
};

// Builds the HLOD of `objects` (object i = index i). Cost: one simplification per node of at most
// branching x max_proxy_triangles triangles (leaves: their objects' coarse meshes), so about
// O(objects / leaf_objects x proxy cost); memory: the proxies. Never throws on odd input (empty or
// degenerate coarse meshes give empty proxies).
Hlod build_hlod(std::span<const HlodObject> objects, const HlodOptions& options = {});

}  // namespace lodstream::hierarchy
