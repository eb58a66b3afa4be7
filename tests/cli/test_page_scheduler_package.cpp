// The PageScheduler on a real baked package (refined_elephant): it reaches the ideal cut of a view with the
// records before the pages that need them, and with a moving camera the pages for where it will be arrive
// sooner than when it looks only at the current view.
#include <gtest/gtest.h>

#include "baked.hpp"
#include "package/reader.hpp"
#include "schedule/package_records.hpp"
#include "schedule/page_scheduler.hpp"
#include "support/dag_package.hpp"

using namespace lodstream;
using namespace lodstream::schedule;

namespace {

struct Everything : NodeSource {
  const NodeSource& all;
  explicit Everything(const NodeSource& a) : all(a) {}
  const package::NodeRecord* record(uint32_t id) const override { return all.record(id); }
  bool available(uint32_t) const override { return true; }
};

ViewSample sample(glm::dvec3 eye, glm::dvec3 velocity, double t) {
  ViewSample s;
  s.time_s = t;
  s.eye = eye + velocity * t;
  s.forward = {0, 0, -1};
  s.velocity = velocity;
  s.width = 640;
  s.height = 480;
  return s;
}

}  // namespace

TEST(PageSchedulerPackage, ReachesTheIdealCutOfARealPackage) {
  auto reader = package::PackageReader::open(test::elephant_package());
  PackageRecords all(reader);
  PageScheduler s(reader.root());
  test::Held held(all, s);
  const View view = view_of(sample({0.0, 0.1, 1.2}, {}, 0));
  const WeightedView views[] = {{view, 1.0, 0.0}};
  uint64_t bytes = 0;
  for (int round = 0; round < 1000; ++round) {
    auto pages = s.next(reader.scene(), all, views, {1.0, 64 * 1024, SIZE_MAX});
    if (pages.empty()) break;
    for (const PageRef& p : pages) {
      ASSERT_FALSE(s.held(p.kind, p.id));
      s.set_held(p.kind, p.id);
      bytes += p.bytes;
    }
  }
  const Cut cut = select_cut(reader.scene(), held, view, {1.0});
  const Cut ideal = select_cut(reader.scene(), Everything(all), view, {1.0});
  EXPECT_TRUE(cut.converged());
  ASSERT_EQ(cut.drawn.size(), ideal.drawn.size());
  for (size_t i = 0; i < cut.drawn.size(); ++i) EXPECT_EQ(cut.drawn[i].node, ideal.drawn[i].node);
  EXPECT_GT(bytes, 0u);
  EXPECT_LE(bytes, reader.source().size());
}

TEST(PageSchedulerPackage, WithAMovingCameraThePagesForWhereItWillBeArriveSooner) {
  // The camera passes close by the elephant's side (0.55 units from its centre) at 0.4 units per second;
  // the link delivers about one page (40 KB) per 0.1 s. The view it will have at t = 2 s is complete sooner
  // when the scheduler looks at the predicted views than when it looks only at the current one.
  auto reader = package::PackageReader::open(test::elephant_package());
  PackageRecords all(reader);
  const glm::dvec3 start{-0.6, 0.0, 0.55}, velocity{0.4, 0.0, 0.0};
  const View target = view_of(sample(start, velocity, 2.0));
  auto complete_at = [&](bool predict_path) {
    PageScheduler s(reader.root());
    test::Held held(all, s);
    for (int step = 0; step <= 40; ++step) {
      const double t = 0.1 * step;
      if (select_cut(reader.scene(), held, target, {1.0}).converged()) return t;
      const ViewSample now = sample(start, velocity, t);
      const std::vector<WeightedView> views =
          predict_path ? predicted_views(now, 0.0) : std::vector<WeightedView>{{view_of(now), 1.0, 0.0}};
      for (const PageRef& p : s.next(reader.scene(), all, views, {1.0, 40 * 1024, SIZE_MAX}))
        s.set_held(p.kind, p.id);
    }
    return double(INFINITY);
  };
  const double predicted = complete_at(true), current_only = complete_at(false);
  std::printf("view at t=2 s complete at %.1f s with prediction, %.1f s without\n", predicted, current_only);
  EXPECT_LT(predicted, current_only);
}
