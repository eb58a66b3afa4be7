// The plane prediction of the predictive codecs (predictive_node.hpp, kPlanePrediction) and the split form of
// a page's position residuals (page_parts.hpp): the encoder chooses the plane prediction on irregular smooth
// surfaces (a coarse level's vertices, off the parallelogram along the surface) and not where the
// parallelogram is exact, such nodes decode to the quantized positions, their pages store the dominant axis'
// residuals in a stream of their own and round-trip, and a hostile split form is an error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/node_header.hpp"
#include "package/page_parts.hpp"
#include "package/predictive_codec.hpp"
#include "package/predictive_node.hpp"
#include "package/traversal_codec.hpp"
#include "package_fixture.hpp"
#include "support/expect_error.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

bool plane_predicted(std::span<const uint8_t> node) {
  ByteReader r(node, "node");
  return NodeHeader::read(r, node[0], 255, node.size()).flags & kPlanePrediction;
}

class PlanePrediction : public ::testing::TestWithParam<uint32_t> {};

INSTANTIATE_TEST_SUITE_P(Codecs, PlanePrediction,
                         ::testing::Values(PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(PlanePrediction, ChosenOnIrregularSmoothSurfacesAndDecodesToTheQuantizedPositions) {
  const NodeCodec& codec = node_codec(GetParam());
  // The flat regular grid: the parallelogram is exact; the slid sphere's chunks (clusters of a coarse
  // level): off it along the surface.
  std::vector<std::pair<Mesh, bool>> cases = {{grid(12), false}};
  std::vector<std::vector<uint8_t>> locked;
  for (Mesh& chunk : split_into_chunks(slid_sphere(1), 128, locked))
    cases.emplace_back(std::move(chunk), true);
  for (const auto& [m, plane] : cases) {
    const PositionGrid pg = PositionGrid::for_bounds(m.bounds(), 14);
    NodeGeometry g;
    g.mesh = &m;
    const std::vector<uint8_t> node = codec.encode(g, pg);
    EXPECT_EQ(plane_predicted(node), plane);
    const DecodedNode d = codec.decode(node, pg, "node");
    ASSERT_EQ(d.mesh.vertex_count(), m.vertex_count());
    expect_near_input(d.mesh, m, 0.87f * pg.step);
  }
}

// The position part's form byte of a page stored by part (page_parts.hpp: seven size varints, the header
// stream, then the positions' part) and where it lies.
size_t position_form_at(std::span<const uint8_t> regrouped) {
  ByteReader r(regrouped, "test");
  uint64_t size[7];
  for (uint64_t& s : size) s = r.varint();
  return r.position() + size[0];
}

TEST(PlanePrediction, PagesStoreTheDominantAxisApartAndHostileSplitsAreErrors) {
  // Codec 2: codec 3 predicts some of these chunks from two parallelograms (kMultiParallelogram), and its
  // page then keeps the residuals in one stream.
  const NodeCodec& codec = node_codec(PredictiveCodec::kId);
  const Mesh sphere = slid_sphere(3);
  const PositionGrid pg = PositionGrid::for_bounds(sphere.bounds(), 14);
  std::vector<std::vector<uint8_t>> locked;
  std::vector<uint8_t> page;
  std::vector<uint32_t> sizes;
  for (const Mesh& chunk : split_into_chunks(sphere, 128, locked)) {
    NodeGeometry g;
    g.mesh = &chunk;
    const std::vector<uint8_t> node = codec.encode(g, pg);
    EXPECT_TRUE(plane_predicted(node));
    page.insert(page.end(), node.begin(), node.end());
    sizes.push_back(uint32_t(node.size()));
  }
  const std::vector<uint8_t> regrouped =
      zstd_decompress_at_most(compress_page(page, sizes, codec, 9, 6), UINT32_MAX, "test");
  const size_t at = position_form_at(regrouped);
  ASSERT_EQ(regrouped[at], 2u);  // the split form
  auto unpack = [&](const std::vector<uint8_t>& bytes) {
    return decompress_page(zstd_compress(bytes, 1), uint32_t(page.size()), codec, "page 3");
  };
  EXPECT_EQ(unpack(regrouped), page);
  auto expect_error = [&](const std::vector<uint8_t>& bytes, const char* what) {
    expect_error_naming("page 3", what, [&] { unpack(bytes); });
  };
  std::vector<uint8_t> bad = regrouped;
  bad[at + 1] ^= 0x40;  // the first stream's size (a varint)
  expect_error(bad, "first stream's size");
  bad = regrouped;
  bad[at + 1] = 0;  // no first stream: its values past its end
  expect_error(bad, "empty first stream");
  bad = regrouped;
  bad[at] = 3;  // no form
  expect_error(bad, "form");
}

}  // namespace
}  // namespace lodstream::test
