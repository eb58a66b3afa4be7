#include "io/obj_chunk.hpp"

#include <charconv>
#include <cstring>
#include <string_view>

namespace lodstream {

namespace {

bool blank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

// The next blank-separated token of a line (empty at its end).
std::string_view next_token(const char*& p, const char* end) {
  while (p < end && blank(*p)) ++p;
  const char* start = p;
  while (p < end && !blank(*p)) ++p;
  return {start, static_cast<size_t>(p - start)};
}

// A token for an error message: at most 32 characters, non-printable ones as '?'.
std::string quoted(std::string_view t) {
  std::string s(t.substr(0, 32));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return "'" + s + "'";
}

// The whole token as a number. Converted to double first and then rounded to float, as tinyobjloader did,
// so files read exactly as before. std::from_chars takes no leading '+', which OBJ writers may emit.
bool parse_real(std::string_view t, float& out) {
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  double d = 0;
  auto [ptr, ec] = std::from_chars(b, e, d);
  if (b == e || ec != std::errc() || ptr != e) return false;
  out = static_cast<float>(d);
  return true;
}

bool parse_int(std::string_view t, int32_t& out) {
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  auto [ptr, ec] = std::from_chars(b, e, out);
  return b != e && ec == std::errc() && ptr == e;
}

struct SyntaxError {
  std::string reason;
};

class ChunkParser {
 public:
  explicit ChunkParser(ObjChunk& chunk) : c_(chunk) {}

  void line(const char* p, const char* end) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (p == end || *p == '#') return;
    const size_t rest = static_cast<size_t>(end - p);
    const char k = *p;
    if (k == 'v' && rest > 1 && blank(p[1])) return vertex(p + 2, end);
    if (k == 'v' && rest > 2 && p[1] == 't' && blank(p[2])) return texcoord(p + 3, end);
    if (k == 'v' && rest > 2 && p[1] == 'n' && blank(p[2])) return normal(p + 3, end);
    if (k == 'f' && rest > 1 && blank(p[1])) return face(p + 2, end);
    if (k == 'o' && rest > 1 && blank(p[1]))  // the name is the rest of the line, as written
      return event(ObjEvent::Kind::object, std::string(p + 2, end));
    if (k == 'g' && rest > 1 && blank(p[1])) return group(p + 2, end);
    if (rest >= 6 && std::memcmp(p, "usemtl", 6) == 0) {
      const char* q = p + 6;
      return event(ObjEvent::Kind::use_material, std::string(next_token(q, end)));
    }
    if (rest > 6 && std::memcmp(p, "mtllib", 6) == 0 && blank(p[6]))
      return event(ObjEvent::Kind::material_library, std::string(p + 7, end));
  }

  void warn(const std::string& what) {
    if (c_.warning.empty()) c_.warning = what, c_.warning_line = c_.lines;
  }

 private:
  float real(const char*& p, const char* end, const char* what) {
    std::string_view t = next_token(p, end);
    float value = 0;
    if (!parse_real(t, value))
      throw SyntaxError{std::string("expected ") + what +
                        (t.empty() ? ", found the end of the line" : ", found " + quoted(t))};
    return value;
  }

  void vertex(const char* p, const char* end) {
    const float x = real(p, end, "the x coordinate"), y = real(p, end, "the y coordinate"),
                z = real(p, end, "the z coordinate");
    c_.positions.insert(c_.positions.end(), {x, y, z});
    // Optional colour: exactly three more numbers after x y z (a fourth value alone is a w, ignored).
    float rgb[3] = {1.0f, 1.0f, 1.0f};
    bool found = true;
    for (float& channel : rgb) found = found && parse_real(next_token(p, end), channel);
    if (!found) rgb[0] = rgb[1] = rgb[2] = 1.0f;
    const bool white = rgb[0] == 1.0f && rgb[1] == 1.0f && rgb[2] == 1.0f;
    if (c_.colors.empty() && white) return;
    if (c_.colors.empty()) c_.colors.assign(c_.positions.size() - 3, 1.0f);
    c_.colors.insert(c_.colors.end(), rgb, rgb + 3);
  }

  void texcoord(const char* p, const char* end) {
    const float u = real(p, end, "the u coordinate");
    std::string_view t = next_token(p, end);
    float v = 0.0f;  // `vt u` alone is allowed
    if (!t.empty() && !parse_real(t, v)) throw SyntaxError{"expected the v coordinate, found " + quoted(t)};
    c_.texcoords.insert(c_.texcoords.end(), {u, v});
  }

  void normal(const char* p, const char* end) {
    const float x = real(p, end, "the normal's x"), y = real(p, end, "the normal's y"),
                z = real(p, end, "the normal's z");
    c_.normals.insert(c_.normals.end(), {x, y, z});
  }

