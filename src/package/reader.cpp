#include "package/reader.hpp"

#include <algorithm>
#include <charconv>

#include "core/error.hpp"
#include "package/page_parts.hpp"
#include "package/records.hpp"

namespace lodstream::package {

namespace {
constexpr uint64_t kOpenReadBytes = 64 * 1024;
}

PackageReader PackageReader::open(const std::filesystem::path& file) {
  return PackageReader(std::make_shared<FileSource>(file));
}

PackageReader::PackageReader(std::shared_ptr<const ByteSource> source) : source_(std::move(source)) {
  const uint64_t size = source_->size();
  if (size < 2 * kHeaderSize) {
    throw Error(where("too small to be a .lods package (" + std::to_string(size) + " bytes)"));
  }
  // One read of the tail: the trailer and usually the whole root index.
  const uint64_t tail_size = std::min(size, kOpenReadBytes);
  const uint64_t tail_offset = size - tail_size;
  std::vector<uint8_t> tail(tail_size);
  source_->read(tail_offset, tail);
  std::copy(tail.end() - kHeaderSize, tail.end(), trailer_.begin());
  header_ = decode_header(std::span<const uint8_t, kHeaderSize>(trailer_), size, where("trailer"));

  const Range root_range{header_.root_offset, header_.root_size, header_.root_raw_size,
                         header_.root_checksum};
  std::vector<uint8_t> raw_root;
  if (root_range.offset >= tail_offset) {
    auto first = tail.begin() + std::ptrdiff_t(root_range.offset - tail_offset);
    raw_root = unpack(root_range, std::span<const uint8_t>(&*first, root_range.size), "root index");
  } else {
    raw_root = unpack(root_range, read_range(root_range, "root index"), "root index");
  }
  root_ = parse_root(raw_root, where("root index"));
  index_map_ = IndexPageMap(root_);
  codec_ = &node_codec(root_.codec);
  check_layout();
  index_pages_.resize(root_.index_pages.size());
}

// Every stored range lies between the header and the root index, and no two overlap.
void PackageReader::check_layout() const {
  struct Span {
    uint64_t offset, size;
    std::string what;
  };
  std::vector<Span> spans;
  spans.reserve(root_.pages.size() + root_.blobs.size() + root_.index_pages.size());
  for (size_t i = 0; i < root_.pages.size(); ++i) {
    spans.push_back({root_.pages[i].offset, root_.pages[i].size, "page " + std::to_string(i)});
  }
  for (size_t i = 0; i < root_.blobs.size(); ++i) {
    if (root_.blobs[i].raw_size != root_.blobs[i].size)
      throw Error(where("blob " + std::to_string(i) + " has inconsistent sizes"));
    spans.push_back({root_.blobs[i].offset, root_.blobs[i].size, "blob " + std::to_string(i)});
  }
  for (size_t i = 0; i < root_.index_pages.size(); ++i) {
    spans.push_back({root_.index_pages[i].range.offset, root_.index_pages[i].range.size,
                     "index page " + std::to_string(i)});
  }
  std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) { return a.offset < b.offset; });
  uint64_t end = kHeaderSize;
  for (const Span& s : spans) {
    if (s.offset < end)
      throw Error(
          where(s.what + " at offset " + std::to_string(s.offset) + " overlaps the header or another range"));
    if (s.size > header_.root_offset || s.offset > header_.root_offset - s.size) {
      throw Error(where(s.what + " [" + std::to_string(s.offset) + ", +" + std::to_string(s.size) +
                        ") extends past the start of the root index"));
    }
    end = s.offset + s.size;
  }
}

std::vector<uint8_t> PackageReader::read_range(const Range& range, const std::string& what) const {
  // Ranges were checked against the layout at open (the root index's against the header), so this allocation
  // is bounded by the file size.
  std::vector<uint8_t> stored(range.size);
  source_->read(range.offset, stored);
  (void)what;
  return stored;
}

void PackageReader::check_stored(const Range& range, std::span<const uint8_t> stored,
                                 const std::string& what) const {
  if (stored.size() != range.size) {
    throw Error(where(what + ": " + std::to_string(stored.size()) + " bytes given, " +
                      std::to_string(range.size) + " expected"));
  }
  if (checksum64(stored) != range.checksum) {
    throw Error(
        where(what + " at offset " + std::to_string(range.offset) + ": checksum mismatch (corrupted)"));
  }
}

