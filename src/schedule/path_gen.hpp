// Generated camera paths fitted to a scene's bounds (issue 6: `bench stream --path gen:NAME`), for scenes
// that have no recorded path. With c the bounds' centre, r half their diagonal and `up` the scene's up axis,
// a and b two horizontal axes (perpendicular to up; a is the world axis least aligned with up, projected):
//   orbit     one turn in 12 s at distance 1.8 r and height 0.4 r, looking at c;
//   fly       entering the scene: from 3 r out along a (height 0.6 r) to 1.2 r along (a + b)/sqrt 2 (height
//             0.3 r) at 6 s, to 0.6 r along b (height 0.15 r) at 12 s, looking at c; about 0.3 r per second,
//             a walk through the scene whatever its units (model units are not always metres);
//   drive     a straight pass at 3.6x the fly's speed: 4 r across the scene in 4 s, offset 0.5 r along b at
//             height 0.08 r, looking ahead;
//   teleport  four views from 1.5 r on +a, +b, -a, -b (height 0.3 r), each held 3 s, with a jump of one
//             millisecond between them (teleports() finds them).
// Key frames every 0.5 s where the pose moves. Pure computation.
#pragma once

#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "schedule/camera_path.hpp"

namespace lodstream::schedule {

struct PathGenOptions {
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_degrees = 60.0f;
  int width = 1280, height = 720;
};

// The names gen: accepts, in the order of the header comment.
const std::vector<std::string>& generated_path_names();

// The path `name` (orbit, fly, drive, teleport) fitted to `bounds` (world space, not empty). Throws
// lodstream::Error naming the known paths for an unknown name, or for empty bounds or a zero up vector.
CameraPath generate_path(const std::string& name, const Bounds& bounds, const PathGenOptions& options = {});

// Times at which `path` lands after a jump: the end of every key-frame segment shorter than `max_jump_s` (a
// teleport of
// generate_path lasts 1 ms). Cost: O(key frames).
std::vector<double> teleports(const CameraPath& path, double max_jump_s = 1.0 / 30.0);

}  // namespace lodstream::schedule
