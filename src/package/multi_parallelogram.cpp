#include "package/multi_parallelogram.hpp"

namespace lodstream::package {

void find_parallelograms(std::span<const uint32_t> indices, uint32_t first_vertex, uint32_t V,
                         Parallelograms& out) {
  const size_t T = indices.size() / 3;
  // Per vertex, its kept half-edges: (end << 16 | third corner of the triangle).
  thread_local std::vector<uint8_t> leaving_count;
  thread_local std::vector<uint32_t> leaving;
  leaving_count.assign(V, 0);
  leaving.resize(size_t(kMaxLeaving) * V);
  out.count.assign(V, 0);
  out.corners.resize(size_t(3 * kMaxParallelograms) * V);
  auto keep = [&](uint32_t from, uint32_t end, uint32_t third) {
    const uint32_t n = leaving_count[from];
    if (n == kMaxLeaving) return;
    leaving[size_t(kMaxLeaving) * from + n] = end << 16 | third;
    leaving_count[from] = uint8_t(n + 1);
  };
  const uint32_t* idx = indices.data();
  for (size_t t = 0; t < T; ++t) {
    const uint32_t a = idx[3 * t] - first_vertex, b = idx[3 * t + 1] - first_vertex,
                   c = idx[3 * t + 2] - first_vertex;
    if ((a >= V) | (b >= V) | (c >= V) | (a == b) | (b == c) | (c == a)) continue;
    // v the largest corner, x -> y the triangle's edge opposite it; the triangle across holds y -> x.
    uint32_t v = a, x = b, y = c;
    if (b > v && b > c) v = b, x = c, y = a;
    if (c > v && c > b) v = c, x = a, y = b;
    const uint32_t n = out.count[v];
    const uint32_t* h = &leaving[size_t(kMaxLeaving) * y];
    const uint32_t kept = n < kMaxParallelograms ? leaving_count[y] : 0;
    for (uint32_t i = 0; i < kept; ++i) {
      if ((h[i] >> 16) != x) continue;
      if (const uint32_t z = h[i] & 0xffff; z < v) {
        uint16_t* to = &out.corners[3 * (size_t(kMaxParallelograms) * v + n)];
        to[0] = uint16_t(x), to[1] = uint16_t(y), to[2] = uint16_t(z);
        out.count[v] = uint8_t(n + 1);
      }
      break;
    }
    keep(a, b, c), keep(b, c, a), keep(c, a, b);
  }
}

}  // namespace lodstream::package
