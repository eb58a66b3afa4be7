// Data pages stored by part (package/page_parts.hpp): they round-trip, are smaller than whole pages for the
// byte-plane codecs, pages of non-codec bytes stay
// whole, and hostile regrouped bytes are errors.
#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/bytes.hpp"
#include "package/format.hpp"
#include "package/meshopt_codec.hpp"
#include "package/page_parts.hpp"
#include "package/predictive_codec.hpp"
#include "package/residual_coder.hpp"
#include "package/traversal_codec.hpp"
#include "package_fixture.hpp"
#include "support/expect_error.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

struct Page {
  std::vector<uint8_t> bytes;
  std::vector<uint32_t> node_sizes;
};

// A sphere with normals cut into chunks of 64 triangles, each encoded by `codec`, one after the other;
// `noise` moves each vertex by up to that much along each axis, as a scan's vertices lie off any regular
// pattern.
Page sphere_page(const NodeCodec& codec, float noise = 0.0f) {
  Mesh sphere = uv_sphere(1.0f, 24, 32);
  std::mt19937 rng(5);
  for (glm::vec3& p : sphere.positions)
    for (int a = 0; a < 3; ++a) p[a] += std::uniform_real_distribution<float>(-noise, noise)(rng);
  const PositionGrid grid = PositionGrid::for_bounds(sphere.bounds());
  std::vector<std::vector<uint8_t>> locked;
  Page page;
  for (const Mesh& chunk : split_into_chunks(sphere, 64, locked)) {
    NodeGeometry g;
    g.mesh = &chunk;
    const std::vector<uint8_t> node = codec.encode(g, grid);
    page.bytes.insert(page.bytes.end(), node.begin(), node.end());
    page.node_sizes.push_back(uint32_t(node.size()));
  }
  return page;
}

// The regrouped bytes a page stored by part decompresses to.
std::vector<uint8_t> content(std::span<const uint8_t> stored) {
  return zstd_decompress_at_most(stored, UINT32_MAX, "test");
}

// Where the form byte of part p (1 positions, 2 normals) of regrouped bytes lies
// (page_parts.hpp: seven size varints, then the seven streams).
size_t form_at(std::span<const uint8_t> regrouped, size_t p) {
  ByteReader r(regrouped, "test");
  uint64_t size[7];
  for (uint64_t& s : size) s = r.varint();
  size_t at = r.position();
  for (size_t q = 0; q < p; ++q) at += size[q];
  return at;
}

// The form bytes of the positions' and normals' parts of regrouped bytes.
std::pair<uint8_t, uint8_t> residual_forms(std::span<const uint8_t> regrouped) {
  return {regrouped[form_at(regrouped, 1)], regrouped[form_at(regrouped, 2)]};
}

class PageParts : public ::testing::TestWithParam<uint32_t> {};

