#include "net/push_client.hpp"

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <set>

#include "net/url.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
using asio::awaitable;
using asio::use_awaitable;
using tcp = asio::ip::tcp;
using WebSocket = beast::websocket::stream<beast::tcp_stream>;

struct PushClient::Impl {
  asio::io_context io;
  asio::strand<asio::io_context::executor_type> strand = asio::make_strand(io);
  asio::steady_timer wake{strand};
  asio::steady_timer stop_timer{strand};  // cuts off a close the server does not answer
  asio::steady_timer backoff{strand};     // the wait before a reconnection
  asio::steady_timer hello_wait{strand};  // a connection opened before the Hello is known waits on it
  UrlParts url;
  wire::Hello hello;
  bool has_hello = false;  // owned by the strand
  PageInbox* inbox = nullptr;
  PushClient* owner = nullptr;
  PushReconnect reconnect;
  // Owned by the strand:
  std::optional<wire::ViewUpdate> view;
  std::optional<wire::Ack> ack;
  // Data pages evicted and not yet said (over the current connection), by whether the disk keeps them.
  std::set<uint32_t> release, release_kept;
  bool open = false, closing = false, done = false;
  bool welcomed_now = false;      // the current connection was welcomed
  uint64_t connection = 0;        // the current connection's number; a writer of an older one stops
  uint64_t received = 0;          // page bytes over the current connection
  std::set<uint32_t> arrived[2];  // pages received over any connection and not evicted since, by kind
  std::set<uint32_t> evicted;     // data pages evicted since the start and not received again
  std::set<uint32_t> on_disk;     // data pages not held in memory that the disk cache keeps
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

  // Data page `id` is held again (its bytes or a Restore arrived): nothing to say about it any more.
  void held_again(uint32_t id) {
    evicted.erase(id), release.erase(id), release_kept.erase(id), on_disk.erase(id);
  }

  double now() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  static awaitable<void> send(WebSocket& ws, const wire::Message& m) {
    const std::vector<uint8_t> frame = wire::encode(m);
    co_await ws.async_write(asio::buffer(frame), use_awaitable);
  }

  // The Hello of a (re)connection: the pages held when the client started plus every page received since,
  // minus the data pages evicted since (`evicted`).
  wire::Hello current_hello() const {
    wire::Hello h = hello;
    auto held = [&](const std::vector<wire::PageRun>& runs, const std::set<uint32_t>& more,
                    const std::set<uint32_t>& gone) {
      std::set<uint32_t> pages = more;
      for (const wire::PageRun& run : runs)
        for (uint64_t p = run.first; p < uint64_t(run.first) + run.count; ++p)
          if (!gone.count(uint32_t(p))) pages.insert(uint32_t(p));
      const std::vector<uint32_t> sorted(pages.begin(), pages.end());
      return wire::page_runs(sorted);
    };
    h.held = held(hello.held, arrived[size_t(schedule::PageKind::data)], evicted);
    h.held_index = held(hello.held_index, arrived[size_t(schedule::PageKind::index)], {});
    const std::vector<uint32_t> kept(on_disk.begin(), on_disk.end());
    h.on_disk = wire::page_runs(kept);
    return h;
  }

  // Sends acknowledgements, views and the close of connection `number` over `ws` until it ends.
  awaitable<void> writer(std::shared_ptr<WebSocket> ws, uint64_t number) {
    try {
      while (open && connection == number) {
        if (ack) {
          const wire::Message m = *std::exchange(ack, std::nullopt);
          co_await send(*ws, m);
        } else if (view) {
          const wire::Message m = *std::exchange(view, std::nullopt);
          co_await send(*ws, m);
        } else if (!release.empty() || !release_kept.empty()) {
          const bool kept = release.empty();
          std::set<uint32_t>& said = kept ? release_kept : release;
          const std::vector<uint32_t> pages(said.begin(), said.end());
          said.clear();
          // Named, not a temporary in the co_await (GCC 12 destroys such temporaries twice).
          const wire::Message m = wire::Released{wire::page_runs(pages), kept};
          co_await send(*ws, m);
        } else if (closing) {
          open = false;
          co_await ws->async_close(beast::websocket::close_code::normal, use_awaitable);
        } else {
          wake.expires_at(std::chrono::steady_clock::time_point::max());
          boost::system::error_code ec;
          co_await wake.async_wait(asio::redirect_error(use_awaitable, ec));
        }
      }
    } catch (const boost::system::system_error&) {
      // the reader reports the connection's end
    }
  }

