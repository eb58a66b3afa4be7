// Metro-style sampling of a triangle surface (Cignoni et al. 1998, "Metro: measuring error on simplified
// surfaces"): points spread over the surface in proportion to area, so that a maximum over them approximates
// the one-sided Hausdorff distance and an area-weighted mean over them the mean distance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.hpp"

namespace lodstream {

// The default number of area samples for a surface of `triangles` triangles: 2 per triangle, at least 100,000
// (so that a surface of a few large triangles is still sampled densely).
size_t default_area_samples(size_t triangles);

// Decides how many area samples each triangle gets and where they lie; generates them on demand, one triangle
// at a time, so that callers can visit millions of samples in parallel without storing them.
//
// Plan: N area samples are spread by systematic sampling over the cumulative area (triangle t gets
// floor(N·P(t+1)/A + u) − floor(N·P(t)/A + u) of them, P the prefix sum of triangle areas, A the total area,
// u a seeded offset in [0,1)), so each triangle gets the floor or ceiling of its expected share N·A_t/A; and
// at least one, so that no triangle, however small, goes unsampled. Within a triangle, the k samples are the
// first k points of the R2 low-discrepancy sequence (Roberts 2018: frac(o + i·(1/g, 1/g²)), g the plastic
// number) with a seeded per-triangle offset o (Cranley–Patterson rotation), folded onto the triangle ((s,t) →
// (1−s,1−t) when s+t > 1, which keeps the density uniform). Each sample stands for area A_t / k of the
// surface (its weight). Deterministic: the same mesh, N and seed give the same points on every machine and
// thread count.
class SurfaceSampler {
 public:
  // `surface` must outlive the sampler. Cost: O(T) time, 8 bytes per triangle.
  SurfaceSampler(const Mesh& surface, size_t area_samples, uint64_t seed);

  size_t triangle_count() const { return prefix_area_.size() - 1; }
  double total_area() const { return prefix_area_.back(); }
  double triangle_area(size_t t) const { return prefix_area_[t + 1] - prefix_area_[t]; }
  // Number of area samples of triangle t (at least 1). O(1).
  size_t sample_count(size_t t) const;
  // Sum of sample_count over all triangles. O(1).
  size_t total_samples() const { return total_samples_; }
  // Replaces `out` with triangle t's samples. O(sample_count(t)).
  void sample_triangle(size_t t, std::vector<glm::vec3>& out) const;

 private:
  const Mesh& surface_;
  std::vector<double> prefix_area_;  // T + 1 entries: area of triangles [0, t)
  double scale_ = 0;                 // N / A
  double offset_ = 0;                // u
  uint64_t seed_ = 0;
  size_t total_samples_ = 0;
};

}  // namespace lodstream
