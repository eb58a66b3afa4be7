// A parallel OBJ reader of our own. tinyobjloader (Debian's libtinyobjloader-dev, which read OBJ here before)
// parses on one thread, and its multi-threaded variant is not packaged in Debian; on a 4.8M-triangle city
// that single thread was most of the import. The file is mapped, cut at line breaks into chunks parsed in
// parallel (obj_chunk.hpp), and the chunks are stitched in file order: vertex numbering (relative indices
// included), the object / group / material state, and the per-object meshes. The result is the scene the
// tinyobjloader-based reader produced, vertex for vertex; tinyobjloader still reads the .mtl files and
// triangulates the rare faces of more than four corners.
#include "io/obj_reader.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>

#include "core/error.hpp"
#include "io/mapped_file.hpp"
#include "io/obj_chunk.hpp"

namespace lodstream {

namespace {

std::filesystem::path texture_path(const std::filesystem::path& dir, std::string name) {
  if (name.empty()) return {};
  std::replace(name.begin(), name.end(), '\\', '/');
  std::filesystem::path p(name);
  if (p.is_relative()) p = dir / p;
  return std::filesystem::absolute(p).lexically_normal();
}

// First line of a (possibly multi-line) tinyobjloader message.
std::string first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

// The file names of an `mtllib` line: separated by spaces, '\' escapes the next character.
std::vector<std::string> library_names(const std::string& rest) {
  std::vector<std::string> names;
  std::string name;
  bool escaped = false;
  for (char c : rest) {
    if (!escaped && c == '\\') {
      escaped = true;
      continue;
    }
    if (!escaped && c == ' ') {
      if (!name.empty()) names.push_back(std::move(name));
      name.clear();
      continue;
    }
    escaped = false;
    name += c;
  }
  names.push_back(std::move(name));
  return names;
}

// The faces of a chunk from `face` on belong to mesh `key` (until the next run).
struct Run {
  uint32_t face;
  uint32_t key;
  size_t triangles = 0;  // counted after triangulation
  size_t corner = 0;     // its first corner in the chunk's triangles
};

// One output mesh: the faces of one shape (an `o` / `g` section) that use one material.
struct Key {
  size_t shape;
  int material;  // -1: none
  std::string name;
  size_t triangles = 0;
  std::vector<std::pair<uint32_t, uint32_t>> runs;  // (chunk, run) in file order
};

// The reader's state between faces, advanced over the events of every chunk in file order: what tinyobjloader
// kept (current shape and its name, current material, loaded libraries).
class Stitcher {
 public:
  Stitcher(const std::filesystem::path& dir) : library_reader_(dir.string() + "/") {}

  // Turns `chunk`'s events into runs of faces per key.
  std::vector<Run> runs(ObjChunk& chunk, size_t first_line) {
    std::vector<Run> runs;
    uint32_t face = 0;
    for (ObjEvent& e : chunk.events) {
      add_run(runs, face, e.face);
      face = e.face;
      apply(e, first_line + e.line);
    }
    add_run(runs, face, chunk.faces);
    chunk.events = {};
    return runs;
  }

  std::vector<Key>& keys() { return keys_; }
  std::vector<tinyobj::material_t>& materials() { return materials_; }
  const std::string& warning() const { return warning_; }
  size_t warning_line() const { return warning_line_; }

 private:
  void add_run(std::vector<Run>& runs, uint32_t from, uint32_t to) {
    if (to <= from) return;
    auto [it, inserted] = shape_keys_.try_emplace(material_, static_cast<uint32_t>(keys_.size()));
    if (inserted) keys_.push_back(Key{shape_, material_, name_, 0, {}});
    runs.push_back(Run{from, it->second});
  }

  void warn(const std::string& what, size_t line) {
    if (warning_.empty()) warning_ = what, warning_line_ = line;
  }

