// From a node's stored coarse coordinates back to positions: the locked stream (a bit per vertex, then the k
// low bits of x, y, z of each locked vertex, packed LSB first; empty when k = 0) and the one formula
//   p = origin + float(c * 2^k + low) * step     (low = 0 for free vertices)
// that every codec decodes with, so that equal finest-grid coordinates give bit-identical positions in every
// node (crack-free cuts).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "package/quantized_node.hpp"

namespace lodstream::package {

// The locked stream of a quantized node stored at shift k (empty when k = 0); a locked vertex whose k low
// bits are all 0 is flagged as free (it decodes alike and stores no low bits: elephant_1m 1.3 KB less, the
// ~1/8 of locked vertices at shift 1 that lie on even grid points). Cost: O(V).
std::vector<uint8_t> encode_locked_stream(const QuantizedNode& node, uint32_t k);

// A validated locked stream: its size matches V, k and the number of locked vertices, and no flag lies past
// the last vertex. Throws lodstream::Error starting with `where`. Cost: O(V / 8).
struct LockedStream {
  std::span<const uint8_t> stream;
  size_t vertices = 0;
  uint32_t k = 0;
  static LockedStream parse(std::span<const uint8_t> stream, size_t vertices, uint32_t k,
                            const std::string& where);
};

// positions[v] from coarse coordinates c (x y z per vertex, |c| ≤ 2^32) by the formula above. Cost: O(V).
void decode_positions(std::span<const int64_t> c, const LockedStream& locked, const PositionGrid& grid,
                      glm::vec3* positions);

}  // namespace lodstream::package
