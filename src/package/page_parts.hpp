// Data pages stored by part (format version 3). zstd entropy-codes a block's literals with one Huffman table,
// so a page of whole nodes codes position residuals, normal residuals, connectivity symbols and headers with
// one table for all. Stored by part, a page is the same bytes regrouped: the parts of NodeSizeBreakdown
// (header, positions' low byte planes, their other planes, normals' low and other planes, attributes,
// locked, connectivity: eight) of every node, part by part, each part ending a zstd block, so that each gets
// its own tables (matches may still reach back across parts). Measured (bake, codec 3, zstd 9, min match 6,
// whole package), six parts (positions and normals whole), then eight: elephant_1m 7,279,505 -> 6,850,221 B
// (-5.9 %) -> 6,749,830 (also with the damped parallelogram: -0.4 % of this), refined_elephant 569,408 ->
// 539,775 (-5.2 %) -> 530,950 (-0.9 %), motorBike (10-bit normals) 2,607,957 -> 2,528,943 (-3.0 %), then -1.4
// %; decode (bench_package, codec 3, checksum + zstd + codec) 33.4 -> 31.4 M triangles/s per core (load 5.5).
//
// Format 6: six parts (header, positions, normals, attributes, locked, connectivity), and for the byte-plane
// codecs (2, 3) a residual part (positions, normals) is, when not empty, a form byte then either (0) the
// nodes' planes as the nodes hold them, or (1) the residuals of all the page's nodes as one stream of
// residual_coder.hpp (an entropy coder of our own, order 0, rANS), which zstd then stores as it is (a block
// of its own, incompressible). The writer keeps the smaller as zstd stores it, the planes' size estimated
// by compressing the part alone at zstd level 1 (page_parts.cpp; measuring it at the pages' level 9 took
// as long as compressing the page): on scans the coded form (sub-bit codes for the many tiny residuals), on
// regular synthetic meshes the planes (zstd's matches find repeated residual runs that an order-0 coder
// cannot: a page of a UV sphere took 6,786 B coded against 5,081 B whole). The coded form must also pay for
// its decode, about 25 instructions a residual against about 3 for zstd's Huffman stage over the planes: it
// is kept only when it saves at least 0.2 bit a residual. Measured (whole pages, coded against zstd'd
// planes): on the pages of bench_package (refined_elephant) the positions save 0.12 bit a residual, the
// normals 0.34; elephant_1m 0.26 and 0.30. With both coded BM_Decode/4 took ~440 instructions a triangle
// (callgrind, decode_node + unpack_page; 382 all planes), with the rule 404. Sizes in residual_coder.hpp.
//
// Format 7: seven parts, the connectivity split into the nodes' connectivity streams and their tails
// (NodeSizeBreakdown::tail; codec 3: the traversal's symbols, then its references), and for the byte-plane
// codecs the connectivity part, when not empty, is a form byte then either (0) the nodes' bytes or (1) the
// symbols of all the page's nodes as one stream of symbol_coder.hpp (the previous symbol as context, rANS),
// when they are all traversal symbols and that saves kMinSavedBits a symbol over zstd (the decode costs
// about 35 instructions a symbol). The references, varints that zstd compresses to about two thirds, stay
// bytes in a block of their own. Measured (`lodstream bake --json`, format 6 -> 7): see symbol_coder.hpp.
// Format 13: the connectivity part is the nodes' bytes again, no form byte: a record's symbols are a rANS
// stream under fixed tables that the traversal decodes itself (traversal_connectivity.hpp), with no page
// pass and no page tables (symbol_coder.hpp is gone; its figures are in git history, format 12).
//
// Format 9: the positions' residual part may also take the split form (2): varint size of the first stream,
// then two streams of residual_coder.hpp, the first holding component 0 of every node's residuals (with the
// plane prediction, predictive_node.hpp, the distance from the gate triangle's plane: small), the second
// components 1 and 2; the writer keeps it when smaller than the one stream. `lodstream bake --json`, format
// 8 -> 9 (the plane prediction in one stream, then split): elephant_1m 3,794,801 -> 3,709,001 -> 3,599,331 B
// (-5.2 %), refined_elephant 325,520 -> 321,226 -> 318,287 (-2.2 %), motorBike 1,628,092 -> 1,596,611 ->
// 1,580,314 (-2.9 %).
//
// Format 13: the normals' residual part may also take the paired form (3): one paired stream of
// residual_coder.hpp (built-in tables, component 1 in the context of component 0); the writer keeps it when
// smaller than the one stream. `lodstream bake`, format 12 -> 13: see residual_coder.hpp.
//
// The regrouped bytes (the zstd frame's content): seven varints, the sizes of the seven part streams; then
// the streams. The header stream holds, per node in page order, varint node size then the node's header; the
// other streams the node's part, in the same order (the residual streams: the node's residuals, component
// by component, in the order of its planes). A reader walks the header stream: the codec's layout() of each
// header gives the sizes of that node's parts (NodeCodec::layout), and copying them back in order (decoding
// the residuals back into their planes) gives the page of whole nodes that the node records point into. A
// page whose frame holds exactly the page's raw size is stored whole: a page whose bytes are not all codec
// nodes, or a codec-1 page that is smaller whole. Pages of the byte-plane codecs (2, 3) are not also
// compressed whole: by part was smaller on every page of elephant_1m, motorBike and refined_elephant with
// codecs 2 and 3 and of the city with codec 3 (2,378 pages; elephant_1m codec 3 6,320,159 vs 6,764,425 B,
// format 3), and the second compression cost about a tenth of a bake's CPU. Codec 1's pages were smaller by
// part too on those meshes (400 pages), but not always: a small page of a test sphere is 1 % larger by part,
// so codec 1 keeps whichever is smaller.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "package/node_codec.hpp"

