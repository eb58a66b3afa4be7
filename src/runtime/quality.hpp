// Per-frame quality of a cut (DESIGN.md, Measuring quality), for tests, benchmarks and the CSV of
// `view --headless`:
//   pixel error: the screen-space error of what is drawn for each visible object (the largest e_px of its
//     drawn nodes), max and mean over the drawn objects;
//   benefit ratio = sum_i A_i alpha_i / sum_i A_i over the objects i in the view frustum, A_i = screen area
//     (pixels, clipped to the viewport) of object i's bounding sphere's projection, alpha_i = the
//     area-weighted mean over its drawn nodes of min(1, tau / e_px(node)) (weights: each node's sphere's
//     clipped screen area), 0 when nothing of it is drawn. It is 1 exactly when everything visible is drawn
//     at tau or better. An object covered by a drawn HLOD proxy (cut.hpp) is drawn at the proxy's error:
//     its alpha_i is min(1, tau / e_px(proxy)) and its pixel error the proxy's. A progressive mesh is drawn
//     at its last drawn step's error (the steps below it, `refined`, are not counted).
// Pure computation; cost O(drawn nodes) plus a 256-strip integration per sphere.
#pragma once

#include "package/index.hpp"
#include "runtime/selection.hpp"

namespace lodstream::runtime {

struct FrameQuality {
  double pixel_error_max = 0.0;   // 0 when nothing is drawn
  double pixel_error_mean = 0.0;  // over drawn objects
  double benefit_ratio = 0.0;     // 1 when no object is in the frustum (nothing to wish for)
  uint32_t visible_objects = 0;   // objects in the frustum (A_i counted)
};

// Quality of `cut` (from select_cut over the same scene, nodes and view) for target error `tau`.
FrameQuality frame_quality(const package::PackageScene& scene, const NodeSource& nodes, const Cut& cut,
                           const View& view, double tau);

}  // namespace lodstream::runtime
