#include "io/scene_codec.hpp"

#include <cstring>

#include "core/error.hpp"

namespace lodstream {

namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'S', 'C', 'N', '0', '1'};
constexpr uint32_t kNormals = 1, kUvs = 2, kColors = 4;

struct Writer {
  std::string out;
  void bytes(const void* p, size_t n) {
    if (n > 0) out.append(static_cast<const char*>(p), n);
  }
  void u32(uint32_t v) { bytes(&v, 4); }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes(s.data(), s.size());
  }
  template <class T>
  void array(const std::vector<T>& v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
};

struct Reader {
  const char* p;
  size_t left;
  const std::string& what;
  [[noreturn]] void fail(const std::string& why) const { throw Error(what + ": " + why); }
  void bytes(void* dst, size_t n) {
    if (n > left) fail("truncated scene data from the import worker");
    if (n == 0) return;  // an empty array's data() may be null
    std::memcpy(dst, p, n);
    p += n;
    left -= n;
  }
  uint32_t u32() {
    uint32_t v;
    bytes(&v, 4);
    return v;
  }
  std::string str() {
    uint32_t n = u32();
    if (n > left) fail("truncated scene data from the import worker");
    std::string s(p, n);
    p += n;
    left -= n;
    return s;
  }
  // Reads n elements, checking the size before allocating.
  template <class T>
  void array(std::vector<T>& v, size_t n) {
    if (n > left / sizeof(T)) fail("truncated scene data from the import worker");
    v.resize(n);
    bytes(v.data(), n * sizeof(T));
  }
};

}  // namespace

std::string encode_scene(const Scene& scene) {
  Writer w;
  w.bytes(kMagic, 8);
  w.u32(static_cast<uint32_t>(scene.materials.size()));
  for (const auto& m : scene.materials) {
    w.str(m.name);
    w.bytes(&m.base_color, sizeof(glm::vec4));
    w.str(m.base_color_texture);
  }
  w.u32(static_cast<uint32_t>(scene.meshes.size()));
  for (const auto& m : scene.meshes) {
    w.u32(static_cast<uint32_t>(m.positions.size()));
    w.u32(static_cast<uint32_t>(m.indices.size()));
    w.u32((m.has_normals() ? kNormals : 0) | (m.has_uvs() ? kUvs : 0) | (m.has_colors() ? kColors : 0));
    w.u32(m.material);
    w.array(m.positions);
    w.array(m.normals);
    w.array(m.uvs);
    w.array(m.colors);
    w.array(m.indices);
  }
  w.u32(static_cast<uint32_t>(scene.objects.size()));
  for (const auto& o : scene.objects) {
    w.str(o.name);
    w.bytes(&o.transform, sizeof(glm::mat4));
    w.u32(o.mesh);
  }
  return std::move(w.out);
}

Scene decode_scene(const char* data, size_t size, const std::string& what) {
  Reader r{data, size, what};
  char magic[8];
  if (size < 8) r.fail("the import worker wrote no scene");
  r.bytes(magic, 8);
  if (std::memcmp(magic, kMagic, 8) != 0) r.fail("the import worker wrote garbage (bad magic)");
  Scene scene;
  uint32_t n = r.u32();
  if (n > r.left) r.fail("bad material count from the import worker");
  scene.materials.resize(n);
  for (auto& m : scene.materials) {
    m.name = r.str();
    r.bytes(&m.base_color, sizeof(glm::vec4));
    m.base_color_texture = r.str();
  }
  n = r.u32();
  if (n > r.left) r.fail("bad mesh count from the import worker");
  scene.meshes.resize(n);
  for (auto& m : scene.meshes) {
    uint32_t nv = r.u32(), ni = r.u32(), flags = r.u32();
    m.material = r.u32();
    if (m.material >= scene.materials.size()) r.fail("mesh material index out of range");
    r.array(m.positions, nv);
    r.array(m.normals, flags & kNormals ? nv : 0);
    r.array(m.uvs, flags & kUvs ? nv : 0);
    r.array(m.colors, flags & kColors ? nv : 0);
    r.array(m.indices, ni);
  }
  n = r.u32();
  if (n > r.left) r.fail("bad object count from the import worker");
  scene.objects.resize(n);
  for (auto& o : scene.objects) {
    o.name = r.str();
    r.bytes(&o.transform, sizeof(glm::mat4));
    o.mesh = r.u32();
    if (o.mesh >= scene.meshes.size()) r.fail("object mesh index out of range");
  }
  if (r.left != 0) r.fail("trailing bytes after the scene from the import worker");
  return scene;
}

}  // namespace lodstream