  void apply(const ObjEvent& e, size_t line) {
    switch (e.kind) {
      case ObjEvent::Kind::object:
      case ObjEvent::Kind::group:
        ++shape_;
        shape_keys_.clear();
        name_ = e.text;
        break;
      case ObjEvent::Kind::use_material: {
        auto it = material_map_.find(e.text);
        if (it == material_map_.end()) warn("material '" + e.text + "' not found in the .mtl", line);
        material_ = it == material_map_.end() ? -1 : it->second;
        break;
      }
      case ObjEvent::Kind::material_library: {
        // The first of the named files that loads, unless one was loaded before (as tinyobjloader does).
        bool found = false;
        for (const std::string& name : library_names(e.text)) {
          if (libraries_.count(name)) {
            found = true;
            continue;
          }
          std::string warn_mtl, err_mtl;
          const bool ok = library_reader_(name, &materials_, &material_map_, &warn_mtl, &err_mtl);
          if (!warn_mtl.empty()) warn(first_line(warn_mtl), line);
          if (ok) {
            found = true;
            libraries_.insert(name);
            break;
          }
        }
        if (!found) warn("failed to load material file(s); using the default material", line);
        break;
      }
    }
  }

  tinyobj::MaterialFileReader library_reader_;
  std::vector<tinyobj::material_t> materials_;
  std::map<std::string, int> material_map_;
  std::set<std::string> libraries_;
  std::vector<Key> keys_;
  std::map<int, uint32_t> shape_keys_;  // material -> key, in the current shape
  size_t shape_ = 0;
  int material_ = -1;
  std::string name_;
  std::string warning_;
  size_t warning_line_ = 0;
};

// A quad is split along its shorter diagonal: [0 1 2] [0 2 3] when |p2 - p0|^2 < |p3 - p1|^2, else
// [0 1 3] [1 2 3] (tinyobjloader's rule, in float as it computed it).
void split_quad(const ObjCorner* q, const std::vector<float>& positions, std::vector<ObjCorner>& out) {
  auto squared = [&](int a, int b) {
    const float* pa = &positions[3 * static_cast<size_t>(q[a].v)];
    const float* pb = &positions[3 * static_cast<size_t>(q[b].v)];
    const float x = pb[0] - pa[0], y = pb[1] - pa[1], z = pb[2] - pa[2];
    const float xx = x * x, yy = y * y, zz = z * z;
    const float xy = xx + yy;
    return xy + zz;
  };
  static const int first[6] = {0, 1, 2, 0, 2, 3}, second[6] = {0, 1, 3, 1, 2, 3};
  const int* order = squared(0, 2) < squared(1, 3) ? first : second;
  for (int k = 0; k < 6; ++k) out.push_back(q[order[k]]);
}

// A face of five or more corners is triangulated by tinyobjloader itself (its ear clipping over the
// polygon's dominant plane), so that such faces come out as before: it is given the polygon alone.
void split_polygon(const ObjCorner* f, uint32_t n, const std::vector<float>& positions,
                   std::vector<ObjCorner>& out) {
  std::string text;
  char buf[96];
  for (uint32_t k = 0; k < n; ++k) {
    const float* p = &positions[3 * static_cast<size_t>(f[k].v)];
    std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
    text += buf;
  }
  text += "f";
  for (uint32_t k = 1; k <= n; ++k) text += " " + std::to_string(k);
  text += "\n";
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", config)) return;
  for (const auto& shape : reader.GetShapes())
    for (const tinyobj::index_t& ix : shape.mesh.indices) out.push_back(f[ix.vertex_index]);
}

// Cuts [data, data + size) into pieces of about `chunk_bytes` that end at a line break.
std::vector<std::pair<const char*, const char*>> cut(const char* data, size_t size, size_t chunk_bytes) {
  std::vector<std::pair<const char*, const char*>> pieces;
  const char* end = data + size;
  for (const char* p = data; p < end;) {
    const char* q = p + std::min(std::max<size_t>(chunk_bytes, 1), static_cast<size_t>(end - p));
    if (q < end) {
      const char* nl = static_cast<const char*>(std::memchr(q - 1, '\n', static_cast<size_t>(end - q + 1)));
      q = nl ? nl + 1 : end;
    }
    pieces.emplace_back(p, q);
    p = q;
  }
  return pieces;
}

// Appends each chunk's array `member` into one, then frees the chunk's.
std::vector<float> concatenate(std::vector<ObjChunk>& chunks, std::vector<float> ObjChunk::*member,
                               const std::vector<size_t>& base, size_t total, size_t width) {
  std::vector<float> all(total * width);
  tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) {
    std::vector<float>& part = chunks[c].*member;
    std::copy(part.begin(), part.end(), all.begin() + static_cast<ptrdiff_t>(base[c] * width));
    part = {};
  });
  return all;
}

}  // namespace

