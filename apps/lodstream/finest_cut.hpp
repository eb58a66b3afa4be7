// The finest cut (DESIGN.md, Measuring quality: what the `full` policy fetches and draws, and the
// full-resolution scene that image metrics compare against): every finest-level node (a node with no
// children) of every object in the view frustum. Shared by the simulator, bench stream's reference frames and
// `view --order full`.
#pragma once

#include <cstdint>
#include <vector>

#include "package/index.hpp"
#include "schedule/cut.hpp"

namespace lodstream::cli {

// Per representation of `scene`: the ids of its nodes with no children (HLOD proxies excluded: the finest
// level is the objects' own geometry), and every step of a progressive mesh (its finest prefix), among
// records 0..node_count-1 of `records` (every record must be known). Cost: one pass over the records.
std::vector<std::vector<uint32_t>> finest_nodes(const package::PackageScene& scene,
                                                const schedule::NodeSource& records, uint32_t node_count);

// The data pages holding the nodes of `finest` (finest_nodes' result), sorted: file order.
std::vector<uint32_t> finest_pages(const schedule::NodeSource& records,
                                   const std::vector<std::vector<uint32_t>>& finest);

// The finest cut for `view`: each object in the frustum drawn with every node of `finest` for its
// representation, each with its projected error (schedule::screen_error of its error under the object's
// transform); objects outside are culled. Cost: O(objects + drawn nodes).
schedule::Cut finest_cut(const package::PackageScene& scene, const schedule::NodeSource& records,
                         const std::vector<std::vector<uint32_t>>& finest, const schedule::View& view);

}  // namespace lodstream::cli
