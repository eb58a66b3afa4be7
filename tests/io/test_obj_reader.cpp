// The parallel OBJ reader: what it reads, that chunk borders anywhere (inside an object, after a `usemtl`, in
// the middle of a face line) change nothing, and that bad input names the line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "files.hpp"
#include "io/obj_reader.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

template <class V>
bool same_bits(const V& a, const V& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}

void expect_same_scene(const Scene& a, const Scene& b, size_t chunk_bytes) {
  SCOPED_TRACE("chunk_bytes " + std::to_string(chunk_bytes));
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].name, b.objects[i].name);
    EXPECT_EQ(a.objects[i].mesh, b.objects[i].mesh);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) EXPECT_EQ(a.materials[i].name, b.materials[i].name);
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    EXPECT_TRUE(same_bits(a.meshes[i].positions, b.meshes[i].positions)) << "mesh " << i;
    EXPECT_TRUE(same_bits(a.meshes[i].normals, b.meshes[i].normals)) << "mesh " << i;
    EXPECT_TRUE(same_bits(a.meshes[i].uvs, b.meshes[i].uvs)) << "mesh " << i;
    EXPECT_TRUE(same_bits(a.meshes[i].colors, b.meshes[i].colors)) << "mesh " << i;
    EXPECT_EQ(a.meshes[i].indices, b.meshes[i].indices) << "mesh " << i;
    EXPECT_EQ(a.meshes[i].material, b.meshes[i].material) << "mesh " << i;
  }
}

// An attribute per corner, through the mesh's indices.
template <class T>
std::vector<T> at_corners(const Mesh& mesh, const std::vector<T>& attribute) {
  std::vector<T> out;
  for (uint32_t i : mesh.indices) out.push_back(attribute.at(i));
  return out;
}

// Reads `file` with chunks of every size from 1 byte to the whole file: all must equal the one-chunk read,
// which is returned.
Scene read_with_every_chunk_size(const std::filesystem::path& file) {
  const size_t size = std::filesystem::file_size(file);
  Scene whole = read_obj(file, size + 1);
  for (size_t chunk = 1; chunk <= size; ++chunk) expect_same_scene(whole, read_obj(file, chunk), chunk);
  return whole;
}