Scene read_obj(const std::filesystem::path& path, size_t chunk_bytes) {
  const std::string file = path.string();
  if (!std::filesystem::is_regular_file(path)) throw Error(file + ": cannot open: no such file");
  const std::filesystem::path dir =
      path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  MappedFile map(path);

  // 1. Parse the chunks in parallel.
  const auto pieces = cut(map.data(), map.size(), chunk_bytes);
  std::vector<ObjChunk> chunks(pieces.size());
  // Each chunk's arrays are reserved from the sizes per byte of the chunk its thread parsed last: grown from
  // empty, they made the kernel map (and zero) about twice the memory, and page faults are costly here.
  struct Sizes {
    size_t bytes = 0, positions = 0, colors = 0, texcoords = 0, normals = 0, corners = 0;
  };
  tbb::enumerable_thread_specific<Sizes> last;
  tbb::parallel_for(size_t(0), pieces.size(), [&](size_t c) {
    ObjChunk& k = chunks[c];
    Sizes& l = last.local();
    const size_t bytes = static_cast<size_t>(pieces[c].second - pieces[c].first);
    if (l.bytes > 0) {
      const double scale = 1.25 * static_cast<double>(bytes) / static_cast<double>(l.bytes);
      auto estimate = [scale](size_t n) { return static_cast<size_t>(scale * static_cast<double>(n)) + 16; };
      k.positions.reserve(estimate(l.positions));
      k.colors.reserve(l.colors > 0 ? estimate(l.colors) : 0);
      k.texcoords.reserve(estimate(l.texcoords));
      k.normals.reserve(estimate(l.normals));
      k.corners.reserve(estimate(l.corners));
    }
    parse_obj_chunk(pieces[c].first, pieces[c].second, k);
    l = Sizes{bytes,           k.positions.size(), k.colors.size(), k.texcoords.size(), k.normals.size(),
              k.corners.size()};
    map.release(pieces[c].first, pieces[c].second);  // the file would double the memory
  });

  // 2. In file order: line numbers, the first error, vertex numbering, and the state between faces.
  const size_t n = chunks.size();
  std::vector<size_t> first_line(n), base_v(n), base_vt(n), base_vn(n);
  size_t lines = 1, nv = 0, nvt = 0, nvn = 0;
  bool colors = false;
  std::string warning;
  size_t warning_line = SIZE_MAX;
  for (size_t c = 0; c < n; ++c) {
    const ObjChunk& k = chunks[c];
    first_line[c] = lines;
    if (!k.error.empty()) throw Error(file + ":" + std::to_string(lines + k.error_line) + ": " + k.error);
    if (!k.warning.empty() && warning.empty()) warning = k.warning, warning_line = lines + k.warning_line;
    lines += k.lines;
    base_v[c] = nv, base_vt[c] = nvt, base_vn[c] = nvn;
    nv += k.positions.size() / 3, nvt += k.texcoords.size() / 2, nvn += k.normals.size() / 3;
    colors |= !k.colors.empty();
  }
  if (nv > INT32_MAX || nvt > INT32_MAX || nvn > INT32_MAX) throw Error(file + ": too many vertices");
  Stitcher stitcher(dir);
  std::vector<std::vector<Run>> runs(n);
  for (size_t c = 0; c < n; ++c) runs[c] = stitcher.runs(chunks[c], first_line[c]);
  if (!stitcher.warning().empty() && stitcher.warning_line() < warning_line)
    warning = stitcher.warning(), warning_line = stitcher.warning_line();
  if (!warning.empty())
    std::fprintf(stderr, "lodstream: warning: %s:%zu: %s\n", file.c_str(), warning_line, warning.c_str());

  if (colors)
    for (auto& k : chunks)
      if (k.colors.empty()) k.colors.assign(k.positions.size(), 1.0f);
  const std::vector<float> positions = concatenate(chunks, &ObjChunk::positions, base_v, nv, 3);
  const std::vector<float> vertex_colors =
      colors ? concatenate(chunks, &ObjChunk::colors, base_v, nv, 3) : std::vector<float>();
  const std::vector<float> texcoords = concatenate(chunks, &ObjChunk::texcoords, base_vt, nvt, 2);
  const std::vector<float> normals = concatenate(chunks, &ObjChunk::normals, base_vn, nvn, 3);

  // 3. Per chunk: relative indices made absolute, indices checked, faces triangulated (chunk.corners then
  // holds triangles), triangles counted per run.
  std::vector<std::string> errors(n);
  std::vector<uint32_t> error_face(n);
  tbb::parallel_for(size_t(0), n, [&](size_t c) {
    ObjChunk& k = chunks[c];
    const size_t base[3] = {base_v[c], base_vt[c], base_vn[c]};
    for (auto [corner, which] : k.relative) {
      int32_t& i = which == 0   ? k.corners[corner].v
                   : which == 1 ? k.corners[corner].vt
                                : k.corners[corner].vn;
      i = static_cast<int32_t>(i + static_cast<int64_t>(base[which]));
    }
    k.relative = {};
    auto check = [&](const ObjCorner& x, int32_t v_count, int32_t vt_count, int32_t vn_count) -> std::string {
      static const char* const names[] = {"vertex", "texture coordinate", "normal"};
      const int32_t values[3] = {x.v, x.vt, x.vn}, counts[3] = {v_count, vt_count, vn_count};
      for (int a = 0; a < 3; ++a) {
        if (a > 0 && values[a] == -1) continue;  // absent
        if (values[a] < 0) return std::string("relative ") + names[a] + " index reaches before the first one";
        if (values[a] >= counts[a])
          return std::string("face references ") + names[a] + " " + std::to_string(int64_t(values[a]) + 1) +
                 ", but there are only " + std::to_string(counts[a]);
      }
      return {};
    };
    std::vector<ObjCorner> triangles;
    const bool polygons = !k.polygons.empty();
    size_t next_polygon = 0, corner = 0, run = 0;
    std::vector<Run>& r = runs[c];
    for (uint32_t f = 0; f < k.faces; ++f) {
      const uint32_t size = next_polygon < k.polygons.size() && k.polygons[next_polygon].first == f
                                ? k.polygons[next_polygon++].second
                                : 3;
      for (uint32_t j = 0; j < size; ++j) {
        std::string problem = check(k.corners[corner + j], static_cast<int32_t>(nv),
                                    static_cast<int32_t>(nvt), static_cast<int32_t>(nvn));
        if (!problem.empty()) {
          errors[c] = std::move(problem);
          error_face[c] = f;
          return;
        }
      }
      while (run + 1 < r.size() && r[run + 1].face <= f) ++run;
      if (!polygons) {
        ++r[run].triangles;
      } else {
        const size_t before = triangles.size();
        if (size == 3)
          triangles.insert(triangles.end(), &k.corners[corner], &k.corners[corner] + 3);
        else if (size == 4)
          split_quad(&k.corners[corner], positions, triangles);
        else
          split_polygon(&k.corners[corner], size, positions, triangles);
        r[run].triangles += (triangles.size() - before) / 3;
      }
      corner += size;
    }
    if (polygons) k.corners = std::move(triangles);
    k.polygons = {};
  });
  for (size_t c = 0; c < n; ++c)
    if (!errors[c].empty())
      throw Error(
          file + ":" +
          std::to_string(first_line[c] + obj_face_line(pieces[c].first, pieces[c].second, error_face[c])) +
          ": " + errors[c]);

  // 4. Meshes: one per key that has triangles, in order of first use.
  std::vector<Key>& keys = stitcher.keys();
  for (size_t c = 0; c < n; ++c) {
    size_t corner = 0;
    for (size_t r = 0; r < runs[c].size(); ++r) {
      Run& run = runs[c][r];
      run.corner = corner;
      corner += 3 * run.triangles;
      keys[run.key].triangles += run.triangles;
      keys[run.key].runs.emplace_back(static_cast<uint32_t>(c), static_cast<uint32_t>(r));
    }
  }
  const auto& materials = stitcher.materials();
  Scene scene;
  for (const auto& m : materials) {
    Material mat;
    mat.name = m.name;
    mat.base_color = glm::vec4(m.diffuse[0], m.diffuse[1], m.diffuse[2], m.dissolve);
    mat.base_color_texture = texture_path(dir, m.diffuse_texname).string();
    scene.materials.push_back(std::move(mat));
  }
  const uint32_t default_material = static_cast<uint32_t>(scene.materials.size());
  bool default_used = false;
  std::vector<const Key*> mesh_keys;
  for (size_t i = 0; i < keys.size(); ++i) {
    const Key& key = keys[i];
    if (key.triangles == 0) continue;
    size_t in_shape = 0;  // a shape using two materials becomes two objects, "name/material"
    for (size_t j = i; j > 0 && keys[j - 1].shape == key.shape; --j) in_shape += keys[j - 1].triangles > 0;
    for (size_t j = i + 1; j < keys.size() && keys[j].shape == key.shape; ++j)
      in_shape += keys[j].triangles > 0;
    std::string name = key.name.empty() ? path.stem().string() : key.name;
    if (in_shape > 0)
      name += "/" + (key.material < 0 ? std::string("default") : materials[key.material].name);
    scene.objects.push_back(
        Object{std::move(name), glm::mat4(1.0f), static_cast<uint32_t>(mesh_keys.size())});
    mesh_keys.push_back(&key);
    default_used |= key.material < 0;
  }
  if (default_used) scene.materials.emplace_back().name = "default";  // base colour 0.8 grey

  // 5. Fill the meshes in parallel, each from its runs in file order: one vertex per distinct corner
  // (v, vt, vn) of the mesh, in order of first use. Welding then merges equal vertices exactly as it would
  // have merged the corners (the first of equal ones is the same), at a fifth of the memory. A normal or UV
  // is kept per vertex; a mesh where some corner lacks one loses that attribute.
  struct Slots {
    std::vector<uint32_t> first;  // per position: the mesh's first vertex at it
    std::vector<uint32_t> mesh;   // per position: the mesh that set `first`
  };
  tbb::enumerable_thread_specific<Slots> thread_slots;
  scene.meshes.resize(mesh_keys.size());
  tbb::parallel_for(size_t(0), mesh_keys.size(), [&](size_t m) {
    constexpr uint32_t kNone = UINT32_MAX;
    Slots& slots = thread_slots.local();
    if (slots.first.empty()) slots.first.resize(nv), slots.mesh.assign(nv, kNone);
    const Key& key = *mesh_keys[m];
    Mesh& mesh = scene.meshes[m];
    mesh.material = key.material < 0 ? default_material : static_cast<uint32_t>(key.material);
    mesh.indices.reserve(3 * key.triangles);
    std::vector<ObjCorner> vertex;  // the indices of each vertex
    std::vector<uint32_t> next;     // the next vertex at the same position
    bool keep_normals = nvn > 0, keep_uvs = nvt > 0;
    for (auto [c, r] : key.runs) {
      const Run& run = runs[c][r];
      const ObjCorner* x = chunks[c].corners.data() + run.corner;
      for (const ObjCorner* end = x + 3 * run.triangles; x != end; ++x) {
        keep_normals &= x->vn >= 0;
        keep_uvs &= x->vt >= 0;
        uint32_t i = slots.mesh[x->v] == m ? slots.first[x->v] : kNone, previous = kNone;
        while (i != kNone && (vertex[i].vt != x->vt || vertex[i].vn != x->vn)) previous = i, i = next[i];
        if (i == kNone) {
          i = static_cast<uint32_t>(vertex.size());
          vertex.push_back(*x);
          next.push_back(kNone);
          if (previous != kNone)
            next[previous] = i;
          else
            slots.first[x->v] = i, slots.mesh[x->v] = static_cast<uint32_t>(m);
        }
        mesh.indices.push_back(i);
      }
    }
    mesh.positions.reserve(vertex.size());
    for (const ObjCorner& x : vertex)
      mesh.positions.emplace_back(positions[3 * size_t(x.v)], positions[3 * size_t(x.v) + 1],
                                  positions[3 * size_t(x.v) + 2]);
    if (keep_normals) {
      mesh.normals.reserve(vertex.size());
      for (const ObjCorner& x : vertex)
        mesh.normals.emplace_back(normals[3 * size_t(x.vn)], normals[3 * size_t(x.vn) + 1],
                                  normals[3 * size_t(x.vn) + 2]);
    }
    if (keep_uvs) {
      mesh.uvs.reserve(vertex.size());
      for (const ObjCorner& x : vertex)
        mesh.uvs.emplace_back(texcoords[2 * size_t(x.vt)], texcoords[2 * size_t(x.vt) + 1]);
    }
    if (colors) {
      mesh.colors.reserve(vertex.size());
      for (const ObjCorner& x : vertex)
        mesh.colors.emplace_back(vertex_colors[3 * size_t(x.v)], vertex_colors[3 * size_t(x.v) + 1],
                                 vertex_colors[3 * size_t(x.v) + 2], 1.0f);
    }
  });
  return scene;
}

}  // namespace lodstream
