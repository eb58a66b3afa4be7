// Symmetric distance between two surfaces, Metro style (Cignoni, Rocchini, Scopigno 1998): sample each
// surface densely, measure each sample's exact distance to the other surface, combine both directions.
#pragma once

#include "core/mesh.hpp"
#include "core/scene.hpp"
#include "measure/reference_surface.hpp"

namespace lodstream {

// With h(A,B) = max_{a∈A} min_{b∈B} |a − b| (the one-sided Hausdorff distance, Book Fig. 3.1):
struct SurfaceDistance {
  OneSidedDistance a_to_b;  // samples of A measured against B: a_to_b.max estimates h(A,B)
  OneSidedDistance b_to_a;  // samples of B measured against A
  double hausdorff = 0;     // H(A,B) = max(h(A,B), h(B,A)), from the samples
  // Area-weighted over both surfaces: mean = (A_a·mean_ab + A_b·mean_ba) / (A_a + A_b), i.e. the mean
  // distance of a point drawn uniformly from the union of both surfaces to the other surface; rms likewise
  // with squares: rms = sqrt((A_a·rms_ab² + A_b·rms_ba²) / (A_a + A_b)).
  double mean = 0;
  double rms = 0;
  size_t samples = 0;  // a_to_b.samples + b_to_a.samples
};

// Distance between the world-space surfaces of two scenes (every object, transforms applied). Throws
// lodstream::Error when either has no triangles or holds invalid geometry. Cost: two BVH builds (O(T log T),
// parallel) and one exact closest-point query per sample; with the default sampling (every vertex plus 2
// samples per triangle) two 1M-triangle meshes take a few seconds on 2 cores. Deterministic for options.seed.
SurfaceDistance measure_surface_distance(const Scene& a, const Scene& b, const DistanceOptions& options = {});

// The same for two meshes in one coordinate system.
SurfaceDistance measure_surface_distance(const Mesh& a, const Mesh& b, const DistanceOptions& options = {});

}  // namespace lodstream
