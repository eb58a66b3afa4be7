// Conservative rounding of the (error, sphere) pairs of node records, so that the index stores them in few
// bytes (index.hpp, "compact pair"): errors are rounded up to 16 significant bits, spheres to a grid of
// 2^-kSphereGridBits of their radius (2^-kZeroErrorSphereGridBits for a pair of error 0) (centre rounded to
// the grid, radius grown by the centre's move plus one step, then rounded up to the grid), and every
// invariant inspect --verify checks still holds exactly:
//   - errors stay monotonic (rounding up to 16 bits is a non-decreasing function of the error);
//   - a rounded sphere contains the exact one (decoded vertices, HLOD objects' bounds stay inside);
//   - a node's sphere stays inside its parents' sphere: a pair's rounded sphere is kept only when it lies
//     inside the final sphere of every pair that is its parents' pair somewhere (when it does not: its
//     centre on the corners of its grid cell, then the same without the step of margin, then each grid
//     twice as fine, down to 2^-15 of the radius); else the exact sphere is kept, which the parents' final
//     sphere contains (it contains their exact one, which contained it);
//   - a node's parents' pair stays bit-for-bit its parents' own pair (rounding is per distinct pair).
// Pairs of roots (a node without parents, and the +infinity parents' pair of a root) keep their exact
// spheres: other representations' proxies (HLOD) are built to contain them.
#pragma once

#include <cstdint>
#include <span>

#include "core/bounds.hpp"
#include "package/index.hpp"

namespace lodstream::package {

// Why 6 (lead, measured: bake, inspect --parts, render at 1 px from three cameras): a sphere's centre costs
// about grid bits + 2 per coordinate against the previous pair's, so each bit less saves ~3 bits a distinct
// pair; at 10 / 8 / 7 / 6 / 5 / 4 elephant_1m's package is 4,153,943 / 4,137,082 / 4,127,827 / 4,113,846 /
// 4,105,135 / 4,097,110 B and its 1 px cut from near 549,068 / same / same / 549,632 / 550,196 / 551,612
// triangles (mid and far views, refined_elephant's and motorBike's three views unchanged throughout;
// motorBike 1,704,373 -> 1,696,450 B at 6). 6 keeps the spheres' growth below 3 x 2^-6 = 4.7 % and the
// cuts within 0.1 %.
inline constexpr int kSphereGridBits = 6;
// The grid of a pair of error 0 (a finest node's own: drawn whenever its parents are not, so its sphere
// serves frustum culling and screen-area weights, never a screen error); finer grids follow as for any pair.
// Why 2 (idxsize, format 13, with the cell's corners and every grid tried as pair_rounding.cpp's decide
// does; sizeindex on format 12 had found 3 / 2 equal, 6,769 / 6,765 B, when most spheres at 2 fell back
// to a grid 2^3 times finer): at 3 / 2 / 1 refined_elephant's index pages are 5,743 / 5,509 / 5,501 B,
// elephant_1m's 122,602 / 119,141 / 117,046 B, the city's at 3 / 2 382,141 / 372,308 B; at 2 the 1 px
// renders of refined_elephant, bunny, horse, motorBike, elephant_1m and the city (three cameras each) are
// the same images as at 3, and bench stream's times to benefit 0.95 (elephant_1m, motorBike, city) the
// same. A finest sphere's radius at 2 is 1.11x its radius at 3 on average (elephant_1m, city; at most
// 1.40x); its growth over the exact sphere at most about 3 x 2^-2.
inline constexpr int kZeroErrorSphereGridBits = 2;

// e rounded up to a float whose low 8 mantissa bits are zero (16 significant bits): relative change below
// 2^-15. 0, +infinity and values that would round to infinity are returned unchanged.
float round_error_up(float e);

// The smallest sphere on the grid of step 2^(floor(log2 radius) - grid_bits) that contains `s` with one step
// of margin, or `s` when it has no such grid (zero or subnormal radius, or a centre more than 2^24 steps from
// the origin). Relative growth of the radius: at most about 3 x 2^-grid_bits.
Sphere round_sphere_out(const Sphere& s, int grid_bits = kSphereGridBits);

// Rounds the pairs of `nodes` (own and parents') as the header describes. Cost: O(nodes x parents' pairs per
// pair) with an ordered map of the distinct pairs.
void round_pairs(std::span<NodeRecord> nodes);

}  // namespace lodstream::package
