// The page scheduler (DESIGN.md, Serving and the wire; seed 003 §5, "greedy by benefit per byte"): which
// pages of a package to transfer next, for a client whose views are known (the current one and predicted
// ones). The same code runs in the push server (per session), in a pulling client and in the benchmark's
// simulator; it is pure computation.
//
// Unit of benefit: a group exchange (schedule/cut.hpp) of a view's ideal cut whose G is not all held. Its
// benefit is the screen area it refines times the error it removes on a log scale, summed over the weighted
// views:
//   benefit = sum_v w_v * A_i * min(1, |P| a(P) / W_i) * gain(P, G) / sum_j A_j,
//   gain(P, G) = sum_g a(g) ln(max(e_P, tau) / max(e_g, tau)) / sum_g a(g) over G's members g,
// A_i the clipped screen area of the exchange's object, a(P) that of P's bounding sphere (shared by P's
// nodes), W_i the screen area of the nodes drawn now for object i (so |P| a(P) / W_i is P's weight in
// alpha_i's area-weighted mean), e_P and e_g the projected errors of P and of a member g (members come from
// different groups: their errors differ), a(g) the screen area of g's sphere, sum_j A_j the screen area of
// the objects in view v's frustum. For an object's roots the share is 1 and the gain a constant 10 (drawing
// something where nothing is drawn comes before refining). Measured alternatives (motorBike, gen:fly, 10
// Mbit/s): the one-step accuracy gain min(1, tau/e_G) - min(1, tau/e_P) starves coarse exchanges, whose own
// gain is tiny but which unlock everything below (benefit ratio 0.25 at 1 s where sse-pull had 0.5); the
// reachable gain 1 - min(1, tau/e_P) went deep in few places (0.14 at 1 s, AUC 0.942); the log gain gives
// 0.51 at 1 s and AUC 0.949 (sse-pull 0.948, oracle 0.956), and on the city 0.947 (sse-pull 0.869). Its cost
// is the stored bytes of the pages it still needs: the data pages of G's members and the index pages of the
// records of P and G that are not held. Greedy (seed 003, E11): exchanges are ranked once by benefit / cost
// (costs as of the call); the first eligible one in that order goes next (eligible: all of P held or chosen,
// so it refines what will be drawn), its pages counted as held, which may make later ones eligible. Exchanges
// of no benefit (no screen area: outside the viewport) come after all others, by e_P per byte, so that a
// view's ideal cut is always reached. Where the records the scheduler sees are unknown (a pulling client that
// has not fetched an index page yet), the index page comes first, by the projected error its arrival may
// remove.
//
// HLOD (cut.hpp): the exchange below a proxy P has as G its child proxies, or for a leaf the roots of all
// its objects in the frustum (one exchange, as the cut refines a leaf only when every one is available);
// every object a proxy draws is drawn by it whole, so its benefit is sum_o A_o ln(max(e_P, tau) /
// max(e_o, tau)) / sum_j A_j over the objects o of G's members (e_o: the member's projected error; the
// HLOD's roots count kRootGain), held members included. Measured (city with HLOD, gen:fly, 10 Mbit/s):
// valuing each object's roots as its own exchange, and proxies by their parent's sphere, kept push at 22
// proxies for 3.9 s (to 0.95 in 5.30 s, 2.40 s with leaves as one exchange); counting only the members not
// held yet left the buildings (whose roots arrive with the root index) under a coarse proxy (oracle 4.87
// s, 2.20 s counting them).
//
// Cost: one select_cut per view, then O(E log E) to rank and O(E) cheap checks per exchange picked, over the
// E exchanges of the views' ideal cuts.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "package/index.hpp"
#include "package/index_page_map.hpp"
#include "schedule/cut.hpp"
#include "schedule/motion.hpp"

namespace lodstream::schedule {

enum class PageKind : uint8_t { data = 0, index = 1 };

// One page to transfer: a data page (root().pages) or an index page (root().index_pages), with its stored
// size.
struct PageRef {
  PageKind kind = PageKind::data;
  uint32_t id = 0;
  uint32_t bytes = 0;
  bool operator==(const PageRef&) const = default;
};

struct ScheduleOptions {
  double tau = 1.0;                 // target pixel error
  uint64_t max_bytes = UINT64_MAX;  // stop once the pages chosen add up to this much (at least one page)
  size_t max_pages = SIZE_MAX;
  // The planned cuts' triangle budget (CutOptions::triangle_budget), e.g. what the client's cache affords
  // (cache_budget.hpp).
  uint64_t triangle_budget = UINT64_MAX;
};

class PageScheduler {
 public:
  // The package's page tables (sizes, index-page coverage); `root` must outlive the scheduler.
  explicit PageScheduler(const package::RootIndex& root);

  // Marks a page held (arrived, or sent and in flight: never scheduled again) or not held (evicted).
  void set_held(PageKind kind, uint32_t id, bool held = true);
  bool held(PageKind kind, uint32_t id) const;
  // Whether node `id`'s record is held by the client (in the root index or in a held index page).
  bool record_held(uint32_t id) const;
  // Whether node `id`'s data page is held.
  bool node_held(const package::NodeRecord& record) const { return held(PageKind::data, record.page); }
  // A page with its byte cost: its stored size, unless set_cost said otherwise.
  PageRef page(PageKind kind, uint32_t id) const;
  // The bytes data page `id` costs to bring to the client (what next() ranks benefit per byte by and fills
  // max_bytes with): a push server prices a page the client keeps on disk at the message that restores it.
  // Throws lodstream::Error for a page the package does not have. Cost: O(1).
  void set_cost(uint32_t id, uint32_t bytes);
  // The index page that holds node `id`'s record, or package::kNone for the root index. Throws
  // lodstream::Error for a node the package does not have. Cost: O(1) (package::IndexPageMap).
  uint32_t index_page_of(uint32_t id) const;

  // The next pages to transfer in benefit-per-byte order for `views` (their weights as given), never a held
  // page. `records` gives the node records the scheduler can see (all of them in a server; those arrived in
  // a pulling client); its available() is not used: availability is this scheduler's held set. Empty when
  // every view's ideal cut is held.
  std::vector<PageRef> next(const package::PackageScene& scene, const NodeSource& records,
                            std::span<const WeightedView> views, const ScheduleOptions& options) const;

  // The `sse-pull` baseline (DESIGN.md, Measuring quality; what Cesium and Nexus clients do): the pages of
  // the nodes that `view`'s ideal cut misses, in decreasing order of the projected error their arrival
  // removes (select_cut's `missing` order), the index page first where a record is unknown; no prediction, no
  // byte cost. Never a held page.
  std::vector<PageRef> next_sse(const package::PackageScene& scene, const NodeSource& records,
                                const View& view, const ScheduleOptions& options) const;

 private:
  const package::RootIndex* root_;
  package::IndexPageMap index_map_;
  std::vector<bool> data_held_, index_held_;
  std::vector<uint32_t> data_cost_;
};

}  // namespace lodstream::schedule
