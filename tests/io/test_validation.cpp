// Bad input of every kind gives a one-line lodstream::Error naming the file, never a crash.
#include <gtest/gtest.h>

#include "files.hpp"
#include "io/export.hpp"
#include "io/validate.hpp"
#include "support/shapes.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

void expect_error(const std::filesystem::path& file, const std::string& words) {
  std::string message = import_error(file);
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find(words), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

const char* kHeader =
    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

std::string binary_triangle(int index2) {
  std::string b = kHeader;
  float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  b.append(reinterpret_cast<const char*>(v), sizeof v);
  b += char(3);
  int32_t idx[3] = {0, 1, index2};
  b.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return b;
}

}  // namespace

TEST(Validation, GoodBinaryTriangleLoads) {
  EXPECT_EQ(import_model(write_file("ok.ply", binary_triangle(2))).triangle_count(), 1u);
}

TEST(Validation, TruncatedBinaryPly) {
  std::string b = binary_triangle(2);
  expect_error(write_file("truncated.ply", b.substr(0, b.size() - 5)), "byte offset");
  expect_error(write_file("truncated_vertices.ply", b.substr(0, std::string(kHeader).size() + 20)), "bytes");
}

TEST(Validation, BadIndex) {
  expect_error(write_file("bad_index.ply", binary_triangle(7)), "vertex 7");
  expect_error(write_file("negative_index.ply", binary_triangle(-1)), "references vertex");
  expect_error(write_file("bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "vertex 3");
  expect_error(write_file("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "9");
}

TEST(Validation, NanAndInfinity) {
  expect_error(write_file("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"), "vertex 1");
  expect_error(write_file("inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 -inf 0\n3 0 1 2\n"), "non-finite");
  std::string b = binary_triangle(2);
  float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(b.data() + std::string(kHeader).size() + 4, &nan, 4);
  expect_error(write_file("nan.ply", b), "vertex 0");
}

TEST(Validation, EmptyModels) {
  expect_error(write_file("empty.off", "OFF\n0 0 0\n"), "no triangles");
  expect_error(write_file("empty.obj", "# nothing\n"), "no triangles");
  expect_error(write_file("zero_bytes.ply", ""), "not a PLY file");
  expect_error(
      write_file("points.ply", std::string(kHeader).substr(0, std::string(kHeader).find("element face")) +
                                   "end_header\n" + std::string(36, '\0')),
      "no triangles");
}

TEST(Validation, GarbageBytes) {
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage += char((i * 7919 + 13) % 256);
  expect_error(write_file("garbage.ply", garbage), "not a PLY file");
  expect_error(write_file("garbage.off", garbage), "not an OFF file");
  expect_error(write_file("garbage_header.ply", "ply\nformat binary_little_endian 1.0\n" + garbage),
               "bad PLY header");
  expect_error(write_file("garbage_body.off", "OFF\n3 1 0\n" + garbage.substr(0, 100)), "garbage_body.off:");
}

TEST(Validation, HugeDeclaredCounts) {
  std::string header = kHeader;
  header.replace(header.find("vertex 3"), 8, "vertex 1000000000000");
  expect_error(write_file("huge.ply", header + std::string(64, '\0')), "declares 1000000000000");
  std::string faces = kHeader;
  faces.replace(faces.find("face 1"), 6, "face 99999999999");
  expect_error(write_file("huge_faces.ply", faces + std::string(64, '\0')), "declares 99999999999");
  expect_error(write_file("huge.off", "OFF\n4000000000 9000000000 0\n0 0 0\n"), "declares 4000000000");
  std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 123456789012\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n";
  expect_error(write_file("huge_ascii.ply", ascii), "declares 123456789012");
}

TEST(Validation, DegenerateTrianglesAreDroppedAndCounted) {
  // Two good triangles, one with a repeated corner, one collinear.
  auto file =
      write_file("degenerate.off",
                 "OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n1 1 1\n3 0 1 2\n3 1 4 2\n3 0 0 1\n3 0 1 3\n");
  testing::internal::CaptureStderr();
  Scene s = import_model(file);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_NE(err.find("dropped 2 degenerate"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

TEST(Validation, MissingFileAndUnknownPlyFormat) {
  expect_error(temp_dir() / "missing.ply", "no such file");
  expect_error(write_file("fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"), "unknown format");
}

// A mesh large enough to be checked on several cores: the error names the first bad triangle in index order,
// and the degenerate triangles spread over it are dropped with the order of the others kept.
TEST(Validation, LargeMeshNamesTheFirstBadTriangleAndKeepsOrder) {
  const Mesh good = sphere(1.0f, 200, 200);  // 79,600 triangles
  Mesh bad = good;
  for (size_t t : {size_t(70000), size_t(41234), size_t(60000)}) bad.indices[3 * t + 1] = 1000000;
  try {
    validate_mesh(bad, "big");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "big: triangle 41234 references vertex 1000000, but there are only " +
                                         std::to_string(good.vertex_count()) + " vertices");
  }
  Mesh degenerate = good;
  std::vector<uint32_t> expected;
  for (size_t t = 0; t < good.triangle_count(); ++t) {
    uint32_t* i = &degenerate.indices[3 * t];
    if (t % 1000 == 7) {
      i[2] = i[0];  // a repeated corner
      continue;
    }
    expected.insert(expected.end(), i, i + 3);
  }
  const ValidationCounts counts = validate_mesh(degenerate, "big");
  EXPECT_EQ(counts.degenerate_triangles, good.triangle_count() - expected.size() / 3);
  EXPECT_EQ(degenerate.indices, expected);
}
