// The streamed form of a progressive mesh (hierarchy/progressive_steps.hpp): what each prefix step stores
// besides its codec geometry (the vertex-substitution chains, in the codec's extra bytes) and how a client
// assembles the mesh of steps 0..j from their decoded nodes (seed 002 §2.5, TRAVERSE: the vertex prefix, the
// triangle prefix, each corner >= nv replaced by its parent until it is below nv).
//
// Chains bytes: varint count n, then n pairs (vertex, parent) sorted by vertex: varint (vertex - previous
// vertex - 1, the first one's "previous" being -1), varint (vertex - parent - 1), so parent < vertex always.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh.hpp"
#include "package/node_codec.hpp"

namespace lodstream::package {

// Encodes (vertex, parent) pairs, sorted by vertex with parent < vertex (throws lodstream::Error otherwise).
// Cost: O(n).
std::vector<uint8_t> encode_chains(std::span<const std::pair<uint32_t, uint32_t>> chains);

// Decodes encode_chains' bytes; every vertex must be below `index_end`. Throws lodstream::Error starting
// with `where` on corrupted bytes. Cost: O(bytes).
std::vector<std::pair<uint32_t, uint32_t>> decode_chains(std::span<const uint8_t> bytes, uint32_t index_end,
                                                         const std::string& where);

// The mesh of the prefix made of `steps` (decoded nodes of steps 0..j, in order): their vertices
// concatenated (each step must start where the previous one ended), their triangles concatenated, every
// corner >= nv (the vertex count) resolved through the chains the steps carry. Validates as it goes: a gap
// between steps, attributes present in one step and not another, a corner with no chain, or a triangle that
// resolves to a repeated vertex (none does in a well-formed prefix) is a lodstream::Error starting with
// `where`. Material: step 0's. Cost: O(vertices + triangles + chain hops).
Mesh assemble_prefix(std::span<const DecodedNode* const> steps, const std::string& where);

}  // namespace lodstream::package
