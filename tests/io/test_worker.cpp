// Formats read by assimp in the import worker, and every way the worker can fail.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <glm/gtc/matrix_transform.hpp>

#include "files.hpp"

using namespace lodstream;
using namespace lodstream::test;

namespace {

// A worker stand-in: a shell script with the given body (receives FILE OUTFILE as $2 $3).
std::filesystem::path fake_worker(const std::string& name, const std::string& body) {
  auto path = write_file(name, "#!/bin/sh\n" + body + "\n");
  chmod(path.c_str(), 0755);
  return path;
}

}  // namespace

TEST(Worker, AsciiStl) {
  auto file = write_file(
      "tetra.stl",
      "solid t\n"
      "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
      "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
      "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
      "facet normal 1 1 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
      "endsolid t\n");
  Scene s = import_model(file);
  EXPECT_EQ(s.triangle_count(), 4u);
  // STL is unwelded with flat normals: welded to 4 corners x 3 creased faces each (all edges are sharper than
  // 60).
  EXPECT_EQ(s.meshes[0].vertex_count(), 12u);
  EXPECT_EQ(s.bounds().max, glm::vec3(1.0f));
}

TEST(Worker, GltfHierarchyInstancesAndMaterials) {
  // One triangle mesh used by two nodes; the second is a child of a translated parent and is scaled itself.
  float data[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string b64;
  {
    const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const auto* bytes = reinterpret_cast<const unsigned char*>(data);
    for (size_t i = 0; i < sizeof data; i += 3) {
      uint32_t v = bytes[i] << 16 | bytes[i + 1] << 8 | bytes[i + 2];
      for (int k = 3; k >= 0; --k) b64 += table[(v >> (6 * k)) & 63];
    }
  }
  auto dir = temp_dir();
  std::ofstream(dir / "scene.gltf") << R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [
    {"name": "first", "mesh": 0},
    {"name": "parent", "translation": [10, 0, 0], "children": [2]},
    {"name": "second", "mesh": 0, "scale": [2, 2, 2]}
  ],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
  "materials": [{"name": "paint", "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.5, 0.75, 1.0],
                 "baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}],
  "images": [{"uri": "tex/paint.png"}],
  "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" +
                                           b64 + R"("}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]
})";
  Scene s = import_model(dir / "scene.gltf");
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.meshes.size(), 1u);  // instanced, stored once
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.unique_triangle_count(), 1u);
  EXPECT_EQ(s.objects[1].name, "second");
  EXPECT_EQ(s.objects[1].transform,
            glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0)), glm::vec3(2)));
  EXPECT_EQ(s.bounds().max, glm::vec3(12, 2, 0));
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].base_color, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
  EXPECT_EQ(s.materials[0].base_color_texture, (dir / "tex" / "paint.png").lexically_normal().string());
}

TEST(Worker, AssimpErrorBecomesOneLine) {
  auto file = write_file("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [ {");
  std::string e = import_error(file);
  EXPECT_EQ(e.rfind(file.string() + ": import failed: ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(Worker, QuantizedGltfIsRejected) {
  auto file = write_file("quantized.gltf",
                         R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_mesh_quantization"]})");
  EXPECT_NE(import_error(file).find("KHR_mesh_quantization"), std::string::npos);
}

TEST(Worker, CrashTimeoutAndGarbageAreErrors) {
  auto model = write_file("any.stl", "solid x\nendsolid x\n");
  ImportOptions crash;
  crash.worker = fake_worker("crash.sh", "kill -SEGV $$");
  EXPECT_NE(import_error(model, crash).find("crashed (signal 11"), std::string::npos);

  ImportOptions hang;
  hang.worker = fake_worker("hang.sh", "exec sleep 30");
  hang.worker_timeout_s = 0.3;
  EXPECT_NE(import_error(model, hang).find("did not finish"), std::string::npos);

  ImportOptions garbage;
  garbage.worker = fake_worker("garbage.sh", "echo nonsense > \"$3\"");
  EXPECT_NE(import_error(model, garbage).find("garbage"), std::string::npos);

  ImportOptions fails;
  fails.worker = fake_worker("fails.sh", "echo 'lodstream: error: it went wrong' >&2; exit 1");
  EXPECT_NE(import_error(model, fails).find("import failed: it went wrong"), std::string::npos);

  ImportOptions missing;
  missing.worker = temp_dir() / "no-such-worker";
  EXPECT_NE(import_error(model, missing).find("cannot start"), std::string::npos);
}
