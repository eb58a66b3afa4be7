// Cut selection, screen error and screen area live in the schedule module (the server's scheduler runs them
// too); the client's runtime names them here, once, so its code reads as before the move.
#pragma once

#include "schedule/cut.hpp"
#include "schedule/screen_area.hpp"
#include "schedule/screen_error.hpp"

namespace lodstream::runtime {

using schedule::Cut;
using schedule::DrawnNode;
using schedule::in_frustum;
using schedule::max_scale;
using schedule::NodeSource;
using schedule::object_sphere;
using schedule::ObjectState;
using schedule::projected_area;
using schedule::screen_error;
using schedule::select_cut;
using schedule::to_world;
using schedule::View;
using schedule::WorldSphere;

}  // namespace lodstream::runtime
