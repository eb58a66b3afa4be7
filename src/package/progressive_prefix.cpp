#include "package/progressive_prefix.hpp"

#include <unordered_map>

#include "core/error.hpp"
#include "package/bytes.hpp"

namespace lodstream::package {

std::vector<uint8_t> encode_chains(std::span<const std::pair<uint32_t, uint32_t>> chains) {
  ByteWriter w;
  w.varint(chains.size());
  int64_t previous = -1;
  for (const auto& [vertex, parent] : chains) {
    if (int64_t(vertex) <= previous || parent >= vertex)
      throw Error("progressive chains: pairs must be sorted by vertex with parent < vertex");
    w.varint(uint64_t(int64_t(vertex) - previous - 1));
    w.varint(vertex - parent - 1);
    previous = vertex;
  }
  return std::move(w.bytes);
}

std::vector<std::pair<uint32_t, uint32_t>> decode_chains(std::span<const uint8_t> bytes, uint32_t index_end,
                                                         const std::string& where) {
  if (bytes.empty()) return {};
  ByteReader r(bytes, where);
  const size_t n = r.count(2, "chain pairs");
  std::vector<std::pair<uint32_t, uint32_t>> out(n);
  int64_t previous = -1;
  for (auto& [vertex, parent] : out) {
    const uint64_t gap = r.varint(), below = r.varint();
    if (gap >= uint64_t(index_end) || previous + 1 + int64_t(gap) >= int64_t(index_end))
      r.fail("chain vertex out of range");
    vertex = uint32_t(previous + 1 + int64_t(gap));
    if (below >= vertex) r.fail("chain parent out of range");
    parent = uint32_t(vertex - below - 1);
    previous = vertex;
  }
  r.expect_end();
  return out;
}

Mesh assemble_prefix(std::span<const DecodedNode* const> steps, const std::string& where) {
  Mesh out;
  if (steps.empty()) return out;
  const Mesh& first = steps[0]->mesh;
  out.material = first.material;
  std::unordered_map<uint32_t, uint32_t> parent;
  for (size_t k = 0; k < steps.size(); ++k) {
    const DecodedNode& s = *steps[k];
    const Mesh& m = s.mesh;
    const std::string step = where + ": step " + std::to_string(k);
    if (s.first_vertex != out.positions.size())
      throw Error(step + " starts at vertex " + std::to_string(s.first_vertex) + ", not where step " +
                  std::to_string(k) + " - 1 ended");
    if (m.has_normals() != first.has_normals() || m.has_uvs() != first.has_uvs() ||
        m.has_colors() != first.has_colors())
      throw Error(step + ": its attributes differ from step 0's");
    out.positions.insert(out.positions.end(), m.positions.begin(), m.positions.end());
    out.normals.insert(out.normals.end(), m.normals.begin(), m.normals.end());
    out.uvs.insert(out.uvs.end(), m.uvs.begin(), m.uvs.end());
    out.colors.insert(out.colors.end(), m.colors.begin(), m.colors.end());
    out.indices.insert(out.indices.end(), m.indices.begin(), m.indices.end());
    for (const auto& [vertex, p] : decode_chains(s.extra, s.index_end, step + " chains"))
      parent.emplace(vertex, p);
  }
  const uint32_t nv = uint32_t(out.positions.size());
  // TRAVERSE: every corner >= nv goes down its chain (parent < vertex, so each walk ends).
  for (uint32_t& c : out.indices)
    while (c >= nv) {
      auto it = parent.find(c);
      if (it == parent.end())
        throw Error(where + ": corner " + std::to_string(c) + " has no chain below " + std::to_string(nv) +
                    " vertices");
      c = it->second;
    }
  for (size_t t = 0; t < out.triangle_count(); ++t) {
    const uint32_t a = out.indices[3 * t], b = out.indices[3 * t + 1], c = out.indices[3 * t + 2];
    if (a == b || b == c || a == c)
      throw Error(where + ": triangle " + std::to_string(t) + " of the prefix is degenerate");
  }
  return out;
}

}  // namespace lodstream::package
