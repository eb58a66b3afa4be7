#include "package/writer.hpp"

#include <tbb/parallel_for.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/page_parts.hpp"
#include "package/pair_rounding.hpp"
#include "package/quantized_node.hpp"

namespace lodstream::package {

namespace {

// zstd's minimum match length in the data pages of `codec` (0 = the level's own): 6 for the codecs of byte
// planes (predictive, traversal), whose short repeats cost more as matches than as literals. Measured at
// level 9 on refined_elephant's pages: codec 3 572,635 -> 559,507 B (-2.3 %; bunny -1.9 %, motorBike -1.0 %),
// codec 2 -0.3 %, while meshoptimizer's codec (1) grows 1.4 % and keeps the level's own.
int page_min_match(uint32_t codec) {
  return codec == MeshoptCodec::kId ? 0 : 6;
}

}  // namespace

PackageWriter::PackageWriter(std::filesystem::path file, WriterOptions options)
    : file_(std::move(file)), options_(options) {
  temp_ = file_;
  temp_ += ".tmp." + std::to_string(::getpid());
  out_ = std::fopen(temp_.c_str(), "wb");
  if (!out_) throw Error(temp_.string() + ": cannot create: " + std::strerror(errno));
  const std::array<uint8_t, kHeaderSize> placeholder{};
  write(placeholder, false);
}

PackageWriter::~PackageWriter() {
  compressing_.cancel();
  try {
    compressing_.wait();
  } catch (...) {  // a failed compression: the package is abandoned anyway
  }
  if (out_) {
    std::fclose(out_);
    std::error_code ignored;
    std::filesystem::remove(temp_, ignored);
  }
}

void PackageWriter::write(std::span<const uint8_t> bytes, bool hashed) {
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), out_) != bytes.size()) {
    throw Error(temp_.string() + ": write failed: " + std::strerror(errno));
  }
  if (hashed) hasher_.update(bytes);
  position_ += bytes.size();
}

Range PackageWriter::write_stored(std::span<const uint8_t> bytes, uint32_t raw_size) {
  if (bytes.size() > UINT32_MAX) throw Error(file_.string() + ": a stored range exceeds 4 GiB");
  Range r{position_, uint32_t(bytes.size()), raw_size, checksum64(bytes)};
  write(bytes, true);
  return r;
}

void PackageWriter::add_node(uint32_t id, std::span<const uint8_t> bytes) {
  add_record(std::span(&id, 1), bytes);
}

void PackageWriter::add_record(std::span<const uint32_t> ids, std::span<const uint8_t> bytes) {
  if (ids.empty() || ids.size() > kMaxRecordClusters) {
    throw Error(file_.string() + ": a record of " + std::to_string(ids.size()) + " clusters");
  }
  if (bytes.size() > kMaxPageRawBytes) {
    throw Error(file_.string() + ": node " + std::to_string(ids[0]) + " is larger than a page may be");
  }
  for (uint32_t id : ids) {
    if (id >= locations_.size()) locations_.resize(size_t(id) + 1);
    if (locations_[id].added) throw Error(file_.string() + ": node " + std::to_string(id) + " added twice");
    locations_[id].added = true;
  }
  group_.push_back({{ids.begin(), ids.end()}, group_bytes_.size(), bytes.size()});
  group_bytes_.insert(group_bytes_.end(), bytes.begin(), bytes.end());
}

void PackageWriter::place(size_t first, size_t end) {
  for (size_t i = first; i < end; ++i) {
    const Entry& e = group_[i];
    if (!page_.empty() && page_.size() + e.size > options_.page_bytes) flush_page();
    for (uint32_t c = 0; c < e.ids.size(); ++c) {
      locations_[e.ids[c]] = {uint32_t(pages_.size() + pending_.size()), uint32_t(page_.size()),
                              uint32_t(e.size), c, true};
    }
    page_.insert(page_.end(), group_bytes_.begin() + e.offset, group_bytes_.begin() + e.offset + e.size);
    page_nodes_.push_back(uint32_t(e.size));
  }
}

void PackageWriter::end_group() {
  if (group_.empty()) return;
  // A group that does not fit in what is left of the page starts a new one (it is split only if it alone is
  // larger than a page).
  if (!page_.empty() && page_.size() + group_bytes_.size() > options_.page_bytes) flush_page();
  place(0, group_.size());
  if (page_.size() >= options_.page_bytes) flush_page();
  group_.clear();
  group_bytes_.clear();
}

void PackageWriter::flush_page() {
  if (page_.empty()) return;
  PendingPage& p = pending_.emplace_back();
  p.raw = std::move(page_), p.node_sizes = std::move(page_nodes_);
  page_ = {}, page_nodes_ = {};
  compressing_.run([&p, codec = options_.codec, level = options_.zstd_level] {
    p.stored = compress_page(p.raw, p.node_sizes, node_codec(codec), level, page_min_match(codec));
    p.compressed.store(true, std::memory_order_release);
  });
  write_pending(false);
}

void PackageWriter::write_pending(bool all) {
  if (all || pending_.size() > kPendingPages) compressing_.wait();  // rethrows a task's error
  while (!pending_.empty() && pending_.front().compressed.load(std::memory_order_acquire)) {
    const PendingPage& p = pending_.front();
    pages_.push_back(write_stored(p.stored, uint32_t(p.raw.size())));
    page_bytes_ += p.stored.size();
    pending_.pop_front();
  }
}