std::vector<uint8_t> PackageReader::unpack(const Range& range, std::span<const uint8_t> stored,
                                           const std::string& what) const {
  check_stored(range, stored, what);
  return zstd_decompress(stored, range.raw_size, where(what));
}

uint32_t PackageReader::index_page_of(uint32_t id) const {
  if (id >= root_.node_count) {
    throw Error(where("node " + std::to_string(id) + " does not exist (" + std::to_string(root_.node_count) +
                      " nodes)"));
  }
  return index_map_.page_of(id);
}

bool PackageReader::has_node(uint32_t id) const {
  uint32_t page = index_page_of(id);
  return page == kNone || !index_pages_[page].empty();
}

const NodeRecord* PackageReader::held_node(uint32_t id) const {
  if (id >= root_.node_count) return nullptr;
  const uint32_t page = index_map_.page_of(id);
  if (page == kNone) return &root_.root_nodes[id];
  const std::vector<NodeRecord>& records = index_pages_[page];
  return records.empty() ? nullptr : &records[id - root_.index_pages[page].first_node];
}

void PackageReader::add_index_page(uint32_t page, std::span<const uint8_t> stored) {
  if (page >= root_.index_pages.size())
    throw Error(where("index page " + std::to_string(page) + " does not exist"));
  const IndexPage& p = root_.index_pages[page];
  const std::string what = "index page " + std::to_string(page);
  std::vector<uint8_t> raw = unpack(p.range, stored, what);
  index_pages_[page] = parse_nodes(raw, root_, p.first_node, p.node_count, where(what));
}

const NodeRecord& PackageReader::node(uint32_t id) {
  uint32_t page = index_page_of(id);
  if (page == kNone) return root_.root_nodes[id];
  if (index_pages_[page].empty()) {
    add_index_page(page, read_range(root_.index_pages[page].range, "index page"));
  }
  return index_pages_[page][id - root_.index_pages[page].first_node];
}

std::vector<uint8_t> PackageReader::unpack_page(uint32_t page, std::span<const uint8_t> stored) const {
  std::vector<uint8_t> out;
  unpack_page(page, stored, out);
  return out;
}

std::span<const uint8_t> PackageReader::unpack_page(uint32_t page, std::span<const uint8_t> stored,
                                                    std::vector<uint8_t>& buffer) const {
  if (page >= root_.pages.size()) throw Error(where("page " + std::to_string(page) + " does not exist"));
  const Range& range = root_.pages[page];
  const std::string what = "page " + std::to_string(page);
  check_stored(range, stored, what);
  return decompress_page(stored, range.raw_size, *codec_, where(what), buffer);
}

std::vector<uint8_t> PackageReader::read_page(uint32_t page) const {
  std::vector<uint8_t> out;
  read_page(page, out);
  return out;
}

std::span<const uint8_t> PackageReader::read_page(uint32_t page, std::vector<uint8_t>& buffer) const {
  if (page >= root_.pages.size()) throw Error(where("page " + std::to_string(page) + " does not exist"));
  // The stored bytes in a per-thread buffer kept at the largest page read, like `buffer`.
  thread_local std::vector<uint8_t> stored;
  const Range& range = root_.pages[page];
  if (stored.size() < range.size) stored.resize(range.size);  // bounded by the file (check_layout)
  const std::span<uint8_t> bytes = std::span(stored).first(range.size);
  source_->read(range.offset, bytes);
  return unpack_page(page, bytes, buffer);
}

std::span<const uint8_t> PackageReader::node_bytes(uint32_t id, std::span<const uint8_t> page) {
  return record_bytes(id, node(id), page);
}

std::span<const uint8_t> PackageReader::record_bytes(uint32_t id, const NodeRecord& n,
                                                     std::span<const uint8_t> page) const {
  if (page.size() != root_.pages[n.page].raw_size) {
    throw Error(where("node " + std::to_string(id) + ": given page is not page " + std::to_string(n.page)));
  }
  return page.subspan(n.offset, n.size);  // offset + size <= raw_size was checked when the record was parsed
}

DecodedNode PackageReader::decode_node(uint32_t id, std::span<const uint8_t> page) {
  DecodedNode decoded;
  decode_node(id, page, decoded);
  return decoded;
}

