#include "io/off_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <string_view>

#include "core/error.hpp"
#include "io/mapped_file.hpp"
#include "io/text_cursor.hpp"

namespace lodstream {

Scene read_off(const std::filesystem::path& path) {
  const std::string file = path.string();
  MappedFile map(path);
  TextCursor c(map.data(), map.data() + map.size(), file, '#');
  std::string_view keyword = c.token();
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
    throw Error(file + ": not an OFF file (it does not start with OFF)");
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  bool st = false, color = false, normal = false;
  if (prefix.starts_with("ST")) st = true, prefix.remove_prefix(2);
  if (prefix.starts_with("C")) color = true, prefix.remove_prefix(1);
  if (prefix.starts_with("N")) normal = true, prefix.remove_prefix(1);
  if (!prefix.empty()) c.fail("unsupported OFF variant '" + std::string(keyword.substr(0, 16)) + "'");
  if (c.more_on_line()) {
    std::string_view next = c.token();
    if (next == "BINARY") c.fail("binary OFF is not supported");
    c = TextCursor(next.data(), map.data() + map.size(), file, '#');
    c.skip_space();
    // Keep line numbers right: the counts sit on line 1.
  }
  const uint64_t nv = c.number<uint64_t>("the vertex count");
  const uint64_t nf = c.number<uint64_t>("the face count");
  c.number<uint64_t>("the edge count");
  // Each vertex needs at least 6 bytes ("0 0 0\n") and each face at least 8 ("3 0 1 2\n").
  if (nv > c.remaining() / 6 || nf > c.remaining() / 8 || nv >= UINT32_MAX)
    c.fail("OFF header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
           " faces, more than the " + std::to_string(c.remaining()) + " remaining bytes can hold");
  c.next_line();

  Mesh mesh;
  mesh.positions.resize(nv);
  if (normal) mesh.normals.resize(nv);
  if (color) mesh.colors.resize(nv);
  if (st) mesh.uvs.resize(nv);
  // A vertex line: x y z, then [nx ny nz] (N), [r g b [a]] (C), [s t] (ST).
  const size_t fixed = 3 + (normal ? 3 : 0) + (st ? 2 : 0);
  float values[16];
  for (uint64_t i = 0; i < nv; ++i) {
    c.skip_space();
    size_t n = 0;
    bool integer_color = true;
    while (c.more_on_line()) {
      if (n == 16) c.fail("too many numbers on a vertex line");
      std::string_view t = c.token();
      auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), values[n]);
      if (t.empty() || ec != std::errc() || ptr != t.data() + t.size())
        c.fail("expected a number in vertex " + std::to_string(i) + ", found '" +
               std::string(t.substr(0, 32)) + "'");
      if (n >= 3 + (normal ? 3 : 0)) integer_color &= t.find_first_of(".eE") == std::string_view::npos;
      ++n;
    }
    const size_t channels = n - std::min(n, fixed);
    if (n < fixed || (color && channels != 3 && channels != 4) || (!color && n != fixed))
      c.fail("vertex " + std::to_string(i) + " has " + std::to_string(n) + " numbers, which does not match " +
             std::string(keyword));
    mesh.positions[i] = glm::vec3(values[0], values[1], values[2]);
    size_t k = 3;
    if (normal) mesh.normals[i] = glm::vec3(values[k], values[k + 1], values[k + 2]), k += 3;
    if (color) {
      glm::vec4 rgba(values[k], values[k + 1], values[k + 2], channels == 4 ? values[k + 3] : 1.0f);
      if (integer_color) rgba = glm::vec4(glm::vec3(rgba) / 255.0f, channels == 4 ? rgba.a / 255.0f : 1.0f);
      mesh.colors[i] = rgba;
      k += channels;
    }
    if (st) mesh.uvs[i] = glm::vec2(values[k], values[k + 1]);
    c.next_line();
  }
  mesh.indices.reserve(3 * nf);
  size_t skipped = 0;
  std::vector<uint32_t> polygon;
  for (uint64_t f = 0; f < nf; ++f) {
    c.skip_space();
    uint64_t n = c.number<uint64_t>("a face's corner count");
    if (n > c.remaining())
      c.fail("face corner count " + std::to_string(n) + " is larger than the rest of the file");
    polygon.resize(n);
    for (auto& v : polygon) {
      uint64_t idx = c.number<uint64_t>("a vertex index");
      if (idx >= nv)
        c.fail("face " + std::to_string(f) + " references vertex " + std::to_string(idx) +
               ", but there are only " + std::to_string(nv) + " vertices");
      v = static_cast<uint32_t>(idx);
    }
    c.next_line();  // a face colour may follow
    if (n < 3) {
      ++skipped;
      continue;
    }
    for (size_t k = 1; k + 1 < n; ++k)
      mesh.indices.insert(mesh.indices.end(), {polygon[0], polygon[k], polygon[k + 1]});
  }
  if (skipped > 0)
    std::fprintf(stderr, "lodstream: warning: %s: skipped %zu faces with fewer than 3 corners\n",
                 file.c_str(), skipped);
  return make_scene(std::move(mesh), path.stem().string());
}

}  // namespace lodstream
