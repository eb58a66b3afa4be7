// Where a client's transport (pull_fetcher.hpp, push_client.hpp) leaves what arrived, for the frame loop to
// take at its next frame: so that streaming never blocks a frame (DESIGN.md, Client runtime). Thread-safe;
// each call holds a mutex for O(1) (put) or O(arrived) (take). A listener (optional) is called after every
// put and fail, on the transport's thread, without the mutex held: a consumer on a thread of its own waits
// for it instead of polling.
#pragma once

#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "schedule/page_scheduler.hpp"

namespace lodstream {

struct ArrivedPage {
  schedule::PageRef page;
  std::vector<uint8_t> bytes;  // as stored in the package
  bool from_disk = false;      // a push server's Restore: no bytes, load the page from the disk cache
};

class PageInbox {
 public:
  PageInbox() = default;
  // `listener` must not call back into this inbox's put() or fail(), and must outlive the transport.
  explicit PageInbox(std::function<void()> listener) : listener_(std::move(listener)) {}

  void put(ArrivedPage page) {
    {
      std::lock_guard lock(mutex_);
      pages_.push_back(std::move(page));
    }
    if (listener_) listener_();
  }
  // The transport failed (for good): the reason, once; later failures are dropped.
  void fail(const std::string& reason) {
    {
      std::lock_guard lock(mutex_);
      if (error_.empty()) error_ = reason;
    }
    if (listener_) listener_();
  }
  std::vector<ArrivedPage> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(pages_, {});
  }
  std::string error() const {
    std::lock_guard lock(mutex_);
    return error_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<ArrivedPage> pages_;
  std::string error_;
  const std::function<void()> listener_;
};

}  // namespace lodstream