INSTANTIATE_TEST_SUITE_P(Codecs, PageParts,
                         ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(PageParts, RoundTripByPartAndNoLargerThanWhole) {
  const NodeCodec& codec = node_codec(GetParam());
  const Page page = sphere_page(codec);
  ASSERT_GT(page.node_sizes.size(), 10u);
  const std::vector<uint8_t> stored = compress_page(page.bytes, page.node_sizes, codec, 9, 6);
  EXPECT_EQ(decompress_page(stored, uint32_t(page.bytes.size()), codec, "page"), page.bytes);
  const size_t whole = zstd_compress(page.bytes, 9, 6).size();
  EXPECT_LE(stored.size(), whole);
  if (GetParam() != MeshoptCodec::kId) {
    // Residual planes, connectivity and headers with tables of their own: stored by part, and smaller.
    EXPECT_NE(content(stored).size(), page.bytes.size());
    EXPECT_LT(stored.size(), whole);
    // The sphere's regular rings repeat their residuals, which zstd's matches find and an order-0 coder
    // cannot: its residuals stay planes.
    EXPECT_EQ(residual_forms(content(stored)), std::make_pair(uint8_t(0), uint8_t(0)));
  }
}

// Regrouped bytes `plain` with part p (1 positions, 2 normals) replaced by the form byte
// `form` and `bytes`, and where that part's form byte lies.
std::pair<std::vector<uint8_t>, size_t> with_part(std::span<const uint8_t> plain, size_t p, uint8_t form,
                                                  std::span<const uint8_t> bytes) {
  ByteReader r(plain, "test");
  uint64_t size[7];
  for (uint64_t& s : size) s = r.varint();
  const size_t at = form_at(plain, p);
  size[p] = 1 + bytes.size();
  ByteWriter w;
  for (uint64_t s : size) w.varint(s);
  const size_t out_at = w.bytes.size() + (at - r.position());
  w.raw(plain.subspan(r.position(), at - r.position()));
  w.u8(form);
  w.raw(bytes);
  w.raw(plain.subspan(form_at(plain, p + 1)));
  return {std::move(w.bytes), out_at};
}

TEST(PageParts, NoisyResidualsAreStoredCodedAndSmaller) {
  for (uint32_t id : {PredictiveCodec::kId, TraversalCodec::kId}) {  // the byte-plane codecs
    const NodeCodec& codec = node_codec(id);
    const Page page = sphere_page(codec, 0.01f);
    const std::vector<uint8_t> stored = compress_page(page.bytes, page.node_sizes, codec, 9, 6);
    EXPECT_EQ(decompress_page(stored, uint32_t(page.bytes.size()), codec, "page"), page.bytes);
    // Positions coded; the normals, coded in the frame of their prediction (predicted_normals.hpp), are
    // spread so evenly here that the coded form saves under kMinSavedBits on them: either form.
    EXPECT_GE(residual_forms(content(stored)).first, 1u) << "codec " << id;  // coded, one stream or split
    EXPECT_LT(stored.size(), zstd_compress(page.bytes, 9, 6).size());
  }
}

// The regrouped bytes of the noisy sphere's page by codec 3 with its normals' part in the paired form
// (residual_coder.hpp; the writer keeps it on scans, not on the sphere, whose normals zstd stores in fewer
// bytes), and where that part's form byte lies.
std::pair<std::vector<uint8_t>, size_t> paired_normals(const Page& page) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const std::vector<uint8_t> plain = content(compress_page(page.bytes, page.node_sizes, codec, 9, 6));
  const size_t at = form_at(plain, 2);
  EXPECT_EQ(plain[at], 0u);
  // The nodes' normal planes, one after the other in the part, as residuals (node by node, component 0
  // then component 1).
  std::vector<uint64_t> values;
  std::vector<uint32_t> counts;
  size_t node_at = 0, planes_at = at + 1;
  for (uint32_t node_size : page.node_sizes) {
    const NodeSizeBreakdown b = codec.breakdown(std::span(page.bytes).subspan(node_at, node_size), "test");
    const size_t count = b.normal_low / 2;
    std::vector<int64_t> residuals(2 * count);
    if (count)
      read_planes(plain.data() + planes_at, count, 2, uint32_t(b.normals / b.normal_low), residuals.data());
    for (int64_t v : residuals) values.push_back(zigzag(v));
    counts.push_back(uint32_t(count)), node_at += node_size, planes_at += b.normals;
  }
  EXPECT_EQ(planes_at, form_at(plain, 3));
  return with_part(plain, 2, 3, encode_paired_residuals(values, counts));
}

// The normals' part in the paired form decodes back; a set out of range is an error, and so is the paired
// form in the positions' part.
TEST(PageParts, NormalsInThePairedFormDecodeBack) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const Page page = sphere_page(codec, 0.01f);
  const uint32_t raw_size = uint32_t(page.bytes.size());
  const auto [good, at] = paired_normals(page);
  auto unpack = [&](const std::vector<uint8_t>& regrouped) {
    return decompress_page(zstd_compress(regrouped, 1), raw_size, codec, "page 7");
  };
  EXPECT_EQ(unpack(good), page.bytes);
  std::vector<uint8_t> bad = good;
  bad[at + 1] = 8;  // the set: residual_tables::kSets
  expect_error_naming("page 7", "set out of range", [&] { unpack(bad); });
  bad = good;
  bad[form_at(good, 1)] = 3;
  expect_error_naming("page 7", "positions in the paired form", [&] { unpack(bad); });
  std::mt19937 rng(11);
  for (int i = 0; i < 400; ++i) {
    bad = good;
    for (int k = 0; k < 1 + i % 3; ++k) bad[at + 1 + rng() % (form_at(good, 3) - at - 1)] = uint8_t(rng());
    try {
      EXPECT_EQ(unpack(bad).size(), raw_size);
    } catch (const Error&) {
    }
  }
}