uint32_t PackageWriter::add_blob(std::span<const uint8_t> bytes) {
  blobs_.push_back(write_stored(bytes, uint32_t(bytes.size())));
  return uint32_t(blobs_.size() - 1);
}

WrittenPackage PackageWriter::finish(PackageScene scene, std::vector<NodeRecord> nodes, uint32_t root_nodes) {
  if (!out_) throw Error(file_.string() + ": package already finished");
  end_group();
  flush_page();
  write_pending(true);
  const std::string name = file_.string();
  if (nodes.size() > UINT32_MAX - 1) throw Error(name + ": too many nodes");
  if (locations_.size() > nodes.size()) {
    throw Error(name + ": node " + std::to_string(locations_.size() - 1) + " was added but has no record");
  }
  if (root_nodes > nodes.size()) throw Error(name + ": more root-index nodes than nodes");
  for (size_t id = 0; id < nodes.size(); ++id) {
    if (id >= locations_.size() || locations_[id].page == kNone) {
      throw Error(name + ": node " + std::to_string(id) + " has a record but no bytes");
    }
    nodes[id].page = locations_[id].page;
    nodes[id].offset = locations_[id].offset;
    nodes[id].size = locations_[id].size;
    nodes[id].cluster = locations_[id].cluster;
  }
  round_pairs(nodes);  // every invariant kept (pair_rounding.hpp); the index stores rounded pairs compactly

  RootIndex root;
  root.codec = node_codec(options_.codec).id();
  root.scene = std::move(scene);
  root.pages = std::move(pages_);
  root.blobs = std::move(blobs_);
  root.node_count = uint32_t(nodes.size());
  WrittenPackage written;
  // Index pages: serialized, checked by the reader's parser and compressed on every core, written in order.
  const uint32_t per_page = options_.nodes_per_index_page;
  const size_t index_pages = (nodes.size() - root_nodes + per_page - 1) / per_page;
  std::vector<std::vector<uint8_t>> raw(index_pages), stored(index_pages);
  auto page_first = [&](size_t k) { return root_nodes + uint32_t(k) * per_page; };
  auto page_count = [&](size_t k) {
    return std::min<uint32_t>(per_page, uint32_t(nodes.size()) - page_first(k));
  };
  tbb::parallel_for(size_t(0), index_pages, [&](size_t k) {
    raw[k] = serialize_nodes(std::span(nodes).subspan(page_first(k), page_count(k)), page_first(k));
    if (raw[k].size() > kMaxIndexPageRawBytes)
      throw Error(name + ": index page too large; use fewer nodes per page");
    parse_nodes(raw[k], root, page_first(k), page_count(k), name + ": index page as written");
    stored[k] = zstd_compress(raw[k], options_.zstd_level);
  });
  for (size_t k = 0; k < index_pages; ++k) {
    root.index_pages.push_back(
        {write_stored(stored[k], uint32_t(raw[k].size())), page_first(k), page_count(k)});
    written.index_bytes += stored[k].size();
  }
  raw = {};
  stored = {};
  nodes.resize(root_nodes);
  root.root_nodes = std::move(nodes);
  std::vector<uint8_t> raw_root = serialize_root(root);
  if (raw_root.size() > kMaxRootRawBytes) throw Error(name + ": root index too large; put fewer nodes in it");
  // The writer's own output must pass the reader's validation.
  RootIndex reparsed = parse_root(raw_root, name + ": root index as written");
  std::vector<uint8_t> stored_root = zstd_compress(raw_root, options_.zstd_level);

  Header header;
  Range root_range = write_stored(stored_root, uint32_t(raw_root.size()));
  header.root_offset = root_range.offset;
  header.root_size = root_range.size;
  header.root_raw_size = root_range.raw_size;
  header.root_checksum = root_range.checksum;
  header.content_hash = hasher_.digest();
  header.file_size = position_ + kHeaderSize;
  const std::array<uint8_t, kHeaderSize> header_bytes = encode_header(header);
  write(header_bytes, false);
  if (std::fseek(out_, 0, SEEK_SET) != 0 ||
      std::fwrite(header_bytes.data(), 1, kHeaderSize, out_) != kHeaderSize || std::fflush(out_) != 0 ||
      ::fsync(::fileno(out_)) != 0) {
    throw Error(temp_.string() + ": write failed: " + std::strerror(errno));
  }
  int closed = std::fclose(out_);
  out_ = nullptr;
  std::error_code ec;
  if (closed == 0) std::filesystem::rename(temp_, file_, ec);
  if (closed != 0 || ec) {
    std::filesystem::remove(temp_, ec);
    throw Error(name + ": cannot move the finished package into place");
  }

  written.bytes = header.file_size;
  written.page_bytes = page_bytes_;
  written.root_index_bytes = stored_root.size();
  written.pages = uint32_t(reparsed.pages.size());
  written.index_pages = uint32_t(reparsed.index_pages.size());
  written.nodes = reparsed.node_count;
  written.content_hash = header.content_hash;
  return written;
}

}  // namespace lodstream::package
