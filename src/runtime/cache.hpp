// The client's page cache (DESIGN.md, Client runtime; issue 5): stored pages of one or more packages, keyed
// by (package content hash, page), under a byte budget. It lives in memory (not on disk) for the client's
// lifetime; because it is keyed by content hash, a client that reconnects to the same package finds its
// pages again and can tell the server what it holds (pages()), and a changed package (another hash) never
// sees stale pages.
//
// Eviction is by usefulness for the current and predicted views, not only by recency: the client sets, each
// frame, the pages the current cut draws (pinned: never evicted) and a usefulness per page (page_usefulness
// below); when over budget, the page with the lowest usefulness goes first, least recently used first among
// equals. A page inserted since the last set_usefulness counts as most useful (it was fetched because a cut
// asked for it) until set_usefulness rates it, the newest of them going first (arrivals come in the
// scheduler's order); a rated page absent from the usefulness map counts 0. Only
// pinned pages (and, transiently, unrated ones) can keep the cache over budget.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <span>
#include <unordered_map>
#include <vector>

#include "package/format.hpp"
#include "package/index.hpp"
#include "runtime/selection.hpp"

namespace lodstream::runtime {

class PageCache {
 public:
  explicit PageCache(uint64_t budget_bytes) : budget_(budget_bytes) {}

  // Stores (or replaces) page `page` of package `package`, then evicts down to the budget. Cost:
  // O(cached pages) when it evicts, O(log) otherwise.
  void insert(const package::ContentHash& package, uint32_t page, std::vector<uint8_t> bytes);
  // The page's bytes, or nullptr; marks it used. The pointer is valid until the next insert / set_usefulness
  // / clear.
  const std::vector<uint8_t>* find(const package::ContentHash& package, uint32_t page);
  bool contains(const package::ContentHash& package, uint32_t page) const;
  // Pages of `package` held, sorted (what a reconnecting client reports).
  std::vector<uint32_t> pages(const package::ContentHash& package) const;

  // Replaces the pins and usefulness of `package`'s pages, then evicts down to the budget.
  void set_usefulness(const package::ContentHash& package, std::span<const uint32_t> pinned,
                      const std::unordered_map<uint32_t, double>& usefulness);
  // Changes the budget, evicting down to it.
  void set_budget(uint64_t budget_bytes);
  // Drops every page of `package`.
  void clear(const package::ContentHash& package);

  uint64_t bytes() const { return bytes_; }
  uint64_t budget() const { return budget_; }
  uint64_t evicted_pages() const { return evicted_; }

 private:
  struct Key {
    uint64_t low, high;
    uint32_t page;
    auto operator<=>(const Key&) const = default;
  };
  struct Entry {
    std::vector<uint8_t> bytes;
    uint64_t last_use = 0;
    double usefulness = INFINITY;  // unrated
    bool pinned = false;
  };
  static Key key(const package::ContentHash& h, uint32_t page) { return {h.low, h.high, page}; }
  void evict();

  uint64_t budget_, bytes_ = 0, clock_ = 0, evicted_ = 0;
  std::map<Key, Entry> entries_;
};

struct PageUsefulness {
  std::vector<uint32_t> pinned;                     // pages of the current cut's drawn nodes
  std::unordered_map<uint32_t, double> usefulness;  // per page of `cached_nodes`
};

// Usefulness of the pages holding `cached_nodes` (node ids whose page is cached and whose record is known):
// a page's usefulness is the largest, over `views` (the current one and predicted ones), the objects
// instancing a node's representation that are in that view's frustum, and the page's nodes n, of the
// projected error of n's parents (parent_error, parent_sphere): the error that shows where n is dropped and
// its parents drawn instead (+inf for a root, so roots stay longest). Pages of `current`'s drawn nodes are
// pinned. Cost: O(cached nodes * views * instances).
PageUsefulness page_usefulness(const package::PackageScene& scene, const NodeSource& nodes,
                               const Cut& current, std::span<const View> views,
                               std::span<const uint32_t> cached_nodes);

}  // namespace lodstream::runtime