void PackageReader::decode_node(uint32_t id, std::span<const uint8_t> page, DecodedNode& decoded) {
  const NodeRecord& n = node(id);
  // The error context, built in a buffer kept across calls (a string built anew took three allocations a
  // node), the numbers by to_chars (std::to_string's strings took ~5 M of elephant_1m's 19,860 nodes), and
  // only where it may be read: for a record decoded from its bytes and for an error, not for the other
  // clusters of the last record (refined_elephant's `bench decode --runs 1` under callgrind: decode_node
  // 46.57 -> 46.29 M instructions, ~220 a node).
  auto context = [&]() -> const std::string& {
    std::string& what = node_context_;
    char digits[2][10];
    const size_t id_digits = size_t(std::to_chars(digits[0], digits[0] + 10, id).ptr - digits[0]);
    const size_t page_digits = size_t(std::to_chars(digits[1], digits[1] + 10, n.page).ptr - digits[1]);
    what.assign(source_->name()).append(": node ").append(digits[0], id_digits);
    what.append(" (page ").append(digits[1], page_digits).append(")");
    return what;
  };
  if (n.encoding != NodeEncoding::codec) throw Error(context() + ": holds raw bytes, not codec geometry");
  std::span<const uint8_t> bytes = record_bytes(id, n, page);
  const Representation& rep = root_.scene.representations[n.representation];
  // The last record decoded is kept (in buffers reused by the next: no allocation or clearing per record),
  // so that a record's clusters, usually decoded one after another (consecutive ids of one page group),
  // decode it once.
  LastRecord& last = last_record_;
  if (!(last.valid && last.page == n.page && last.offset == n.offset && last.size == n.size)) {
    last.valid = false;  // until decoded: a corrupted record leaves none
    codec_->decode_into(bytes, rep.grid, context(), last.decoded);
    cluster_firsts(last.decoded, last.firsts);
    last.valid = true, last.page = n.page, last.offset = n.offset, last.size = n.size;
  }
  // extract_cluster reads its context only to refuse a cluster the record does not hold.
  const bool held = n.cluster < record_clusters(last.decoded);
  extract_cluster(last.decoded, n.cluster, held ? last.firsts[n.cluster] : 0,
                  held ? node_context_ : context(), decoded);
  if (decoded.mesh.triangle_count() != n.triangles) {
    throw Error(context() + ": record says " + std::to_string(n.triangles) + " triangles, its bytes hold " +
                std::to_string(decoded.mesh.triangle_count()));
  }
  decoded.mesh.material = n.material;
}

DecodedNode PackageReader::load_node(uint32_t id) {
  return decode_node(id, read_page(node(id).page));
}

std::vector<uint8_t> PackageReader::read_blob(uint32_t blob) const {
  if (blob >= root_.blobs.size()) throw Error(where("blob " + std::to_string(blob) + " does not exist"));
  const Range& r = root_.blobs[blob];
  std::vector<uint8_t> bytes = read_range(r, "blob");
  if (checksum64(bytes) != r.checksum) {
    throw Error(where("blob " + std::to_string(blob) + " at offset " + std::to_string(r.offset) +
                      ": checksum mismatch (corrupted)"));
  }
  return bytes;
}

void PackageReader::verify() const {
  std::array<uint8_t, kHeaderSize> header_bytes{};
  source_->read(0, header_bytes);
  if (header_bytes != trailer_) throw Error(where("header and trailer differ (corrupted)"));
  ContentHasher hasher;
  std::vector<uint8_t> chunk(1 << 20);
  const uint64_t end = header_.file_size - kHeaderSize;
  for (uint64_t at = kHeaderSize; at < end;) {
    size_t n = size_t(std::min<uint64_t>(chunk.size(), end - at));
    source_->read(at, std::span(chunk).first(n));
    hasher.update(std::span(chunk).first(n));
    at += n;
  }
  if (hasher.digest() != header_.content_hash) {
    throw Error(where("content hash mismatch: the file was modified or corrupted"));
  }
}

void PackageReader::verify_contents() {
  verify();
  for (uint32_t page = 0; page < root_.index_pages.size(); ++page) {
    if (index_pages_[page].empty())
      add_index_page(page, read_range(root_.index_pages[page].range, "index page"));
  }
  std::vector<std::vector<uint32_t>> nodes_of_page(root_.pages.size());
  for (uint32_t id = 0; id < root_.node_count; ++id) nodes_of_page[node(id).page].push_back(id);
  std::vector<uint8_t> buffer;  // one for every page
  for (uint32_t page = 0; page < root_.pages.size(); ++page) {
    const std::span<const uint8_t> raw = read_page(page, buffer);
    for (uint32_t id : nodes_of_page[page]) {
      if (node(id).encoding == NodeEncoding::codec) decode_node(id, raw);
    }
  }
}

}  // namespace lodstream::package
