// The view samples a client reports (what the pull scheduler predicts from, what a push server is told): a
// camera's pose with its motion measured between two poses, as a schedule::ViewSample or a wire::ViewUpdate.
#pragma once

#include "core/camera.hpp"
#include "net/wire.hpp"
#include "schedule/motion.hpp"

namespace lodstream::cli {

// `camera`'s pose at `time_s`, with the motion that takes pose `from` to pose `to` in `dt_s` seconds (> 0):
//   velocity = (eye_to - eye_from) / dt,
//   angular velocity = axis * angle / dt, axis = forward_from x forward_to normalised, angle =
//   atan2(|forward_from x forward_to|, forward_from . forward_to) (the rotation turning one view direction
//   into the other; zero when they are parallel).
// A path passes (pose(t), pose(t + dt)); an interactive camera its previous and current poses. O(1).
schedule::ViewSample view_sample(const Camera& camera, double time_s, const Camera& from, const Camera& to,
                                 double dt_s);

// The sample as the wire's view update.
wire::ViewUpdate view_update(const schedule::ViewSample& sample);

}  // namespace lodstream::cli