  // One connection: hello, then pages until it ends. Returns why it was lost ("" when it ended for good:
  // closed by this client, or a failure already reported through the inbox).
  awaitable<std::string> connect() {
    auto ws = std::make_shared<WebSocket>(strand);
    const uint64_t number = ++connection;
    ack.reset();
    release.clear(), release_kept.clear();  // the new Hello says them
    received = 0;
    welcomed_now = false;
    std::string lost;
    try {
      tcp::resolver resolver(strand);
      auto endpoints = co_await resolver.async_resolve(url.host, url.port, use_awaitable);
      beast::get_lowest_layer(*ws).expires_after(std::chrono::seconds(30));
      co_await beast::get_lowest_layer(*ws).async_connect(endpoints, use_awaitable);
      beast::get_lowest_layer(*ws).socket().set_option(tcp::no_delay(true));
      beast::get_lowest_layer(*ws).expires_never();
      ws->set_option(beast::websocket::stream_base::timeout::suggested(beast::role_type::client));
      ws->binary(true);
      ws->read_message_max(wire::kMaxMessageBytes);
      co_await ws->async_handshake(url.host + ":" + url.port, url.target, use_awaitable);
      while (!has_hello && !closing) {
        hello_wait.expires_at(std::chrono::steady_clock::time_point::max());
        boost::system::error_code ec;
        co_await hello_wait.async_wait(asio::redirect_error(use_awaitable, ec));
      }
      if (closing) {
        co_await ws->async_close(beast::websocket::close_code::normal, use_awaitable);
        co_return lost;
      }
      open = true;
      co_await send(*ws, current_hello());
      asio::co_spawn(strand, writer(ws, number), asio::detached);
      for (;;) {
        beast::flat_buffer buffer;
        co_await ws->async_read(buffer, use_awaitable);
        const auto* data = static_cast<const uint8_t*>(buffer.data().data());
        wire::Message m = wire::decode(std::span<const uint8_t>(data, buffer.size()));
        if (auto* page = std::get_if<wire::Page>(&m)) {
          received += page->bytes.size();
          ack = wire::Ack{page->sequence, received, now(), page->server_time_s};
          if (page->kind == schedule::PageKind::data) held_again(page->page_id);
          arrived[size_t(page->kind)].insert(page->page_id);
          inbox->put({{page->kind, page->page_id, uint32_t(page->bytes.size())}, std::move(page->bytes)});
          ++owner->pages_;
          wake.cancel();
        } else if (auto* restore = std::get_if<wire::Restore>(&m)) {
          ack = wire::Ack{restore->sequence, received, now(), restore->server_time_s};
          held_again(restore->page_id);
          arrived[size_t(schedule::PageKind::data)].insert(restore->page_id);
          inbox->put({{schedule::PageKind::data, restore->page_id, 0}, {}, true});
          wake.cancel();
        } else if (auto* welcome = std::get_if<wire::Welcome>(&m)) {
          if (welcome->package_hash != hello.cached_hash) {  // what the client held is of another package
            hello.cached_hash = welcome->package_hash;
            hello.held.clear(), hello.held_index.clear();
            arrived[0].clear(), arrived[1].clear(), evicted.clear(), release.clear(), release_kept.clear();
            on_disk.clear();
          }
          if (owner->welcomed_) ++owner->reconnects_;
          owner->welcomed_ = true;
          welcomed_now = true;
        } else if (auto* bye = std::get_if<wire::Bye>(&m)) {
          inbox->fail(url.host + ":" + url.port + url.target + ": the server said bye: " + bye->reason);
          break;
        } else {
          throw wire::WireError(std::string("wire: unexpected ") + wire::type_name(m) + " from the server");
        }
      }
    } catch (const wire::WireError& e) {
      inbox->fail(e.what());
    } catch (const boost::system::system_error& e) {
      if (!closing) lost = "ws://" + url.host + ":" + url.port + url.target + ": " + e.code().message();
    }
    open = false;
    wake.cancel();
    co_return lost;
  }

