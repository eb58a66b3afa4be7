#include <gtest/gtest.h>

#include "net/push_protocol.hpp"
#include "support/dag_package.hpp"

using namespace lodstream;
using schedule::PageKind;

namespace {

struct Fixture {
  test::DagPackage dag;
  std::shared_ptr<const PushPackage> package =
      std::make_shared<const PushPackage>("dag", std::make_shared<const package::PackageReader>(dag.reader));
  size_t total_pages = dag.reader.root().pages.size() + dag.reader.root().index_pages.size();
};

wire::Hello hello() {
  wire::Hello h;
  h.package = "dag";
  h.cache_budget_bytes = 64u << 20;
  h.viewport_width = 1280;
  h.viewport_height = 720;
  return h;
}

wire::ViewUpdate view(glm::vec3 eye, glm::vec3 forward) {
  wire::ViewUpdate v;
  v.eye = eye;
  v.forward = glm::normalize(forward);
  v.up = {0, 1, 0};
  v.viewport_width = 1280;
  v.viewport_height = 720;
  return v;
}

schedule::View view_of(const wire::ViewUpdate& v) {
  schedule::ViewSample s;
  s.eye = v.eye;
  s.forward = v.forward;
  s.up = v.up;
  s.fov_y_radians = v.fov_y_radians;
  return schedule::view_of(s);
}

// Takes what `p` sends from `t` on, acknowledging every 50 ms of virtual time, until a round sends nothing;
// what was sent, in order.
std::vector<PageToSend> drain_sent(PushProtocol& p, double& t) {
  std::vector<PageToSend> sent;
  for (int round = 0; round < 100; ++round) {
    uint32_t last = 0;
    while (auto page = p.next_page(t)) last = page->sequence, sent.push_back(*page);
    t += 0.05;
    if (!last) break;
    p.on_message(wire::Ack{last, 0, t, 0}, t);
  }
  return sent;
}

// The pages drain_sent sent, in order.
std::vector<schedule::PageRef> drain(PushProtocol& p, double& t) {
  std::vector<schedule::PageRef> pages;
  for (const PageToSend& s : drain_sent(p, t)) pages.push_back(s.page);
  return pages;
}

}  // namespace

TEST(PushProtocol, AHelloForThisPackageComesFirst) {
  Fixture f;
  {
    PushProtocol p(f.package);
    EXPECT_THROW(p.on_message(wire::Ack{1, 0, 0, 0}, 0.0), wire::WireError);
  }
  {
    PushProtocol p(f.package);
    wire::Hello h = hello();
    h.package = "other";
    EXPECT_THROW(p.on_message(h, 0.0), wire::WireError);
  }
  PushProtocol p(f.package);
  EXPECT_FALSE(p.next_page(0.0));  // nothing before the hello
  auto welcome = p.on_message(hello(), 0.0);
  ASSERT_TRUE(welcome && std::holds_alternative<wire::Welcome>(*welcome));
  EXPECT_EQ(std::get<wire::Welcome>(*welcome).package_hash, f.dag.reader.header().content_hash);
  EXPECT_THROW(p.on_message(hello(), 0.1), wire::WireError);                // a second hello
  EXPECT_THROW(p.on_message(wire::Welcome{}, 0.1), wire::WireError);        // a server's message
  EXPECT_THROW(p.on_message(wire::Ack{5, 0, 0, 0}, 0.1), wire::WireError);  // never sent
}

// On a virtual clock with a 50 ms round trip: the view's pages come first (records before the pages that need
// them, within the window, never a held page), the view's cut completes before the rest of the package is
// sent, and with the idle fill the rest follows until everything is sent once.
TEST(PushProtocol, PushesTheViewsCutFirstThenFillsWithinTheWindow) {
  Fixture f;
  PushProtocolOptions options;
  options.min_window_bytes = 4000;
  PushProtocol p(f.package, options);
  wire::Hello h = hello();
  h.cached_hash = f.dag.reader.header().content_hash;
  const uint32_t held_page = f.dag.page_of(f.dag.dag.roots[0]);
  h.held = {{held_page, 1}};
  p.on_message(h, 0.0);
  const wire::ViewUpdate v = view({2, 0, 3}, {0, 0, -1});
  p.on_message(v, 0.0);
  test::Held client(f.dag.all, p.scheduler());
  std::set<std::pair<int, uint32_t>> sent;
  double t = 0.0, converged_at_pages = -1;
  for (int round = 0; round < 200 && !p.everything_sent(); ++round) {
    uint32_t last = 0;
    while (auto page = p.next_page(t)) {
      EXPECT_TRUE(sent.insert({int(page->page.kind), page->page.id}).second) << "page sent twice";
      EXPECT_FALSE(page->page.kind == PageKind::data && page->page.id == held_page);
      EXPECT_LE(p.link().bytes_in_flight(), p.window_bytes() + 1000);
      if (page->page.kind == PageKind::data) {
        for (uint32_t n = 0; n < f.dag.all.size(); ++n) {
          if (f.dag.page_of(n) == page->page.id) {
            EXPECT_TRUE(p.scheduler().record_held(n)) << "node " << n;
          }
        }
      }
      last = page->sequence;
      if (converged_at_pages < 0 &&
          schedule::select_cut(f.dag.scene(), client, view_of(v), {1.0}).converged())
        converged_at_pages = double(sent.size());
    }
    t += 0.05;
    if (last) p.on_message(wire::Ack{last, 0, t, 0}, t);
  }
  EXPECT_TRUE(p.everything_sent());
  EXPECT_EQ(sent.size(), f.total_pages - 1);
  ASSERT_GT(converged_at_pages, 0);
  EXPECT_LT(converged_at_pages, double(f.total_pages - 1));
  EXPECT_DOUBLE_EQ(p.ack_deadline(), INFINITY);
}

