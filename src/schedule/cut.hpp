// Cut selection (DESIGN.md, Data model and Client runtime): which nodes to draw for a view, a target pixel
// error tau and a triangle budget, from the nodes that are AVAILABLE (decoded in the cache) now.
//
// The unit of replacement is a group exchange: a group simplification turned the nodes G (its input, each
// with parents == P) into the nodes P (its output, each with children == G); G and P cover the same surface,
// so a cut replaces P by G as a whole, never a part of it. A cut is a set of refined exchanges; the drawn
// nodes are the roots and the G of every refined exchange, minus the P of every refined exchange.
//
// Invariant (of every cut returned): an exchange is refined only when every node of its P is drawn (so its
// surface is not covered twice) and every node of its G is available; hence the drawn nodes of an object
// cover its surface exactly once (no node drawn together with an ancestor or a descendant, no holes), and
// every drawn node is available. An object is drawn only when all of its representation's roots are
// available (else nothing of it is drawn: no partial object with holes).
//
// Rule: with every node available and no budget, the cut is exactly DESIGN.md's: a node is drawn when its own
// error projects to <= tau px and its parents' to > tau px. It is computed by greedy refinement from the
// roots: exchanges are refined in decreasing order of their P's projected error (ties by object, node id)
// while that error is > tau; an exchange whose G is not all available is skipped (its P stays drawn: the best
// available ancestor-level representation). Budget: the refinement stops at the first exchange that would
// take the triangles over the budget, so a budgeted cut is the threshold cut for a raised tau (reported as
// `tau`), the same for every object; the order does not depend on tau, so cuts are monotonic in tau (a
// larger tau gives a cut whose nodes are ancestors of, or equal to, the smaller tau's).
//
// Culling: an object whose representation bounds (as a sphere, under its transform) are outside the view
// frustum is skipped (nothing drawn, nothing missing). Nodes inside a visible object are not culled.
// Cost: O(n log n) in the nodes visited (drawn nodes plus the P nodes they replaced), twice (the available
// cut and the ideal cut that `missing` comes from). Pure computation; node records are looked up through
// NodeSource, so the caller decides what is known (index pages) and available (cache).
//
// HLOD (hierarchy/hlod.hpp; a representation of kind hlod, drawn without an object: its nodes are world
// space): the objects listed by its roots' records are covered; a covered object's own roots are not where
// its traversal starts. Instead the HLOD's roots are drawn, and an exchange replaces a proxy P by its
// children (G = the child proxies in the frustum) or, for a leaf proxy, by the roots of its objects in the
// frustum (then traversed as above). The same rule and order apply (P's projected error > tau, largest
// first); a leaf's exchange needs every root of its non-culled objects available. A proxy whose sphere is
// outside the frustum is neither drawn nor refined (its objects, inside its sphere, are culled). Proxy errors
// bound their objects' roots' errors and their spheres contain theirs, so the cut rule extends across HLOD ->
// objects. Until every HLOD root is available, nothing of a covered object is drawn (like an object whose
// roots are not all available).
//
// Progressive meshes (hierarchy/progressive_steps.hpp; a representation of kind progressive_mesh, its root
// step 0, each step's child the next step): steps 0..j are drawn TOGETHER (their union is the prefix mesh),
// so refining step k draws step k+1 and keeps k drawn (an exchange with P = {k}, G = {k+1} that removes
// nothing). The same rule and order apply: step k is refined while its own error (the prefix ending with it)
// projects to > tau, so j is the first step whose own error projects to <= tau (or the last available one);
// in the ideal cut the missing steps j+1.. carry parent_error_px = the previous prefix's projected error, so
// a scheduler ranks them like group exchanges. Budget: a step adds its own triangles. All steps share the
// object's sphere, so the errors along the chain are monotonic in pixels too. Drawn steps below the last are
// marked `refined`: their triangles are drawn, the object's error is the last one's.
// Not handled yet: imposters.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "package/index.hpp"
#include "schedule/screen_error.hpp"

namespace lodstream::schedule {

// Node records and availability as the client knows them.
class NodeSource {
 public:
  virtual ~NodeSource() = default;
  // Node `id`'s record, or nullptr while it is unknown (its index page has not arrived).
  virtual const package::NodeRecord* record(uint32_t id) const = 0;
  // Whether node `id`'s geometry is in the cache (drawable now).
  virtual bool available(uint32_t id) const = 0;
};

struct CutOptions {
  double tau = 1.0;  // target pixel error
  uint64_t triangle_budget = std::numeric_limits<uint64_t>::max();
};

// `object` is package::kNone for an HLOD proxy (world space; its record's `objects` are what it stands for).
struct DrawnNode {
  uint32_t object = 0, node = 0;
  double error_px = 0.0;  // its own error, projected
  uint32_t triangles = 0;
  // A progressive step whose next step is drawn too: part of the drawn prefix, but the object is drawn at the
  // last step's error (quality and benefit weigh only that one).
  bool refined = false;
};

// A node the ideal cut (every node available, same tau and budget) needs that is not available: what to
// fetch. `parent_error_px` is the projected error its group's arrival removes (its parents' error; +inf for a
// root; for the roots of an object covered by HLOD, its leaf proxy's): the natural priority for a scheduler.
// `object` is package::kNone for an HLOD proxy. For a node whose record is unknown, `record_known` is false
// and `error_px` is 0 (fetch its index page first); the ideal cut's traversal stops there.
struct MissingNode {
  uint32_t object = 0, node = 0;
  double error_px = 0.0;
  double parent_error_px = 0.0;
  bool record_known = true;
  // For the roots of an object covered by HLOD: the leaf proxy whose exchange they are (it must be drawn for
  // them to be); package::kNone otherwise.
  uint32_t proxy = package::kNone;
};

enum class ObjectState : uint8_t { drawn, culled, incomplete /* a root is not available */ };

struct Cut {
  std::vector<DrawnNode> drawn;      // sorted by (object, node)
  std::vector<MissingNode> missing;  // sorted by decreasing parent_error_px, then (object, node)
  std::vector<ObjectState> objects;  // per scene object
  uint64_t triangles = 0;            // of the drawn nodes
  uint64_t ideal_triangles = 0;      // of the ideal cut
  double tau = 0.0;                  // the tau the cut satisfies: options.tau, or more when the budget bound
  bool budget_limited = false;
  // Nothing is missing for this view: the drawn cut is the ideal cut.
  bool converged() const { return missing.empty(); }
};

// Object `object`'s bounding sphere in world space: its representation's bounds (centre, half diagonal) under
// its transform (radius scaled by the largest axis scale). What culling and the benefit ratio's A_i use.
WorldSphere object_sphere(const package::PackageScene& scene, uint32_t object);

// Node `r`'s own error projected for `view` (DESIGN.md's e_px): of `object` under its transform (error scaled
// by its largest axis scale), or for object package::kNone an HLOD proxy (world space).
double projected_error(const package::PackageScene& scene, uint32_t object, const package::NodeRecord& r,
                       const View& view);

// Selects the cut for `view` over `scene`'s objects. Throws lodstream::Error (naming the node) when node
// links do not form group exchanges (a G member's parents differ from P, a P member's children from G).
Cut select_cut(const package::PackageScene& scene, const NodeSource& nodes, const View& view,
               const CutOptions& options);

}  // namespace lodstream::schedule