namespace lodstream::package {

// Whether pages of `codec` store their residuals coded (residual_coder.hpp): the byte-plane codecs 2 and 3.
bool residuals_coded(const NodeCodec& codec);

// The stored bytes of a page of whole nodes (`node_sizes`, in page order, add up to page.size()): one zstd
// frame at `level` / `min_match` (format.hpp's zstd_compress), by part when `codec` parses every node (for
// codec 1: and that is smaller), else whole. Cost: one zstd compression of the page (two for codec 1), and
// for the byte-plane codecs one at zstd level 1 of each residual part and its rANS coding.
std::vector<uint8_t> compress_page(std::span<const uint8_t> page, std::span<const uint32_t> node_sizes,
                                   const NodeCodec& codec, int level, int min_match);

// The page of whole nodes (raw_size bytes) from its stored frame, either form. Every size is checked: a
// corrupted or hostile page gives a lodstream::Error starting with `where`, never a crash or an allocation
// above 2 raw_size + 64 bytes. Cost: a zstd decompression, plus a copy of the page when stored by part (the
// regrouped bytes decompressed into a per-thread buffer kept at the largest size seen).
std::vector<uint8_t> decompress_page(std::span<const uint8_t> stored, uint32_t raw_size,
                                     const NodeCodec& codec, const std::string& where);
// The same into `buffer`, grown to raw_size when smaller and never shrunk; returns its first raw_size bytes,
// the page. A buffer kept across pages is allocated and zero-filled once, up to the largest page, where a
// fresh page was allocated and zero-filled every time (elephant_1m's bench decode, 356 pages: read_page
// 291.2 -> 277.9 M instructions under callgrind, which counts rep stosb a byte at a time).
std::span<const uint8_t> decompress_page(std::span<const uint8_t> stored, uint32_t raw_size,
                                         const NodeCodec& codec, const std::string& where,
                                         std::vector<uint8_t>& buffer);

}  // namespace lodstream::package