TEST(PushProtocol, WithoutTheIdleFillANewViewRestartsSending) {
  Fixture f;
  PushProtocolOptions options;
  options.fill_when_idle = false;
  PushProtocol p(f.package, options);
  p.on_message(hello(), 0.0);
  EXPECT_FALSE(p.next_page(0.0));  // no view: nothing to send
  p.on_message(view({2, 0, 3}, {0, 0, -1}), 0.0);
  double t = 0.0;
  EXPECT_GT(drain(p, t).size(), 0u);
  EXPECT_FALSE(p.everything_sent());
  EXPECT_FALSE(p.next_page(t));
  p.on_message(view({14, 0, 3}, {0, 0, -1}), t);  // the other end of the DAG
  EXPECT_GT(drain(p, t).size(), 0u);
}

// Once everything the view needs is sent (no idle fill), acknowledgements and view updates with the same
// pose cost no plan; another pose does.
TEST(PushProtocol, AConvergedSessionPlansAgainOnlyForAnotherPose) {
  Fixture f;
  PushProtocolOptions options;
  options.fill_when_idle = false;
  PushProtocol p(f.package, options);
  p.on_message(hello(), 0.0);
  const wire::ViewUpdate still = view({2, 0, 3}, {0, 0, -1});
  p.on_message(still, 0.0);
  double t = 0.0;
  EXPECT_GT(drain(p, t).size(), 0u);
  const uint64_t plans = p.counters().plans;
  for (int i = 0; i < 20; ++i) {
    wire::ViewUpdate again = still;
    again.client_time_s = t;  // a newer sample of the same pose, past the replan interval
    p.on_message(again, t);
    EXPECT_FALSE(p.next_page(t));
    t += 0.2;
  }
  EXPECT_EQ(p.counters().plans, plans);
  p.on_message(view({14, 0, 3}, {0, 0, -1}), t);
  EXPECT_GT(drain(p, t).size(), 0u);
  EXPECT_GT(p.counters().plans, plans);
}

// The idle fill waits for the first view: a window filled in file order before it would hold back the
// view's pages by a round trip. The first page after the view is one its cut needs.
TEST(PushProtocol, NothingIsSentBeforeTheFirstView) {
  Fixture f;
  PushProtocol p(f.package, {});
  p.on_message(hello(), 0.0);
  EXPECT_FALSE(p.next_page(0.0));
  const wire::ViewUpdate v = view({2, 0, 3}, {0, 0, -1});
  p.on_message(v, 0.0);
  const auto first = p.next_page(0.0);
  ASSERT_TRUE(first);
  schedule::PageScheduler fresh(f.dag.reader.root());
  const schedule::WeightedView views[] = {{view_of(v), 1.0, 0.0}};
  const auto wanted = fresh.next(f.dag.scene(), f.dag.all, views, {1.0});
  EXPECT_NE(std::find(wanted.begin(), wanted.end(), first->page), wanted.end())
      << "page " << first->page.id << " is not one the view needs";
}

TEST(PushProtocol, AClientThatAcknowledgesNothingTimesOut) {
  Fixture f;
  PushProtocolOptions options;
  options.ack_timeout_s = 5.0;
  PushProtocol p(f.package, options);
  p.on_message(hello(), 0.0);
  p.on_message(view({2, 0, 3}, {0, 0, -1}), 1.0);
  ASSERT_TRUE(p.next_page(1.0));
  EXPECT_DOUBLE_EQ(p.ack_deadline(), 6.0);
  EXPECT_NO_THROW(p.check_timeout(5.9));
  EXPECT_THROW(p.check_timeout(6.1), wire::WireError);
}

// A data page the client's cache let go (a Released message) is sent again when the view needs it, and only
// it; releasing a page the package does not have is a protocol error.
TEST(PushProtocol, AReleasedPageIsSentAgainWhenTheViewNeedsIt) {
  Fixture f;
  PushProtocolOptions options;
  options.fill_when_idle = false;
  PushProtocol p(f.package, options);
  p.on_message(hello(), 0.0);
  p.on_message(view({2, 0, 3}, {0, 0, -1}), 0.0);
  double t = 0.0;
  auto data = [&] {
    std::vector<uint32_t> ids;
    for (const schedule::PageRef& page : drain(p, t))
      if (page.kind == PageKind::data) ids.push_back(page.id);
    return ids;
  };
  const std::vector<uint32_t> first = data();
  ASSERT_GE(first.size(), 2u);
  const uint32_t released = first[first.size() / 2];
  p.on_message(wire::Released{{{released, 1}}}, t);
  EXPECT_TRUE(data().empty());  // held off (release_backoff.hpp)
  t += 0.3;
  EXPECT_EQ(data(), std::vector<uint32_t>{released});
  const auto pages = uint32_t(f.dag.reader.root().pages.size());
  EXPECT_THROW(p.on_message(wire::Released{{{pages - 1, 2}}}, t), wire::WireError);
}

