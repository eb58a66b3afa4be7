// Screen area of a bounding sphere's projection: the A_i of DESIGN.md's benefit ratio (Measuring quality) and
// the visibility factor of the scheduler's benefit (seed 003: accuracy x visibility). Pure computation.
#pragma once

#include "schedule/screen_error.hpp"

namespace lodstream::schedule {

// Screen area in pixels, clipped to the viewport, of the projection of `sphere`. The projection is taken as
// the disc of radius f r / sqrt(D^2 - r^2) around the projected centre (f = focal_pixels(), D = distance of
// the centre; exact on the view axis, slightly small off it, where the true outline is an ellipse). A disc
// inside the viewport is pi rho^2; one crossing its border is clipped exactly (the disc's area in each
// quadrant box about its centre in closed form, summed over the viewport's corners; was 256 strips of chords,
// 256 square roots a call and a relative error up to 1e-3: over a quarter of the push server's planning).
// Cost: O(1), up to eight square roots and four arcsines. A sphere that reaches the plane through the eye
// covers the whole viewport (width * height); one entirely behind it covers 0.
double projected_area(const WorldSphere& sphere, const View& view);

}  // namespace lodstream::schedule
