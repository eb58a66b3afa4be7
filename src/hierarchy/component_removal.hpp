// The hierarchy's last fallback for a group that edge collapse cannot reduce: whole closed components
// dropped (a soup of small closed parts, where each part is already as coarse as edge collapse allows and
// the DAG otherwise stalled with every part a root). Vertex clustering (simplify::cluster_mesh) was tried
// first and rejected: it can leave a dropped triangle's edges open, a crack in a cut.
//
// A component (triangles connected through shared positions) may go only when none of its vertices is
// locked: then it shares no position with another group and is not on the mesh's open boundary (locked by
// DagOptions::lock_open_boundary, the default), so it is closed and its removal opens no edge, and the finer
// clusters it came from belong to this group alone (cuts stay crack-free). Components go nearest-first (the
// distance from a component's farthest vertex to the nearest vertex kept) until the target is met; at least
// one component stays.
//
// Bound (two-sided, added to the simplification's): every point of a dropped component C lies in the convex
// hull of its vertices, so within e_C = min over kept vertices v of max over c in C of |c - v| of the kept
// surface; the kept surface is unchanged, so the other direction holds as before. Returns max e_C.
#pragma once

#include <cstdint>
#include <span>

#include "core/mesh.hpp"

namespace lodstream::hierarchy {

// Drops the triangles of unlocked components of `mesh` (locked: one flag per vertex) nearest-first until it
// has at most `target_triangles` triangles or none is left to drop; vertices stay (per-vertex data of the
// caller keeps its numbering), those of dropped components unreferenced. Cost: O(T + V) for the components
// plus O(V_dropped x V_kept) distances (a group holds about a thousand vertices).
// Returns the bound: max e_C over the dropped components, model units (0 when none).
double remove_components(Mesh& mesh, std::span<const uint8_t> locked, size_t target_triangles);

}  // namespace lodstream::hierarchy
