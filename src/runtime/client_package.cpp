#include "runtime/client_package.hpp"

namespace lodstream::runtime {

using schedule::PageKind;

namespace {
uint64_t key(PageKind kind, uint32_t id) {
  return uint64_t(kind) << 32 | id;
}
}  // namespace

ClientPackage::ClientPackage(package::PackageReader reader, uint64_t cache_bytes)
    : reader_(std::move(reader)),
      cache_(cache_bytes),
      nodes_(reader_, cache_),
      scheduler_(reader_.root()),
      cached_(reader_.root().pages.size(), false) {}

void ClientPackage::install(PageKind kind, uint32_t id, std::span<const uint8_t> stored) {
  add(kind, id, stored);
  bytes_received_ += stored.size();
}

void ClientPackage::restore(PageKind kind, uint32_t id, std::span<const uint8_t> stored) {
  add(kind, id, stored);
  bytes_restored_ += stored.size();
}

void ClientPackage::add(PageKind kind, uint32_t id, std::span<const uint8_t> stored) {
  if (kind == PageKind::index) {
    reader_.add_index_page(id, stored);
  } else {
    cache_.insert(reader_.header().content_hash, id, reader_.unpack_page(id, stored));
    cached_[id] = true;
  }
  scheduler_.set_held(kind, id);
  in_flight_.erase(key(kind, id));
}

void ClientPackage::requested(const schedule::PageRef& page) {
  scheduler_.set_held(page.kind, page.id);
  in_flight_.insert(key(page.kind, page.id));
}

void ClientPackage::dropped(const schedule::PageRef& page) {
  if (in_flight_.erase(key(page.kind, page.id))) scheduler_.set_held(page.kind, page.id, false);
}

Frame ClientPackage::frame(const View& view, std::span<const View> predicted,
                           const schedule::CutOptions& options) {
  Frame f;
  f.cut = select_cut(reader_.scene(), nodes_, view, options);
  f.quality = frame_quality(reader_.scene(), nodes_, f.cut, view, options.tau);
  // Eviction order for the current and predicted views; what the cache let go may be scheduled again.
  const auto hash = reader_.header().content_hash;
  const std::vector<uint32_t> cached_pages = cache_.pages(hash);
  std::vector<uint32_t> cached_nodes;
  std::vector<uint8_t> cached(reader_.root().pages.size(), 0);
  for (uint32_t page : cached_pages)
    if (page < cached.size()) cached[page] = 1;
  for (uint32_t id = 0; id < reader_.node_count(); ++id)
    if (const package::NodeRecord* r = nodes_.record(id); r && cached[r->page]) cached_nodes.push_back(id);
  std::vector<View> views{view};
  views.insert(views.end(), predicted.begin(), predicted.end());
  const PageUsefulness u = page_usefulness(reader_.scene(), nodes_, f.cut, views, cached_nodes);
  cache_.set_usefulness(hash, u.pinned, u.usefulness);
  // Pages evicted here or by an insert since the last frame (an arrival that overflowed the budget).
  if (cache_.evicted_pages() != evictions_seen_) {
    evictions_seen_ = cache_.evicted_pages();
    for (uint32_t page = 0; page < cached_.size(); ++page)
      if (cached_[page] && !cache_.contains(hash, page)) {
        cached_[page] = false;
        scheduler_.set_held(PageKind::data, page, false);
        evicted_.push_back(page);
      }
  }
  return f;
}

std::vector<uint32_t> ClientPackage::held(PageKind kind) const {
  std::vector<uint32_t> pages;
  const size_t count =
      kind == PageKind::data ? reader_.root().pages.size() : reader_.root().index_pages.size();
  for (uint32_t id = 0; id < count; ++id)
    if (scheduler_.held(kind, id) && !in_flight_.count(key(kind, id))) pages.push_back(id);
  return pages;
}

}  // namespace lodstream::runtime
