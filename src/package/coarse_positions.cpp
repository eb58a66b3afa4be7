#include "package/coarse_positions.hpp"

#include <bit>

#include "core/error.hpp"

namespace lodstream::package {

std::vector<uint8_t> encode_locked_stream(const QuantizedNode& node, uint32_t k) {
  std::vector<uint8_t> out;
  if (k == 0) return out;
  const size_t V = node.locked.size();
  out.resize((V + 7) / 8, 0);
  // A locked vertex whose k low bits are all 0 is not flagged: its c (floor and rounding agree) decodes to
  // q as a free vertex's does.
  std::vector<uint8_t> flagged(V, 0);
  for (size_t v = 0; v < V; ++v) {
    for (int a = 0; a < 3; ++a) flagged[v] |= node.locked[v] && node.q[3 * v + a] != node.c[3 * v + a] << k;
    if (flagged[v]) out[v / 8] |= static_cast<uint8_t>(1u << (v % 8));
  }
  size_t bit = 0;
  for (size_t v = 0; v < V; ++v) {
    if (!flagged[v]) continue;
    for (int a = 0; a < 3; ++a) {
      const uint64_t low = static_cast<uint64_t>(node.q[3 * v + a] - (node.c[3 * v + a] << k));
      for (uint32_t b = 0; b < k; ++b, ++bit) {
        if (bit % 8 == 0) out.push_back(0);
        out.back() |= static_cast<uint8_t>(((low >> b) & 1u) << (bit % 8));
      }
    }
  }
  return out;
}

LockedStream LockedStream::parse(std::span<const uint8_t> stream, size_t vertices, uint32_t k,
                                 const std::string& where) {
  LockedStream s{stream, vertices, k};
  if (k == 0) {
    if (!stream.empty()) throw Error(where + ": locked stream without a position shift");
    return s;
  }
  const size_t flag_bytes = (vertices + 7) / 8;
  if (stream.size() < flag_bytes) throw Error(where + ": locked stream too short");
  size_t locked_count = 0;
  for (size_t i = 0; i < flag_bytes; ++i) locked_count += std::popcount(stream[i]);
  if (vertices % 8 && (stream[vertices / 8] >> (vertices % 8)))
    throw Error(where + ": locked bits past the last vertex");
  if (stream.size() != flag_bytes + (locked_count * 3 * k + 7) / 8)
    throw Error(where + ": locked stream size does not match its locked vertices");
  return s;
}

void decode_positions(std::span<const int64_t> c, const LockedStream& locked, const PositionGrid& grid,
                      glm::vec3* positions) {
  const size_t V = locked.vertices;
  const uint32_t k = locked.k;
  auto position = [&](int a, int64_t q) { return grid.origin[a] + static_cast<float>(q) * grid.step; };
  if (k == 0) {
    for (size_t v = 0; v < V; ++v)
      for (int a = 0; a < 3; ++a) positions[v][a] = position(a, c[3 * v + a]);
    return;
  }
  const uint8_t* flags = locked.stream.data();
  const uint8_t* residuals = flags + (V + 7) / 8;
  const size_t residual_bytes = locked.stream.size() - (V + 7) / 8;
  const uint64_t mask = (uint64_t(1) << k) - 1;
  size_t bit = 0;
  for (size_t v = 0; v < V; ++v) {
    const bool is_locked = (flags[v / 8] >> (v % 8)) & 1;
    for (int a = 0; a < 3; ++a) {
      int64_t q = c[3 * v + a] * (int64_t(1) << k);
      if (is_locked) {
        // k ≤ 24 bits at bit offset ≤ 7 lie in 4 bytes; parse() checked that they exist.
        uint64_t window = 0;
        for (size_t b = 0; b < 4 && bit / 8 + b < residual_bytes; ++b)
          window |= uint64_t(residuals[bit / 8 + b]) << (8 * b);
        q += static_cast<int64_t>((window >> (bit % 8)) & mask);
        bit += k;
      }
      positions[v][a] = position(a, q);
    }
  }
}

}  // namespace lodstream::package