// The error names file and line, whatever the chunk size.
void expect_line_error(const std::string& name, const std::string& text, int line, const std::string& words) {
  const auto file = write_file(name, text);
  for (size_t chunk : {size_t(1), size_t(2), size_t(5), size_t(9), size_t(1) << 20}) {
    const std::string message = error_of([&](const auto& f) { read_obj(f, chunk); }, file);
    EXPECT_NE(message.find(file.string() + ":" + std::to_string(line) + ": "), std::string::npos)
        << message << " (chunk " << chunk << ")";
    EXPECT_NE(message.find(words), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

}  // namespace

TEST(ObjReader, ObjectsMaterialsRelativeIndicesAndQuadsAcrossChunkBorders) {
  write_file("colours.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  const auto file =
      write_file("scene.obj",
                 "# a comment line\r\n"
                 "mtllib colours.mtl\r\n"
                 "v 0 0 0\nv 1 0 0\nv 3 1 0\nv 0 1 0\n"
                 "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                 "o wall\n"
                 "usemtl red\n"
                 "f 1/1/1 2/2/1 3/3/1 4/1/1\n"  // |p3 - p1|^2 = 10 > |p4 - p2|^2 = 2: split [1 2 4] [2 3 4]
                 "usemtl blue\n"
                 "  f -4/-3/-1 -3/-2/-1 -2/-1/-1  \n"  // relative: vertices 1 2 3
                 "g floor tiles\n"                     // the material stays blue
                 "v 0 0 2\nv 3 0 2\nv 1 1 2\nv 0 1 2\n"
                 "f 5 6 7 8\n"  // |p7 - p5|^2 = 2 < |p8 - p6|^2 = 10: split [5 6 7] [5 7 8]
                 "usemtl red\n"
                 "f -1 -2 -3\n"
                 "o\n"  // no name: ignored, as before
                 "f 1 2 4\n");
  const Scene s = read_with_every_chunk_size(file);
  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[0].name, "wall/red");
  EXPECT_EQ(s.objects[1].name, "wall/blue");
  EXPECT_EQ(s.objects[2].name, "floor tiles/blue");
  EXPECT_EQ(s.objects[3].name, "floor tiles/red");
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "red");
  EXPECT_EQ(s.materials[0].base_color, glm::vec4(1, 0, 0, 1));

  const Mesh& wall_red = s.meshes[s.objects[0].mesh];
  EXPECT_EQ(wall_red.material, 0u);
  const std::vector<glm::vec3> quad = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {3, 1, 0}, {0, 1, 0}};
  EXPECT_EQ(at_corners(wall_red, wall_red.positions), quad);
  EXPECT_EQ(at_corners(wall_red, wall_red.uvs),
            (std::vector<glm::vec2>{{0, 0}, {1, 0}, {0, 0}, {1, 0}, {1, 1}, {0, 0}}));
  EXPECT_EQ(at_corners(wall_red, wall_red.normals), std::vector<glm::vec3>(6, glm::vec3(0, 0, 1)));
  // One vertex per distinct corner, in order of first use.
  EXPECT_EQ(wall_red.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));

  const Mesh& wall_blue = s.meshes[s.objects[1].mesh];
  EXPECT_EQ(wall_blue.material, 1u);
  EXPECT_EQ(at_corners(wall_blue, wall_blue.positions),
            (std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {3, 1, 0}}));
  EXPECT_EQ(at_corners(wall_blue, wall_blue.uvs), (std::vector<glm::vec2>{{0, 0}, {1, 0}, {1, 1}}));

  const Mesh& floor_blue = s.meshes[s.objects[2].mesh];
  EXPECT_EQ(at_corners(floor_blue, floor_blue.positions),
            (std::vector<glm::vec3>{{0, 0, 2}, {3, 0, 2}, {1, 1, 2}, {0, 0, 2}, {1, 1, 2}, {0, 1, 2}}));
  EXPECT_EQ(floor_blue.positions.size(), 4u);
  EXPECT_TRUE(floor_blue.normals.empty());  // no corner has one
  EXPECT_TRUE(floor_blue.uvs.empty());

  const Mesh& floor_red = s.meshes[s.objects[3].mesh];  // -1 -2 -3 after 8 vertices, then `f 1 2 4`
  EXPECT_EQ(at_corners(floor_red, floor_red.positions),
            (std::vector<glm::vec3>{{0, 1, 2}, {1, 1, 2}, {3, 0, 2}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
}

TEST(ObjReader, ColoursGroupNamesAndPolygons) {
  const auto file = write_file("pentagon.obj",
                               "v 0 0 0 1 0 0\nv 2 0 0 0 1 0\nv 3 2 0 0 0 1\nv 1 3 0 1 1 1\nv -1 2 0\n"
                               "g  a\tb  \n"
                               "f 1 2 3 4 5\n"
                               "g\n"         // `g` alone is no group line: the group goes on
                               "f 1 2 +3");  // no line break at the end
  const Scene s = read_with_every_chunk_size(file);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "a b");
  const Mesh& m = s.meshes[0];
  ASSERT_EQ(m.indices.size(), 12u);  // the pentagon in 3 triangles, then one
  // The pentagon's triangles cover it: their areas sum to its area, 8 (shoelace formula).
  const std::vector<glm::vec3> p = at_corners(m, m.positions);
  float area = 0;
  for (size_t t = 0; t < 3; ++t) {
    const glm::vec3 e1 = p[3 * t + 1] - p[3 * t], e2 = p[3 * t + 2] - p[3 * t];
    area += 0.5f * std::abs(e1.x * e2.y - e1.y * e2.x);
  }
  EXPECT_FLOAT_EQ(area, 8.0f);
  EXPECT_EQ(m.positions.size(), 5u);  // the triangle reuses the pentagon's vertices
  const std::vector<glm::vec4> colors = at_corners(m, m.colors);  // a vertex without colour is white
  EXPECT_EQ(colors[9], glm::vec4(1, 0, 0, 1));
  EXPECT_EQ(colors[10], glm::vec4(0, 1, 0, 1));
  EXPECT_EQ(colors[11], glm::vec4(0, 0, 1, 1));
  bool white = false;
  for (size_t c = 0; c < 9; ++c) white |= p[c] == glm::vec3(-1, 2, 0) && colors[c] == glm::vec4(1);
  EXPECT_TRUE(white);
}

TEST(ObjReader, BadInputNamesTheLine) {
  expect_line_error("bad_number.obj", "v 0 0 0\nv 1 0 0\n# x\nv 0 1x 0\nf 1 2 3\n", 4, "'1x'");
  expect_line_error("short_vertex.obj", "v 0 0 0\nv 1 0\n", 2, "end of the line");
  expect_line_error("bad_normal.obj", "v 0 0 0\nvn 0 0 nope\n", 2, "'nope'");
  expect_line_error("out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 3\nf 1 2 9\n", 6, "vertex 9");
  expect_line_error("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 3\n", 4, "index 0");
  expect_line_error("relative_too_far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n", 4, "before the first");
  expect_line_error("bad_corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\r\nvt 0 0\nf 1/a 2 3\n", 5, "'1/a'");
  expect_line_error("uv_out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", 5,
                    "texture coordinate 2");
}

TEST(ObjReader, MissingFile) {
  const std::string message = import_error(temp_dir() / "nothing_here.obj");
  EXPECT_NE(message.find("no such file"), std::string::npos) << message;
}