// A page the client keeps on disk goes out as a Restore (no page bytes on the link), priced by the plan as
// the small message it is, so it never goes later than when it was bytes, and some go earlier (those not held
// back by their parents): one the Hello lists as on disk, and one released with on_disk when the view needs
// it again; a Restore the client could not load (a Released without on_disk) is followed at once by the
// page's bytes.
TEST(PushProtocol, APageTheClientKeepsOnDiskIsRestoredNotSentAgain) {
  Fixture f;
  PushProtocolOptions options;
  options.fill_when_idle = false;
  const wire::ViewUpdate v = view({2, 0, 3}, {0, 0, -1});
  // What is sent to a client whose disk keeps data page `on_disk` (none: -1).
  auto sent_with = [&](int64_t on_disk, std::unique_ptr<PushProtocol>& p, double& t) {
    p = std::make_unique<PushProtocol>(f.package, options);
    wire::Hello h = hello();
    h.cached_hash = f.dag.reader.header().content_hash;
    if (on_disk >= 0) h.on_disk = {{uint32_t(on_disk), 1}};
    p->on_message(h, 0.0);
    p->on_message(v, 0.0);
    t = 0.0;
    return drain_sent(*p, t);
  };
  auto position = [](const std::vector<PageToSend>& sent, uint32_t id) {
    return std::find_if(
               sent.begin(), sent.end(),
               [&](const PageToSend& s) { return s.page.kind == PageKind::data && s.page.id == id; }) -
           sent.begin();
  };
  std::unique_ptr<PushProtocol> client;
  double t = 0.0;
  const std::vector<PageToSend> baseline = sent_with(-1, client, t);
  std::vector<uint32_t> data;
  for (const PageToSend& s : baseline)
    if (s.page.kind == PageKind::data) data.push_back(s.page.id);
  ASSERT_GE(data.size(), 2u);
  size_t earlier = 0;
  for (uint32_t kept : data) {
    const std::vector<PageToSend> sent = sent_with(kept, client, t);
    ASSERT_EQ(sent.size(), baseline.size());  // the same pages, the one on disk as a Restore
    EXPECT_LE(position(sent, kept), position(baseline, kept)) << "page " << kept;
    earlier += position(sent, kept) < position(baseline, kept);
  }
  EXPECT_GT(earlier, 0u);

  const uint32_t kept = data.back();
  const std::vector<PageToSend> sent = sent_with(kept, client, t);
  PushProtocol& p = *client;
  uint64_t page_bytes = 0;
  for (const PageToSend& s : sent) {
    EXPECT_EQ(s.restore, s.page.kind == PageKind::data && s.page.id == kept) << s.page.id;
    if (!s.restore) page_bytes += s.page.bytes;
  }
  EXPECT_EQ(p.counters().restores, 1u);
  EXPECT_EQ(p.counters().bytes_sent, page_bytes);

  // Released and kept on disk: when it is due again, a Restore.
  const uint32_t other = data.front();
  p.on_message(wire::Released{{{other, 1}}, true}, t);
  t += 0.3;
  std::vector<PageToSend> again = drain_sent(p, t);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].page.id, other);
  EXPECT_TRUE(again[0].restore);
  // The client could not load it: the bytes follow without a hold-off.
  p.on_message(wire::Released{{{other, 1}}, false}, t);
  again = drain_sent(p, t);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].page.id, other);
  EXPECT_FALSE(again[0].restore);
  EXPECT_EQ(p.counters().restores, 2u);
}

// A client whose cache is smaller than the view's cut needs is sent a coarser cut that its cache affords,
// not pages it would have to evict.
TEST(PushProtocol, ASmallCacheIsSentTheCutItAffords) {
  Fixture f;
  PushProtocolOptions options;
  options.fill_when_idle = false;
  auto sent_for = [&](uint64_t budget) {
    PushProtocol p(f.package, options);
    wire::Hello h = hello();
    h.cache_budget_bytes = budget;
    p.on_message(h, 0.0);
    p.on_message(view({2, 0, 1}, {0, 0, -1}), 0.0);
    double t = 0.0;
    uint64_t raw = 0;
    for (const schedule::PageRef& page : drain(p, t))
      if (page.kind == PageKind::data) raw += f.dag.reader.root().pages[page.id].raw_size;
    return raw;
  };
  uint64_t package_raw = 0;
  for (const auto& page : f.dag.reader.root().pages) package_raw += page.raw_size;
  const uint64_t large = sent_for(package_raw), small = sent_for(package_raw / 4);
  EXPECT_GT(small, 0u);
  EXPECT_LT(small, large);
  EXPECT_LE(small, package_raw / 4);
}
