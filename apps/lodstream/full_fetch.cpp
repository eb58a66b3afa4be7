#include "full_fetch.hpp"

#include "finest_cut.hpp"
#include "runtime/quality.hpp"

namespace lodstream::cli {

void FullFetch::request(runtime::ClientPackage& client, PullFetcher& fetcher) {
  const package::RootIndex& root = client.reader().root();
  auto ask = [&](schedule::PageKind kind, uint32_t id, const package::Range& range) {
    const schedule::PageRef page{kind, id, uint32_t(range.size)};
    client.requested(page);
    fetcher.request(page, range);
  };
  if (stage_ == Stage::start) {
    for (uint32_t id = 0; id < root.index_pages.size(); ++id)
      ask(schedule::PageKind::index, id, root.index_pages[id].range);
    stage_ = Stage::index_pages;
  }
  if (stage_ == Stage::index_pages && client.in_flight() == 0) {
    finest_ = finest_nodes(client.scene(), client.nodes(), root.node_count);
    for (uint32_t id : finest_pages(client.nodes(), finest_))
      ask(schedule::PageKind::data, id, root.pages[id]);
    stage_ = Stage::finest_pages;
  }
  if (stage_ == Stage::finest_pages && client.in_flight() == 0) stage_ = Stage::arrived;
}

runtime::Frame FullFetch::frame(runtime::ClientPackage& client, const schedule::View& view,
                                double tau) const {
  runtime::Frame f;
  const package::PackageScene& scene = client.scene();
  if (stage_ == Stage::arrived) {
    f.cut = finest_cut(scene, client.nodes(), finest_, view);
  } else {
    for (uint32_t o = 0; o < scene.objects.size(); ++o)
      f.cut.objects.push_back(schedule::in_frustum(schedule::object_sphere(scene, o), view)
                                  ? schedule::ObjectState::incomplete
                                  : schedule::ObjectState::culled);
    // Not converged until everything arrived: the finest cut is missing (one placeholder stands for it).
    f.cut.missing.push_back({});
  }
  f.cut.tau = tau;
  f.quality = runtime::frame_quality(scene, client.nodes(), f.cut, view, tau);
  return f;
}

}  // namespace lodstream::cli