  // Connections until the client closes: a lost one is opened again after a back-off that doubles from
  // reconnect.first_backoff_s to reconnect.max_backoff_s (reset by each Welcome), as long as the first one
  // was welcomed; a first connection that fails is an error.
  awaitable<void> session() {
    double wait_s = reconnect.first_backoff_s;
    for (;;) {
      const std::string lost = co_await connect();
      if (lost.empty() || closing) break;
      if (!owner->welcomed_ || !reconnect.enabled) {
        inbox->fail(lost);
        break;
      }
      if (welcomed_now) wait_s = reconnect.first_backoff_s;
      backoff.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(wait_s)));
      boost::system::error_code ec;
      co_await backoff.async_wait(asio::redirect_error(use_awaitable, ec));
      if (closing) break;
      wait_s = std::min(2.0 * wait_s, reconnect.max_backoff_s);
    }
    done = true;
    wake.cancel();
    stop_timer.cancel();
  }
};

PushClient::PushClient(const std::string& url, wire::Hello hello, PageInbox& inbox, PushReconnect reconnect)
    : PushClient(url, inbox, reconnect) {
  say_hello(std::move(hello));
}

PushClient::PushClient(const std::string& url, PageInbox& inbox, PushReconnect reconnect)
    : impl_(std::make_unique<Impl>()) {
  impl_->url = split_url(url, "ws://");
  impl_->inbox = &inbox;
  impl_->owner = this;
  impl_->reconnect = reconnect;
  asio::co_spawn(impl_->strand, impl_->session(), asio::detached);
  thread_ = std::thread([this] { impl_->io.run(); });
}

PushClient::~PushClient() {
  asio::post(impl_->strand, [m = impl_.get()] {
    m->closing = true;
    m->wake.cancel();
    m->backoff.cancel();
    m->hello_wait.cancel();
    if (m->done) return;
    // A normal close takes a round trip; a server that does not answer is cut off.
    m->stop_timer.expires_after(std::chrono::seconds(2));
    m->stop_timer.async_wait([m](boost::system::error_code ec) {
      if (!ec) m->io.stop();
    });
  });
  thread_.join();
}

void PushClient::say_hello(wire::Hello hello) {
  asio::post(impl_->strand, [m = impl_.get(), hello = std::move(hello)]() mutable {
    for (const wire::PageRun& run : hello.on_disk)
      for (uint64_t p = run.first; p < uint64_t(run.first) + run.count; ++p) m->on_disk.insert(uint32_t(p));
    m->hello = std::move(hello);
    m->has_hello = true;
    m->hello_wait.cancel();
  });
}

void PushClient::send_view(const wire::ViewUpdate& view) {
  asio::post(impl_->strand, [m = impl_.get(), view] {
    m->view = view;
    m->wake.cancel();
  });
}

void PushClient::released(std::span<const uint32_t> pages, bool on_disk) {
  if (pages.empty()) return;
  asio::post(impl_->strand,
             [m = impl_.get(), on_disk, pages = std::vector<uint32_t>(pages.begin(), pages.end())] {
               for (uint32_t p : pages) {
                 m->arrived[size_t(schedule::PageKind::data)].erase(p);
                 m->evicted.insert(p);
                 m->release.erase(p), m->release_kept.erase(p);
                 if (on_disk)
                   m->on_disk.insert(p);
                 else
                   m->on_disk.erase(p);
                 if (m->open) (on_disk ? m->release_kept : m->release).insert(p);
               }
               m->wake.cancel();
             });
}

}  // namespace lodstream
