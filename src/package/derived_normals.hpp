// Normals derived on the client (DESIGN.md, Targets: "normals derived on the client where the source's are
// smooth"), by the encoder alone: decoders are unchanged. A vertex whose fan is closed inside its node (every
// triangle around it is one of the node's) has all its triangles at hand, so its prediction
// (predicted_normals.hpp: the area-weighted sum of their face normals over the decoded positions, Gouraud's
// smooth normal, what import computes for a mesh without normals, io/weld.hpp; or its one-ring smoothing,
// whichever the node uses) is the normal of the surface as decoded. Where the stored normal lies within one
// code step of it (its codes in the prediction's frame are 0 or +-1), the encoder stores (0, 0), which
// decodes to the prediction itself: the closed vertex takes the decoded surface's own normal, and its codes
// become nearly all zeros, which the page's residual coder stores in a small fraction of a bit. A vertex on
// the node's border (its fan continues in other nodes, which must decode it alike), on a hole, a seam or a
// crease (import splits a vertex there, and each copy's fan is open) keeps its codes.
//
// Which fans are closed is read from the triangles: a vertex's fan is closed when the sum, over the node's
// triangles (a, b, c) at it, of next minus previous corner (b - c at a) is 0 in wrapping 32-bit arithmetic:
// a consistently oriented closed fan passes each neighbour once as next and once as previous; an open fan
// leaves first - last, never 0. A vertex of no triangle is open.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace lodstream::package {

// open[v] = 1 for v < V when v's fan among the triangles of `indices` whose corners are all in the node
// (index - first_vertex below V, as predicted_normals counts them) is not closed (above), else 0. Returns the
// number of open vertices. Cost: O(T + V), one pass over the corners.
// The most normal bits at which the encoder derives closed vertices' normals: 9, level 0's (and progressive
// meshes') by default, and the coarse levels' 7 and 6 (bake --coarse-normal-bits), where the codes already
// round toward the prediction (predicted_normals.cpp's dead zone); more bits, a precision asked for
// explicitly, keep their codes, as they keep nearest rounding. Measured (bake, render at 1 px against the
// full model, the usual three cameras), level 0 only: refined_elephant 291,609 -> 288,725 B (-1.0 %), PSNR
// near 47.636 -> 47.629 dB, mid and far unchanged; elephant_1m 3,226,511 -> 3,127,899 B (-3.1 %), near
// 47.797 -> 47.786 dB; horse -0.6 %, near -0.012 dB; bunny -0.06 %, motorBike -0.02 % (their normals are
// the files' own). Every level too (format 11, against level 0 only): refined_elephant 261,306 -> 256,618 B
// (-1.8 %), PSNR near / mid / far 47.628 / 51.023 / 56.549 -> 47.600 / 50.943 / 56.511 dB (the same
// triangles; a coarse cluster's normals are carried from the finer surface it stands for, its own surface's
// differ more); elephant_1m 2,972,234 -> 2,898,959 (-2.5 %), motorBike 1,419,523 -> 1,409,394 (-0.7 %),
// bunny 245,519 -> 242,819 (-1.1 %), horse 317,095 -> 312,104 (-1.6 %). Deriving at 8 bits only where one
// of the two codes is 0: refined_elephant 259,701 B (-0.6 %), PSNR -0.015 / -0.041 / -0.032 dB, a worse
// trade. At 7 bits alone (shift >= 2): -0.23 %, renders unchanged (no such cluster drawn at 1 px).
constexpr uint32_t kDerivedNormalBits = 9;

uint32_t open_vertices(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                       std::vector<uint8_t>& open);

// Sets to (0, 0) the codes (zigzagged, 2 per vertex, as normal_residuals gives them) of every closed vertex
// (open[v] == 0) whose two codes are 0 or +-1 (above). Returns how many it changed. Cost: O(V).
uint32_t derive_closed_normals(std::span<uint64_t> codes, std::span<const uint8_t> open);

}  // namespace lodstream::package