// Into a kept buffer: the page is its first raw-size bytes whatever it held before (a larger page's bytes
// here), it grows when smaller and never shrinks, for both forms (by part, and whole).
TEST_P(PageParts, AKeptBufferTakesPagesOfAnySize) {
  const NodeCodec& codec = node_codec(GetParam());
  const Page page = sphere_page(codec);
  const uint32_t raw_size = uint32_t(page.bytes.size());
  const std::vector<uint8_t> by_part = compress_page(page.bytes, page.node_sizes, codec, 9, 6);
  const std::vector<uint8_t> whole = zstd_compress(page.bytes, 1);
  for (const std::vector<uint8_t>* stored : {&by_part, &whole}) {
    std::vector<uint8_t> buffer(raw_size + 100, 0xab);
    std::span<const uint8_t> out = decompress_page(*stored, raw_size, codec, "page", buffer);
    EXPECT_EQ(out.data(), buffer.data());
    EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.end()), page.bytes);
    EXPECT_EQ(buffer.size(), raw_size + 100);
    buffer.resize(10);
    out = decompress_page(*stored, raw_size, codec, "page", buffer);
    EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.end()), page.bytes);
    EXPECT_EQ(buffer.size(), raw_size);
  }
}

// ByteReader::varint reads the bytes at hand without a check each: a varint that ends within them reads as
// it did byte by byte, and one truncated or longer than 10 bytes is still an error naming its position.
TEST(PageParts, VarintsReadAtOnceKeepTheirErrors) {
  std::vector<uint8_t> bytes;
  for (uint64_t v : {uint64_t(0), uint64_t(127), uint64_t(128), uint64_t(300), UINT64_MAX}) {
    for (; v >= 0x80; v >>= 7) bytes.push_back(uint8_t(v | 0x80));
    bytes.push_back(uint8_t(v));
  }
  ByteReader r(bytes, "varints");
  for (uint64_t v : {uint64_t(0), uint64_t(127), uint64_t(128), uint64_t(300), UINT64_MAX})
    EXPECT_EQ(r.varint(), v);
  EXPECT_TRUE(r.at_end());
  auto error_of = [](const std::vector<uint8_t>& b) {
    ByteReader x(b, "stream");
    try {
      x.varint();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of({0x80, 0x80}), "stream at byte 2: truncated varint (1 bytes needed, 0 left)");
  EXPECT_EQ(error_of(std::vector<uint8_t>(11, 0x80)), "stream at byte 10: varint longer than 10 bytes");
}

TEST(PageParts, PagesOfNonCodecBytesAreStoredWhole) {
  std::vector<uint8_t> bytes(3000);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t(i * 7 % 251);
  const std::vector<uint32_t> sizes = {1000, 1500, 500};
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const std::vector<uint8_t> stored = compress_page(bytes, sizes, codec, 9, 6);
  EXPECT_EQ(content(stored).size(), bytes.size());
  EXPECT_EQ(decompress_page(stored, uint32_t(bytes.size()), codec, "page"), bytes);
}

TEST(PageParts, HostileRegroupedBytesAreErrorsOrPagesOfTheRightSize) {
  const NodeCodec& codec = node_codec(TraversalCodec::kId);
  const Page page = sphere_page(codec, 0.01f);  // positions in the coded form
  const uint32_t raw_size = uint32_t(page.bytes.size());
  const std::vector<uint8_t> good = content(compress_page(page.bytes, page.node_sizes, codec, 9, 6));
  ASSERT_NE(good.size(), raw_size);
  ASSERT_GE(residual_forms(good).first, 1u);
  auto unpack = [&](const std::vector<uint8_t>& regrouped) {
    return decompress_page(zstd_compress(regrouped, 1), raw_size, codec, "page 7");
  };
  EXPECT_EQ(unpack(good), page.bytes);
  auto expect_error = [&](const std::vector<uint8_t>& regrouped, const char* what) {
    expect_error_naming("page 7", what, [&] { unpack(regrouped); });
  };
  std::vector<uint8_t> bad = good;
  bad.push_back(0);
  expect_error(bad, "a byte of no node");
  bad = good;
  bad.pop_back();
  expect_error(bad, "a missing byte");
  bad = good;
  bad[0] ^= 1;  // the header stream's size
  expect_error(bad, "stream sizes");
  expect_error(std::vector<uint8_t>(2 * size_t(raw_size) + 65, 0), "larger than any regrouping");
  bad = good;
  bad[form_at(good, 1)] = 3;  // the positions' form: none of the three
  expect_error(bad, "residual part form");

  std::mt19937 rng(7);
  for (int i = 0; i < 400; ++i) {
    bad = good;
    for (int k = 0; k < 1 + i % 4; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    try {
      EXPECT_EQ(unpack(bad).size(), raw_size);  // bytes the codec itself checks when it decodes the nodes
    } catch (const Error&) {
    }
  }
}

}  // namespace
}  // namespace lodstream::test
