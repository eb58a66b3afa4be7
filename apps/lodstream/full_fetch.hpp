// `lodstream view --order full`: DESIGN.md's `full` policy (what a plain glTF viewer does) on the real
// transport. The client first fetches every index page (it must learn which data pages hold the finest level,
// as a viewer reads a file's index), then every data page holding a finest-level node, in file order, all
// requested at once; it draws nothing until all of them have arrived, then the finest cut (finest_cut.hpp).
// Pure computation over the client's state; the pull fetcher carries the requests.
#pragma once

#include "net/pull_fetcher.hpp"
#include "runtime/client_package.hpp"

namespace lodstream::cli {

class FullFetch {
 public:
  // Requests what is due: every index page on the first call; once they have all arrived, every finest page.
  // Cost: the first and the second stage each pass over the package's records once.
  void request(runtime::ClientPackage& client, PullFetcher& fetcher);
  // The frame for `view`: nothing drawn (objects in the frustum incomplete, the rest culled) until every
  // finest page has arrived, then the finest cut; with its quality for `tau`.
  runtime::Frame frame(runtime::ClientPackage& client, const schedule::View& view, double tau) const;

 private:
  enum class Stage { start, index_pages, finest_pages, arrived } stage_ = Stage::start;
  std::vector<std::vector<uint32_t>> finest_;  // per representation, once the index pages have arrived
};

}  // namespace lodstream::cli
