// One chunk of an OBJ file's lines, parsed on its own: obj_reader.cpp cuts a file at line breaks into chunks,
// parses them in parallel and stitches the results (vertex numbering, object / group / material state).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lodstream {

// One face corner: 0-based indices into the file's positions, texture coordinates and normals; -1 when
// absent. A corner that the file gave as a relative (negative) index holds it relative to the chunk's own
// counts until ObjChunk::relative is applied.
struct ObjCorner {
  int32_t v = -1, vt = -1, vn = -1;
};

// A line that changes the reader's state between faces: `o NAME`, `g NAMES`, `usemtl NAME`, `mtllib FILES`.
struct ObjEvent {
  enum class Kind : uint8_t { object, group, use_material, material_library };
  Kind kind;
  uint32_t face;     // faces of the chunk before the line
  uint32_t line;     // the line's number within the chunk (0-based)
  std::string text;  // object name as written, group names joined by one space, material name, or the
                     // rest of the mtllib line
};

struct ObjChunk {
  std::vector<float> positions;    // x y z per `v`
  std::vector<float> colors;       // r g b per `v` (the `v x y z r g b` extension); empty while all are white
  std::vector<float> texcoords;    // u v per `vt`
  std::vector<float> normals;      // x y z per `vn`
  std::vector<ObjCorner> corners;  // corners of the faces, in order
  std::vector<std::pair<uint32_t, uint32_t>>
      polygons;        // (face, corner count) of each face that is no triangle
  uint32_t faces = 0;  // faces with at least 3 corners (shorter ones are skipped, see warning)
  // Corners holding a relative index: (corner, 0 for v / 1 for vt / 2 for vn).
  std::vector<std::pair<uint32_t, uint8_t>> relative;
  std::vector<ObjEvent> events;
  uint32_t lines = 0;  // line breaks in the chunk
  // The first problem met: an error stops the chunk's parsing, a warning does not. Line within the chunk.
  std::string error, warning;
  uint32_t error_line = 0, warning_line = 0;
};

// Parses the whole lines in [begin, end) the way the OBJ format (and tinyobjloader before this reader) reads
// them: `v` (with optional r g b), `vt` (v defaults to 0), `vn`, `f` with `i`, `i/j`, `i//k` or `i/j/k`
// corners (negative: relative to the vertices read so far), `o`, `g`, `usemtl`, `mtllib`; `#` lines,
// `l`, `p`, `s` and unknown keywords are ignored. A bad number or index sets `error`. `chunk` is cleared
// first, keeping its arrays' capacity. Cost: O(end - begin).
void parse_obj_chunk(const char* begin, const char* end, ObjChunk& chunk);

// The line (within the chunk [begin, end), which parsed without error) of its face number `face`.
// Cost: O(end - begin).
uint32_t obj_face_line(const char* begin, const char* end, uint32_t face);

}  // namespace lodstream
