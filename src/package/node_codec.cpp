#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"

namespace lodstream::package {

const NodeCodec& default_node_codec() {
  return node_codec(PredictiveCodec::kId);
}

const NodeCodec& node_codec(uint32_t id) {
  static const MeshoptCodec meshopt;
  static const PredictiveCodec predictive;
  if (id == MeshoptCodec::kId) return meshopt;
  if (id == PredictiveCodec::kId) return predictive;
  throw Error("unknown node codec id " + std::to_string(id));
}

}  // namespace lodstream::package
