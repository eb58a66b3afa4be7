#include "measure/surface_sampling.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream {

namespace {
// SplitMix64 (Steele, Lea, Flood 2014): a seeded, well-mixed 64-bit hash of a counter.
uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

double unit_double(uint64_t bits) {
  return double(bits >> 11) * 0x1.0p-53;
}  // in [0, 1)
}  // namespace

size_t default_area_samples(size_t triangles) {
  return std::max<size_t>(2 * triangles, 100000);
}

SurfaceSampler::SurfaceSampler(const Mesh& surface, size_t area_samples, uint64_t seed)
    : surface_(surface), seed_(seed) {
  const size_t triangles = surface.triangle_count();
  prefix_area_.resize(triangles + 1);
  prefix_area_[0] = 0.0;
  for (size_t t = 0; t < triangles; ++t)
    prefix_area_[t + 1] = prefix_area_[t] + 0.5 * double(triangle_double_area(surface, t));
  const double area = prefix_area_.back();
  scale_ = area > 0.0 ? double(area_samples) / area : 0.0;
  offset_ = unit_double(splitmix64(seed));
  // With no area at all (scale 0), every degenerate triangle still gets its one sample.
  for (size_t t = 0; t < triangles; ++t) total_samples_ += sample_count(t);
}

size_t SurfaceSampler::sample_count(size_t t) const {
  const double k =
      std::floor(scale_ * prefix_area_[t + 1] + offset_) - std::floor(scale_ * prefix_area_[t] + offset_);
  return std::max<size_t>(1, size_t(k));
}

void SurfaceSampler::sample_triangle(size_t t, std::vector<glm::vec3>& out) const {
  // R2 sequence steps: 1/g and 1/g², g the plastic number (the real root of x³ = x + 1).
  constexpr double g = 1.32471795724474602596;
  constexpr double alpha1 = 1.0 / g, alpha2 = 1.0 / (g * g);
  const uint64_t h = splitmix64(seed_ ^ splitmix64(uint64_t(t) + 1));
  const double o1 = unit_double(h), o2 = unit_double(splitmix64(h));
  const uint32_t* v = &surface_.indices[3 * t];
  const glm::vec3 a = surface_.positions[v[0]];
  const glm::vec3 ab = surface_.positions[v[1]] - a, ac = surface_.positions[v[2]] - a;
  const size_t k = sample_count(t);
  out.resize(k);
  for (size_t i = 0; i < k; ++i) {
    double s = o1 + double(i) * alpha1, r = o2 + double(i) * alpha2;
    s -= std::floor(s);
    r -= std::floor(r);
    if (s + r > 1.0) {
      s = 1.0 - s;
      r = 1.0 - r;
    }
    out[i] = a + float(s) * ab + float(r) * ac;
  }
}

}  // namespace lodstream
