#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"

namespace lodstream::package {

// Codec 1 until codec 2 decodes at the 25 M triangles per second per core that DESIGN.md requires: codec 2
// stores 30 % fewer bytes but decodes at about half codec 1's speed (bench_package, side by side).
const NodeCodec& default_node_codec() {
  return node_codec(MeshoptCodec::kId);
}

const NodeCodec& node_codec(uint32_t id) {
  static const MeshoptCodec meshopt;
  static const PredictiveCodec predictive;
  if (id == MeshoptCodec::kId) return meshopt;
  if (id == PredictiveCodec::kId) return predictive;
  throw Error("unknown node codec id " + std::to_string(id));
}

}  // namespace lodstream::package
