#include "net/push_session.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <vector>

#include "net/wire.hpp"
#include "schedule/link_estimator.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
using asio::awaitable;
using asio::use_awaitable;
using Clock = std::chrono::steady_clock;

namespace {

// State shared by the session's writer (this coroutine) and its reader (a second coroutine on the same
// strand).
struct Shared {
  explicit Shared(const asio::any_io_executor& ex) : wake(ex), reader_done(ex) {}
  schedule::LinkEstimator estimator;
  asio::steady_timer wake;         // cancelled when an acknowledgement arrives or the reader stops
  asio::steady_timer reader_done;  // cancelled when the reader coroutine has returned
  bool reader_running = true;
  std::string reader_error;     // why the reader stopped ("" : the client closed)
  bool protocol_error = false;  // the session ends for a reason the client should be told (a Bye)
  uint32_t acked = 0;
  PushStats stats;
  Clock::time_point start = Clock::now();
  double now() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
};

std::vector<uint8_t> to_vector(const beast::flat_buffer& b) {
  auto data = static_cast<const uint8_t*>(b.data().data());
  return {data, data + b.size()};
}

// GCC 12 destroys some temporaries of a full-expression that contains co_await twice, so every message is
// encoded into a named frame first and no co_await expression here creates an object with a destructor.
awaitable<void> write_frame(WebSocket& ws, const std::vector<uint8_t>& frame) {
  co_await ws.async_write(asio::buffer(frame), use_awaitable);
}

awaitable<void> read_loop(WebSocket& ws, std::shared_ptr<Shared> s) {
  try {
    for (;;) {
      beast::flat_buffer buffer;
      co_await ws.async_read(buffer, use_awaitable);
      wire::Message m = wire::decode(to_vector(buffer));
      if (auto* ack = std::get_if<wire::Ack>(&m)) {
        s->estimator.on_ack(ack->last_sequence, s->now());
        s->acked = std::max(s->acked, ack->last_sequence);
        ++s->stats.acks;
        s->wake.cancel();
      } else if (std::holds_alternative<wire::ViewUpdate>(m)) {
        ++s->stats.views;
      } else if (auto* bye = std::get_if<wire::Bye>(&m)) {
        s->reader_error = "client said bye: " + bye->reason;
        break;
      } else {
        throw wire::WireError(std::string("wire: unexpected ") + wire::type_name(m) +
                              " message from a client");
      }
    }
  } catch (const wire::WireError& e) {
    s->reader_error = e.what();
    s->protocol_error = true;
  } catch (const boost::system::system_error& e) {
    if (e.code() != beast::websocket::error::closed) s->reader_error = e.code().message();
  }
  s->reader_running = false;
  s->wake.cancel();
  s->reader_done.cancel();
}

}  // namespace

awaitable<PushStats> run_push_session(WebSocket& ws, const std::string& name,
                                      const package::PackageReader& package, PushOptions options) {
  auto ex = co_await asio::this_coro::executor;
  auto s = std::make_shared<Shared>(ex);
  ws.binary(true);
  ws.read_message_max(wire::kMaxMessageBytes);
  ws.set_option(beast::websocket::stream_base::timeout::suggested(beast::role_type::server));
  // Keep the kernel's unsent queue short so that what waits to be sent waits here, where it can be
  // re-ordered.
  int lowat = options.notsent_lowat_bytes;
  setsockopt(beast::get_lowest_layer(ws).socket().native_handle(), IPPROTO_TCP, TCP_NOTSENT_LOWAT, &lowat,
             sizeof lowat);
  bool reader_started = false;
  try {
    beast::flat_buffer buffer;
    co_await ws.async_read(buffer, use_awaitable);
    wire::Message first = wire::decode(to_vector(buffer));
    auto* hello = std::get_if<wire::Hello>(&first);
    if (!hello)
      throw wire::WireError(std::string("wire: expected hello first, got ") + wire::type_name(first));
    if (hello->package != name)
      throw wire::WireError("wire: hello names package '" + hello->package + "' on the stream of '" + name +
                            "'");
    const auto& pages = package.root().pages;
    const auto hash = package.header().content_hash;
    std::vector<bool> held(pages.size(), false);
    if (hello->cached_hash == hash)
      for (const auto& run : hello->held)
        for (uint64_t p = run.first; p < uint64_t(run.first) + run.count && p < pages.size(); ++p)
          held[p] = true;
    const auto welcome = wire::encode(wire::Welcome{hash, package.source().size(), uint32_t(pages.size())});
    co_await write_frame(ws, welcome);

    asio::co_spawn(ex, read_loop(ws, s), asio::detached);
    reader_started = true;
    uint32_t sequence = 0;
    std::vector<uint8_t> bytes;
    for (uint32_t page = 0; page < pages.size() && s->reader_running; ++page) {
      if (held[page]) continue;
      // Wait while the window is full; a client that acknowledges nothing for ack_timeout_s is dropped.
      while (s->reader_running &&
             double(s->estimator.bytes_in_flight()) >=
                 std::max(2.0 * s->estimator.bdp_bytes(), double(options.min_window_bytes))) {
        uint32_t acked_before = s->acked;
        s->wake.expires_after(std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(options.ack_timeout_s)));
        boost::system::error_code ec;
        co_await s->wake.async_wait(asio::redirect_error(use_awaitable, ec));
        if (!ec && s->acked == acked_before)
          throw wire::WireError("the client acknowledged nothing for " +
                                std::to_string(options.ack_timeout_s) + " s");
      }
      if (!s->reader_running) break;
      bytes.resize(pages[page].size);
      package.source().read(pages[page].offset, bytes);
      ++sequence;
      s->estimator.on_send(sequence, bytes.size(), s->now());
      const auto frame = wire::encode(wire::Page{sequence, page, s->now(), bytes});
      co_await write_frame(ws, frame);
      ++s->stats.pages_sent;
      s->stats.bytes_sent += bytes.size();
    }
    // Everything is sent: the session stays open (the client keeps sending views) until the client closes.
    if (s->reader_running) {
      s->reader_done.expires_at(Clock::time_point::max());
      boost::system::error_code ec;
      co_await s->reader_done.async_wait(asio::redirect_error(use_awaitable, ec));
    }
    s->stats.end_reason = s->reader_error.empty() ? "closed by client" : s->reader_error;
    if (!s->reader_running && !s->reader_error.empty()) s->stats.end_reason = s->reader_error;
  } catch (const wire::WireError& e) {
    s->stats.end_reason = e.what();
    s->protocol_error = true;
  } catch (const Error& e) {  // the package could not be read
    s->stats.end_reason = e.what();
  } catch (const boost::system::system_error& e) {
    s->stats.end_reason = e.code().message();
  }
  if (s->protocol_error) {
    // Tell the client why, then close; errors here only mean the client is already gone.
    try {
      const auto bye = wire::encode(wire::Bye{s->stats.end_reason.substr(0, 1000)});
      co_await write_frame(ws, bye);
      co_await ws.async_close(beast::websocket::close_code::policy_error, use_awaitable);
    } catch (const boost::system::system_error&) {
    }
  }
  boost::system::error_code ec;
  beast::get_lowest_layer(ws).socket().close(ec);
  if (reader_started && s->reader_running) {
    s->reader_done.expires_at(Clock::time_point::max());
    co_await s->reader_done.async_wait(asio::redirect_error(use_awaitable, ec));
  }
  co_return s->stats;
}

}  // namespace lodstream
