// Residuals as byte planes: signed values zigzag-mapped (0, -1, 1, -2, ... -> 0, 1, 2, 3, ...) and split into
// planes, byte b of component a of every value together, so that the writer's per-page zstd models each byte
// position (mostly tiny low bytes, mostly zero high bytes) with its own statistics. Used by the predictive
// codecs (predictive_codec.hpp, traversal_codec.hpp) for position and normal residuals.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lodstream::package {

inline uint64_t zigzag(int64_t v) {
  return (static_cast<uint64_t>(v) << 1) ^ static_cast<uint64_t>(v >> 63);
}
inline int64_t unzigzag(uint64_t v) {
  return static_cast<int64_t>(v >> 1) ^ -static_cast<int64_t>(v & 1);
}
// Bytes needed for an unsigned value (1..8).
inline uint32_t bytes_for(uint64_t largest) {
  uint32_t n = 1;
  while (n < 8 && (largest >> (8 * n)) != 0) ++n;
  return n;
}

// Appends `values` (count = values.size() / components records of `components` zigzagged values each) as
// `width` byte planes: byte b of component a of record i at plane b * components + a, offset i.
// Cost: O(values.size() * width).
void put_planes(std::vector<uint8_t>& out, const std::vector<uint64_t>& values, uint32_t components,
                uint32_t width);

// Inverse of put_planes: unzigzags `count` records of `components` components stored as `width` planes into
// out[a * count + i] (one array per component, so each loop is a plain pass the compiler can vectorize).
// Forced inline, so that the decoders' AVX2 and AVX-512 builds (decode_predicted_vertices,
// decode_predicted_normals) vectorize it for their targets, where out of line it stayed baseline code (`bench
// decode --runs 1` under callgrind, decode_node with predict_positions inlined likewise:
// refined_elephant 45.49 -> 44.43 M instructions, elephant_1m 682.8 -> 670.1 M). Cost: O(count * components *
// width).
template <typename T>
[[gnu::always_inline]] inline void read_planes(const uint8_t* planes, size_t count, uint32_t components,
                                               uint32_t width, T* out) {
  for (uint32_t a = 0; a < components; ++a) {
    const uint8_t* low = planes + a * count;
    T* o = out + a * count;
    if (width == 1) {
      for (size_t i = 0; i < count; ++i) o[i] = T(int32_t(low[i] >> 1) ^ -int32_t(low[i] & 1));
    } else if (width == 2) {
      const uint8_t* high = planes + (components + a) * count;
      for (size_t i = 0; i < count; ++i) {
        const uint32_t z = low[i] | uint32_t(high[i]) << 8;
        o[i] = T(int32_t(z >> 1) ^ -int32_t(z & 1));
      }
    } else {
      for (size_t i = 0; i < count; ++i) {
        uint64_t value = 0;
        for (uint32_t b = 0; b < width; ++b)
          value |= uint64_t(planes[(b * components + a) * count + i]) << (8 * b);
        o[i] = T(unzigzag(value));
      }
    }
  }
}

}  // namespace lodstream::package
