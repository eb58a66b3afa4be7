#include "io/ply_reader.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/prefault.hpp"
#include "io/mapped_file.hpp"
#include "io/text_cursor.hpp"

namespace lodstream {

namespace {

enum class Type : uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

size_t type_size(Type t) {
  switch (t) {
    case Type::i8:
    case Type::u8:
      return 1;
    case Type::i16:
    case Type::u16:
      return 2;
    case Type::i32:
    case Type::u32:
    case Type::f32:
      return 4;
    case Type::f64:
      return 8;
  }
  return 0;
}

bool parse_type(std::string_view s, Type& t) {
  static const std::pair<std::string_view, Type> names[] = {
      {"char", Type::i8},   {"int8", Type::i8},     {"uchar", Type::u8},   {"uint8", Type::u8},
      {"short", Type::i16}, {"int16", Type::i16},   {"ushort", Type::u16}, {"uint16", Type::u16},
      {"int", Type::i32},   {"int32", Type::i32},   {"uint", Type::u32},   {"uint32", Type::u32},
      {"float", Type::f32}, {"float32", Type::f32}, {"double", Type::f64}, {"float64", Type::f64}};
  for (const auto& [name, type] : names)
    if (s == name) {
      t = type;
      return true;
    }
  return false;
}

// Scale that maps an integer colour channel to [0,1]; floats are taken as they are.
double color_scale(Type t) {
  switch (t) {
    case Type::u8:
    case Type::i8:
      return 1.0 / 255.0;
    case Type::u16:
    case Type::i16:
      return 1.0 / 65535.0;
    case Type::u32:
    case Type::i32:
      return 1.0 / 4294967295.0;
    default:
      return 1.0;
  }
}

// Where a vertex property goes.
enum Slot : uint8_t { X, Y, Z, NX, NY, NZ, U, V, R, G, B, A, kSlots, Skip = kSlots };

Slot slot_of(std::string_view n) {
  if (n == "x") return X;
  if (n == "y") return Y;
  if (n == "z") return Z;
  if (n == "nx") return NX;
  if (n == "ny") return NY;
  if (n == "nz") return NZ;
  if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") return U;
  if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") return V;
  if (n == "red" || n == "r" || n == "diffuse_red") return R;
  if (n == "green" || n == "g" || n == "diffuse_green") return G;
  if (n == "blue" || n == "b" || n == "diffuse_blue") return B;
  if (n == "alpha" || n == "a" || n == "diffuse_alpha") return A;
  return Skip;
}

struct Property {
  std::string name;
  Type type = Type::f32;
  bool is_list = false;
  Type count_type = Type::u8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  bool has_list() const {
    for (const auto& p : properties)
      if (p.is_list) return true;
    return false;
  }
  size_t fixed_size() const {  // bytes of one binary item without lists (lists count their length field only)
    size_t n = 0;
    for (const auto& p : properties) n += p.is_list ? type_size(p.count_type) : type_size(p.type);
    return n;
  }
};

enum class Format { ascii, binary_le, binary_be };

// Reads one binary value of type T at p, swapping bytes when the file's endianness differs.
template <bool Swap, class T>
inline T load_as(const char* p) {
  T v;
  if constexpr (Swap && sizeof(T) == 2) {
    uint16_t u;
    std::memcpy(&u, p, 2);
    v = std::bit_cast<T>(__builtin_bswap16(u));
  } else if constexpr (Swap && sizeof(T) == 4) {
    uint32_t u;
    std::memcpy(&u, p, 4);
    v = std::bit_cast<T>(__builtin_bswap32(u));
  } else if constexpr (Swap && sizeof(T) == 8) {
    uint64_t u;
    std::memcpy(&u, p, 8);
    v = std::bit_cast<T>(__builtin_bswap64(u));
  } else {
    std::memcpy(&v, p, sizeof(T));
  }
  return v;
}

// Reads one binary scalar of type t at p as double.
template <bool Swap>
inline double load(const char* p, Type t) {
  switch (t) {
    case Type::i8:
      return load_as<Swap, int8_t>(p);
    case Type::u8:
      return load_as<Swap, uint8_t>(p);
    case Type::i16:
      return load_as<Swap, int16_t>(p);
    case Type::u16:
      return load_as<Swap, uint16_t>(p);
    case Type::i32:
      return load_as<Swap, int32_t>(p);
    case Type::u32:
      return load_as<Swap, uint32_t>(p);
    case Type::f32:
      return load_as<Swap, float>(p);
    case Type::f64:
      return load_as<Swap, double>(p);
  }
  return 0.0;
}

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  size_t body = 0;  // byte offset of the first byte after end_header
};

Header parse_header(const char* data, size_t size, const std::string& file) {
  // The header is text; cap it so that garbage without a newline is not scanned as one huge line.
  const size_t limit = std::min<size_t>(size, 1 << 20);
  TextCursor c(data, data + limit, file);
  auto line_tokens = [&c]() {
    std::vector<std::string_view> tokens;
    while (c.more_on_line()) tokens.push_back(c.token());
    c.next_line();
    return tokens;
  };
  if (size < 4 || std::string_view(data, 3) != "ply" || (data[3] != '\n' && data[3] != '\r'))
    throw Error(file + ": not a PLY file (it does not start with 'ply')");
  c.next_line();
  Header h;
  bool have_format = false;
  for (;;) {
    if (c.remaining() == 0) c.fail("PLY header has no end_header");
    size_t line = c.line();
    auto t = line_tokens();
    if (t.empty()) continue;
    auto bad = [&](const std::string& why) -> Error {
      return Error(file + ":" + std::to_string(line) + ": bad PLY header: " + why);
    };
    if (t[0] == "end_header") {
      h.body = static_cast<size_t>(c.position() - data);
      break;
    } else if (t[0] == "comment" || t[0] == "obj_info") {
      continue;
    } else if (t[0] == "format") {
      if (t.size() != 3) throw bad("format line needs a format and a version");
      if (t[1] == "ascii")
        h.format = Format::ascii;
      else if (t[1] == "binary_little_endian")
        h.format = Format::binary_le;
      else if (t[1] == "binary_big_endian")
        h.format = Format::binary_be;
      else
        throw bad("unknown format '" + std::string(t[1]) + "'");
      have_format = true;
    } else if (t[0] == "element") {
      uint64_t count = 0;
      if (t.size() != 3) throw bad("element line needs a name and a count");
      auto [p, ec] = std::from_chars(t[2].data(), t[2].data() + t[2].size(), count);
      if (ec != std::errc() || p != t[2].data() + t[2].size()) throw bad("element count is not a number");
      h.elements.push_back({std::string(t[1]), count, {}});
    } else if (t[0] == "property") {
      if (h.elements.empty()) throw bad("property before any element");
      Property prop;
      if (t.size() == 5 && t[1] == "list") {
        prop.is_list = true;
        if (!parse_type(t[2], prop.count_type) || !parse_type(t[3], prop.type))
          throw bad("unknown list type '" + std::string(t[2]) + " " + std::string(t[3]) + "'");
        if (prop.count_type == Type::f32 || prop.count_type == Type::f64)
          throw bad("list count must be an integer");
        prop.name = t[4];
      } else if (t.size() == 3) {
        if (!parse_type(t[1], prop.type)) throw bad("unknown property type '" + std::string(t[1]) + "'");
        prop.name = t[2];
      } else {
        throw bad("malformed property line");
      }
      h.elements.back().properties.push_back(std::move(prop));
    } else {
      throw bad("unknown keyword '" + std::string(t[0].substr(0, 32)) + "'");
    }
  }
  if (!have_format) throw Error(file + ": bad PLY header: no format line");
  return h;
}

struct VertexLayout {
  std::vector<Slot> slots;  // per property of the vertex element
  bool has[kSlots] = {};
  double scale[kSlots] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
};

VertexLayout vertex_layout(const Element& e) {
  VertexLayout l;
  for (const auto& p : e.properties) {
    Slot s = p.is_list ? Skip : slot_of(p.name);
    l.slots.push_back(s);
    if (s != Skip) {
      l.has[s] = true;
      if (s >= R) l.scale[s] = color_scale(p.type);
    }
  }
  return l;
}

// Builds the mesh's attribute arrays from the decoded slot values of vertex i.
struct MeshBuilder {
  Mesh& mesh;
  const VertexLayout& layout;
  bool normals, uvs, colors;
  MeshBuilder(Mesh& m, const VertexLayout& l, size_t n)
      : mesh(m),
        layout(l),
        normals(l.has[NX] && l.has[NY] && l.has[NZ]),
        uvs(l.has[U] && l.has[V]),
        colors(l.has[R] && l.has[G] && l.has[B]) {
    resize_prefaulted(mesh.positions, n);  // pages faulted in on every core (core/prefault.hpp)
    if (normals) resize_prefaulted(mesh.normals, n);
    if (uvs) resize_prefaulted(mesh.uvs, n);
    if (colors) resize_prefaulted(mesh.colors, n);
  }
  void set(size_t i, const double* v) {
    mesh.positions[i] = glm::vec3(v[X], v[Y], v[Z]);
    if (normals) mesh.normals[i] = glm::vec3(v[NX], v[NY], v[NZ]);
    if (uvs) mesh.uvs[i] = glm::vec2(v[U], v[V]);
    if (colors)
      mesh.colors[i] = glm::vec4(v[R] * layout.scale[R], v[G] * layout.scale[G], v[B] * layout.scale[B],
                                 layout.has[A] ? v[A] * layout.scale[A] : 1.0);
  }
};

bool is_face_list(const Property& p) {
  return p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

// Appends polygon `corners` as a fan of triangles.
struct FaceBuilder {
  Mesh& mesh;
  uint64_t vertex_count;
  const std::string& file;
  size_t skipped = 0;  // faces with fewer than three corners
  std::vector<uint32_t> polygon;
  // `where` describes the face's position for an error message.
  template <class Where>
  void add(Where&& where) {
    for (uint32_t v : polygon)
      if (v >= vertex_count)
        throw Error(file + ": " + where() + ": face references vertex " + std::to_string(v) +
                    ", but there are only " + std::to_string(vertex_count) + " vertices");
    if (polygon.size() < 3) {
      ++skipped;
      return;
    }
    for (size_t k = 1; k + 1 < polygon.size(); ++k) {
      mesh.indices.push_back(polygon[0]);
      mesh.indices.push_back(polygon[k]);
      mesh.indices.push_back(polygon[k + 1]);
    }
  }
};

int64_t as_index(double v) {
  return v < 0 || v != v ? -1 : static_cast<int64_t>(v);
}

// The common binary face element, only a list of vertex indices and every face a triangle, read on every core
// at its fixed stride: true when that is what the file holds (indices appended to `mesh`). False, with `mesh`
// as it was, on anything else (another layout, a polygon, a bad index), which the item-by-item reader then
// handles and reports. `count(p)` and `index(p)` read a face's corner count and an index as the file stores
// them (an index as int64_t, -1 when negative or not a number).
template <class Count, class Index>
bool read_triangles_with(const char* data, size_t size, size_t offset, const Element& e,
                         uint64_t vertex_count, Mesh& mesh, Count&& count, Index&& index) {
  const Property& prop = e.properties[0];
  const size_t cs = type_size(prop.count_type), is = type_size(prop.type), stride = cs + 3 * is;
  if (e.count > (size - offset) / stride) return false;
  const size_t base = mesh.indices.size();
  if (base == 0) reserve_prefaulted(mesh.indices, 3 * e.count);  // core/prefault.hpp
  mesh.indices.resize(base + 3 * e.count);
  std::atomic<bool> ok{true};
  tbb::parallel_for(
      tbb::blocked_range<uint64_t>(0, e.count, 1 << 15), [&](const tbb::blocked_range<uint64_t>& r) {
        const char* p = data + offset + r.begin() * stride;
        for (uint64_t f = r.begin(); f < r.end() && ok.load(std::memory_order_relaxed); ++f, p += stride) {
          if (count(p) != 3) return ok.store(false);
          for (int k = 0; k < 3; ++k) {
            const int64_t idx = index(p + cs + k * is);
            if (idx < 0 || uint64_t(idx) >= vertex_count) return ok.store(false);
            mesh.indices[base + 3 * f + k] = uint32_t(idx);
          }
        }
      });
  if (!ok) mesh.indices.resize(base);
  return ok;
}

// read_triangles_with for the face element: a uchar count and 32-bit integer indices (what most writers use)
// read as such, other types through load() and its switch on the type, converted to double and back
// (callgrind, bake of data/horse.ply, 97k faces: ply_reader.cpp 17.6 -> 12.2 M instructions).
template <bool Swap>
bool read_triangles(const char* data, size_t size, size_t offset, const Element& e, uint64_t vertex_count,
                    Mesh& mesh) {
  if (e.properties.size() != 1 || !is_face_list(e.properties[0])) return false;
  const Property& prop = e.properties[0];
  auto uchar_count = [](const char* p) { return int64_t(uint8_t(*p)); };
  if (prop.count_type == Type::u8 && prop.type == Type::i32)
    return read_triangles_with(data, size, offset, e, vertex_count, mesh, uchar_count,
                               [](const char* p) { return int64_t(load_as<Swap, int32_t>(p)); });
  if (prop.count_type == Type::u8 && prop.type == Type::u32)
    return read_triangles_with(data, size, offset, e, vertex_count, mesh, uchar_count,
                               [](const char* p) { return int64_t(load_as<Swap, uint32_t>(p)); });
  return read_triangles_with(
      data, size, offset, e, vertex_count, mesh,
      [&prop](const char* p) { return as_index(load<Swap>(p, prop.count_type)); },
      [&prop](const char* p) { return as_index(load<Swap>(p, prop.type)); });
}

template <bool Swap>
void read_binary(const char* data, size_t size, const Header& h, const std::string& file, Mesh& mesh,
                 size_t& skipped) {
  size_t offset = h.body;
  auto truncated = [&](const std::string& what, size_t at) -> Error {
    return Error(file + ": truncated PLY: " + what + " at byte offset " + std::to_string(at) +
                 " runs past the end (" + std::to_string(size) + " bytes)");
  };
  uint64_t vertex_count = 0;
  for (const auto& e : h.elements)
    if (e.name == "vertex") vertex_count = e.count;
  for (const auto& e : h.elements) {
    size_t min_item = std::max<size_t>(1, e.fixed_size());
    // A declared count larger than the rest of the file can hold is rejected before anything is allocated.
    if (e.count > (size - offset) / min_item)
      throw Error(file + ": PLY header declares " + std::to_string(e.count) + " '" + e.name +
                  "' elements of at least " + std::to_string(min_item) + " bytes, but only " +
                  std::to_string(size - offset) + " bytes follow the header at byte offset " +
                  std::to_string(offset));
    if (e.name == "vertex") {
      if (e.has_list()) throw Error(file + ": PLY vertex element with a list property is not supported");
      VertexLayout layout = vertex_layout(e);
      if (!layout.has[X] || !layout.has[Y] || !layout.has[Z])
        throw Error(file + ": PLY vertex element lacks x, y or z");
      if (vertex_count >= UINT32_MAX) throw Error(file + ": more than 2^32 vertices");
      MeshBuilder builder(mesh, layout, e.count);
      const size_t stride = e.fixed_size();
      std::vector<size_t> offsets;
      for (size_t k = 0, o = 0; k < e.properties.size(); o += type_size(e.properties[k].type), ++k)
        offsets.push_back(o);
      // Fixed-size items: read on every core, `value(p, k)` reading property k at p. Properties all floats
      // (the usual x, y, z) are read as such, without load()'s switch on the type (callgrind, bake of
      // data/elephant_1m.ply: ply_reader.cpp 109.1 -> 89.7 M instructions).
      auto read_items = [&](auto&& value) {
        tbb::parallel_for(tbb::blocked_range<uint64_t>(0, e.count, 1 << 14),
                          [&](const tbb::blocked_range<uint64_t>& r) {
                            double v[kSlots + 1] = {};
                            const char* p = data + offset + r.begin() * stride;
                            for (uint64_t i = r.begin(); i < r.end(); ++i, p += stride) {
                              for (size_t k = 0; k < offsets.size(); ++k)
                                v[layout.slots[k]] = value(p + offsets[k], k);
                              builder.set(i, v);
                            }
                          });
      };
      if (std::all_of(e.properties.begin(), e.properties.end(),
                      [](const Property& q) { return q.type == Type::f32; }))
        read_items([](const char* p, size_t) { return double(load_as<Swap, float>(p)); });
      else
        read_items([&](const char* p, size_t k) { return load<Swap>(p, e.properties[k].type); });
      offset += stride * e.count;
    } else if (e.name == "face" && read_triangles<Swap>(data, size, offset, e, vertex_count, mesh)) {
      offset += e.count * (type_size(e.properties[0].count_type) + 3 * type_size(e.properties[0].type));
    } else if (e.name == "face") {
      FaceBuilder faces{mesh, vertex_count, file, 0, {}};
      mesh.indices.reserve(3 * e.count);
      for (uint64_t f = 0; f < e.count; ++f) {
        const size_t face_start = offset;
        for (const auto& prop : e.properties) {
          if (!prop.is_list) {
            if (offset + type_size(prop.type) > size)
              throw truncated("face " + std::to_string(f), face_start);
            offset += type_size(prop.type);
            continue;
          }
          size_t cs = type_size(prop.count_type), is = type_size(prop.type);
          if (offset + cs > size) throw truncated("face " + std::to_string(f), face_start);
          int64_t n = as_index(load<Swap>(data + offset, prop.count_type));
          offset += cs;
          if (n < 0)
            throw Error(file + ": negative list length at byte offset " + std::to_string(offset - cs));
          if (static_cast<uint64_t>(n) > (size - offset) / is)
            throw truncated("face " + std::to_string(f), face_start);
          if (is_face_list(prop) && n == 3) {  // the common case, without the polygon buffer
            uint32_t tri[3];
            for (int k = 0; k < 3; ++k) {
              int64_t idx = as_index(load<Swap>(data + offset + k * is, prop.type));
              tri[k] = idx < 0 || idx > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(idx);
            }
            if (tri[0] >= vertex_count || tri[1] >= vertex_count || tri[2] >= vertex_count) {
              faces.polygon.assign(tri, tri + 3);
              faces.add([&] {
                return "face " + std::to_string(f) + " at byte offset " + std::to_string(face_start);
              });
            }
            for (uint32_t corner : tri) mesh.indices.push_back(corner);  // no memmove call per face
          } else if (is_face_list(prop)) {
            faces.polygon.resize(static_cast<size_t>(n));
            for (int64_t k = 0; k < n; ++k) {
              int64_t idx = as_index(load<Swap>(data + offset + k * is, prop.type));
              faces.polygon[k] = idx < 0 || idx > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(idx);
            }
            faces.add([&] {
              return "face " + std::to_string(f) + " at byte offset " + std::to_string(face_start);
            });
          }
          offset += static_cast<size_t>(n) * is;
        }
      }
      skipped += faces.skipped;
    } else {
      // Other elements (edges, materials, ...) are skipped item by item.
      for (uint64_t i = 0; i < e.count; ++i)
        for (const auto& prop : e.properties) {
          if (!prop.is_list) {
            offset += type_size(prop.type);
            if (offset > size) throw truncated("element '" + e.name + "'", offset - type_size(prop.type));
            continue;
          }
          size_t cs = type_size(prop.count_type);
          if (offset + cs > size) throw truncated("element '" + e.name + "'", offset);
          int64_t n = as_index(load<Swap>(data + offset, prop.count_type));
          offset += cs;
          if (n < 0 || static_cast<uint64_t>(n) > (size - offset) / type_size(prop.type))
            throw truncated("element '" + e.name + "'", offset - cs);
          offset += static_cast<size_t>(n) * type_size(prop.type);
        }
    }
  }
}

void read_ascii(const char* data, size_t size, const Header& h, const std::string& file, Mesh& mesh,
                size_t& skipped) {
  TextCursor c(data + h.body, data + size, file);
  // Line numbers continue from the header.
  size_t header_lines = 0;
  for (size_t i = 0; i < h.body; ++i) header_lines += data[i] == '\n';
  auto where = [&]() { return "line " + std::to_string(header_lines + c.line()); };
  auto fail = [&](const std::string& why) -> Error {
    return Error(file + ":" + std::to_string(header_lines + c.line()) + ": " + why);
  };
  auto number = [&](const char* what) -> double {
    std::string_view t = c.token();
    double value = 0;
    auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (t.empty()) throw fail(std::string("truncated PLY: expected ") + what + ", found end of file");
    if (ec != std::errc() || ptr != t.data() + t.size())
      throw fail(std::string("expected ") + what + ", found '" + std::string(t.substr(0, 32)) + "'");
    return value;
  };
  uint64_t vertex_count = 0;
  for (const auto& e : h.elements)
    if (e.name == "vertex") vertex_count = e.count;
  for (const auto& e : h.elements) {
    // Each value takes at least two bytes (a digit and a separator).
    uint64_t values = std::max<size_t>(1, e.properties.size());
    if (e.count > (c.remaining() + 1) / (2 * values))
      throw Error(file + ": PLY header declares " + std::to_string(e.count) + " '" + e.name +
                  "' elements, but only " + std::to_string(c.remaining()) + " bytes follow the header");
    if (e.name == "vertex") {
      if (e.has_list()) throw Error(file + ": PLY vertex element with a list property is not supported");
      VertexLayout layout = vertex_layout(e);
      if (!layout.has[X] || !layout.has[Y] || !layout.has[Z])
        throw Error(file + ": PLY vertex element lacks x, y or z");
      if (vertex_count >= UINT32_MAX) throw Error(file + ": more than 2^32 vertices");
      MeshBuilder builder(mesh, layout, e.count);
      double v[kSlots + 1] = {};
      for (uint64_t i = 0; i < e.count; ++i) {
        for (size_t k = 0; k < layout.slots.size(); ++k) v[layout.slots[k]] = number("a vertex property");
        builder.set(i, v);
      }
    } else {
      FaceBuilder faces{mesh, vertex_count, file, 0, {}};
      for (uint64_t f = 0; f < e.count; ++f)
        for (const auto& prop : e.properties) {
          if (!prop.is_list) {
            number("a property value");
            continue;
          }
          double n = number("a list length");
          if (n < 0 || n != static_cast<double>(static_cast<int64_t>(n)) ||
              n > static_cast<double>(c.remaining()))
            throw fail("bad list length");
          if (e.name == "face" && is_face_list(prop)) {
            faces.polygon.resize(static_cast<size_t>(n));
            for (auto& idx : faces.polygon) {
              double x = number("a vertex index");
              idx = x < 0 || x >= static_cast<double>(UINT32_MAX) ? UINT32_MAX : static_cast<uint32_t>(x);
            }
            faces.add(where);
          } else {
            for (int64_t k = 0; k < static_cast<int64_t>(n); ++k) number("a list value");
          }
        }
      skipped += faces.skipped;
    }
  }
}

}  // namespace

Scene read_ply(const std::filesystem::path& path) {
  const std::string file = path.string();
  MappedFile map(path);
  Header h = parse_header(map.data(), map.size(), file);
  bool has_vertex = false;
  for (const auto& e : h.elements) has_vertex |= e.name == "vertex";
  if (!has_vertex) throw Error(file + ": PLY file has no vertex element");
  Mesh mesh;
  size_t skipped = 0;
  switch (h.format) {
    case Format::ascii:
      read_ascii(map.data(), map.size(), h, file, mesh, skipped);
      break;
    case Format::binary_le:
      if constexpr (std::endian::native == std::endian::little)
        read_binary<false>(map.data(), map.size(), h, file, mesh, skipped);
      else
        read_binary<true>(map.data(), map.size(), h, file, mesh, skipped);
      break;
    case Format::binary_be:
      if constexpr (std::endian::native == std::endian::big)
        read_binary<false>(map.data(), map.size(), h, file, mesh, skipped);
      else
        read_binary<true>(map.data(), map.size(), h, file, mesh, skipped);
      break;
  }
  if (skipped > 0)
    std::fprintf(stderr, "lodstream: warning: %s: skipped %zu faces with fewer than 3 corners\n",
                 file.c_str(), skipped);
  return make_scene(std::move(mesh), path.stem().string());
}

}  // namespace lodstream