  // One index of a corner: positive 1-based, or negative relative to the `count` read so far.
  int32_t index(std::string_view t, size_t count, uint8_t which, std::string_view corner) {
    static const char* const names[] = {"vertex", "texture coordinate", "normal"};
    int32_t i = 0;
    if (!parse_int(t, i))
      throw SyntaxError{std::string("bad ") + names[which] + " index in face corner " + quoted(corner)};
    if (i == 0) throw SyntaxError{std::string(names[which]) + " index 0 in face corner (OBJ counts from 1)"};
    if (i > 0) return i - 1;
    c_.relative.emplace_back(static_cast<uint32_t>(c_.corners.size()), which);
    return static_cast<int32_t>(static_cast<int64_t>(count) + i);
  }

  void face(const char* p, const char* end) {
    const size_t first = c_.corners.size();
    for (std::string_view t = next_token(p, end); !t.empty(); t = next_token(p, end)) {
      ObjCorner corner;
      const size_t s1 = t.find('/');
      corner.v = index(t.substr(0, s1), c_.positions.size() / 3, 0, t);
      if (s1 != std::string_view::npos) {
        const size_t s2 = t.find('/', s1 + 1);
        std::string_view vt =
            t.substr(s1 + 1, s2 == std::string_view::npos ? std::string_view::npos : s2 - s1 - 1);
        if (s2 == std::string_view::npos || !vt.empty())  // `i//k` has no texture coordinate
          corner.vt = index(vt, c_.texcoords.size() / 2, 1, t);
        if (s2 != std::string_view::npos) corner.vn = index(t.substr(s2 + 1), c_.normals.size() / 3, 2, t);
      }
      c_.corners.push_back(corner);
    }
    const size_t n = c_.corners.size() - first;
    if (n < 3) {  // dropped, as tinyobjloader did
      warn("face with fewer than 3 corners skipped");
      while (!c_.relative.empty() && c_.relative.back().first >= first) c_.relative.pop_back();
      c_.corners.resize(first);
      return;
    }
    if (n != 3) c_.polygons.emplace_back(c_.faces, static_cast<uint32_t>(n));
    ++c_.faces;
  }

  // `g a b c`: the names joined by one space; `g` alone names the group "".
  void group(const char* p, const char* end) {
    std::string name;
    for (std::string_view t = next_token(p, end); !t.empty(); t = next_token(p, end)) {
      if (!name.empty()) name += ' ';
      name += t;
    }
    if (name.empty()) warn("empty group name");
    event(ObjEvent::Kind::group, std::move(name));
  }

  void event(ObjEvent::Kind kind, std::string text) {
    c_.events.push_back(ObjEvent{kind, c_.faces, c_.lines, std::move(text)});
  }

  ObjChunk& c_;
};

// The end of the line starting at `p` (its '\n', or `end`) and the end of its content (before a '\r').
std::pair<const char*, const char*> line_end(const char* p, const char* end) {
  const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
  if (!eol) eol = end;
  const char* content = eol;
  if (content > p && content[-1] == '\r') --content;
  return {eol, content};
}

}  // namespace

void parse_obj_chunk(const char* begin, const char* end, ObjChunk& chunk) {
  for (auto* v : {&chunk.positions, &chunk.colors, &chunk.texcoords, &chunk.normals}) v->clear();
  chunk.corners.clear();
  chunk.polygons.clear();
  chunk.relative.clear();
  chunk.events.clear();
  chunk.faces = chunk.lines = chunk.error_line = chunk.warning_line = 0;
  chunk.error.clear();
  chunk.warning.clear();
  ChunkParser parser(chunk);
  try {
    for (const char* p = begin; p < end;) {
      auto [eol, content] = line_end(p, end);
      parser.line(p, content);
      if (eol == end) break;
      p = eol + 1;
      ++chunk.lines;
    }
  } catch (const SyntaxError& e) {
    chunk.error = e.reason;
    chunk.error_line = chunk.lines;
  }
}

uint32_t obj_face_line(const char* begin, const char* end, uint32_t face) {
  uint32_t line = 0, faces = 0;
  for (const char* p = begin; p < end; ++line) {
    auto [eol, content] = line_end(p, end);
    const char* q = p;
    while (q < content && (*q == ' ' || *q == '\t')) ++q;
    if (content - q > 1 && q[0] == 'f' && blank(q[1])) {
      q += 2;
      int corners = 0;
      while (!next_token(q, content).empty()) ++corners;
      if (corners >= 3 && faces++ == face) return line;
    }
    if (eol == end) break;
    p = eol + 1;
  }
  return line;
}

}  // namespace lodstream
