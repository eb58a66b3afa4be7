#include "net/push_session.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <vector>

#include "net/wire.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
using asio::awaitable;
using asio::use_awaitable;
using Clock = std::chrono::steady_clock;

namespace {

// State shared by the session's writer (run_push_session) and its reader (a second coroutine on the same
// strand).
struct Shared {
  Shared(const asio::any_io_executor& ex, std::shared_ptr<const PushPackage> package,
         const PushProtocolOptions& options)
      : protocol(std::move(package), options), wake(ex), reader_done(ex) {}
  PushProtocol protocol;
  asio::steady_timer wake;         // cancelled when a message arrives or the reader stops
  asio::steady_timer reader_done;  // cancelled when the reader coroutine has returned
  bool reader_running = true;
  std::string reader_error;     // why the reader stopped ("" : the client closed)
  bool protocol_error = false;  // the session ends for a reason the client should be told (a Bye)
  Clock::time_point start = Clock::now();
  double now() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
};

std::vector<uint8_t> to_vector(const beast::flat_buffer& b) {
  auto data = static_cast<const uint8_t*>(b.data().data());
  return {data, data + b.size()};
}

awaitable<wire::Message> receive(WebSocket& ws) {
  beast::flat_buffer buffer;
  co_await ws.async_read(buffer, use_awaitable);
  co_return wire::decode(to_vector(buffer));
}

awaitable<void> send(WebSocket& ws, const wire::Message& m) {
  auto frame = wire::encode(m);
  co_await ws.async_write(asio::buffer(frame), use_awaitable);
}

awaitable<void> read_loop(WebSocket& ws, std::shared_ptr<Shared> s) {
  try {
    while (!s->protocol.ended()) {
      wire::Message m = co_await receive(ws);
      s->protocol.on_message(m, s->now());
      s->wake.cancel();
    }
    s->reader_error = "client said bye";
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

// Waits until the reader wakes the writer or `deadline_s` (session time; +inf: no deadline) passes.
awaitable<void> wait(Shared& s, double deadline_s) {
  if (std::isinf(deadline_s))
    s.wake.expires_at(Clock::time_point::max());
  else
    s.wake.expires_at(s.start + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(deadline_s + 1e-3)));
  boost::system::error_code ec;
  co_await s.wake.async_wait(asio::redirect_error(use_awaitable, ec));
}

}  // namespace

awaitable<PushStats> run_push_session(WebSocket& ws, std::shared_ptr<const PushPackage> package,
                                      PushOptions options) {
  auto ex = co_await asio::this_coro::executor;
  const package::PackageReader& reader = *package->reader;
  auto s = std::make_shared<Shared>(ex, package, options.protocol);
  ws.binary(true);
  ws.read_message_max(wire::kMaxMessageBytes);
  ws.set_option(beast::websocket::stream_base::timeout::suggested(beast::role_type::server));
  // Keep the kernel's unsent queue short so that what waits to be sent waits in the protocol, where it can be
  // re-ordered.
  int lowat = options.notsent_lowat_bytes;
  setsockopt(beast::get_lowest_layer(ws).socket().native_handle(), IPPROTO_TCP, TCP_NOTSENT_LOWAT, &lowat,
             sizeof lowat);
  bool reader_started = false;
  PushStats stats;
  try {
    wire::Message first = co_await receive(ws);
    const std::optional<wire::Message> welcome = s->protocol.on_message(first, s->now());
    if (welcome) co_await send(ws, *welcome);
    asio::co_spawn(ex, read_loop(ws, s), asio::detached);
    reader_started = true;
    std::vector<uint8_t> bytes;
    while (s->reader_running) {
      while (s->reader_running) {
        auto next = s->protocol.next_page(s->now());
        if (!next) break;
        if (next->restore) {  // the client loads it from its disk
          const wire::Message restore = wire::Restore{next->sequence, next->page.id, next->server_time_s};
          co_await send(ws, restore);
          continue;
        }
        const auto& root = reader.root();
        const package::Range& range = next->page.kind == schedule::PageKind::data
                                          ? root.pages[next->page.id]
                                          : root.index_pages[next->page.id].range;
        bytes.resize(range.size);
        reader.source().read(range.offset, bytes);
        // A named message, not a temporary in the co_await expression (GCC 12 destroys those twice).
        const wire::Message page =
            wire::Page{next->sequence, next->page.id, next->server_time_s, bytes, next->page.kind};
        co_await send(ws, page);
      }
      if (!s->reader_running) break;
      // Nothing to send now: wait for an acknowledgement, a view or the acknowledgement deadline.
      co_await wait(*s, s->protocol.ack_deadline());
      s->protocol.check_timeout(s->now());
    }
    stats.end_reason = s->reader_error.empty() ? "closed by client" : s->reader_error;
  } catch (const wire::WireError& e) {
    stats.end_reason = e.what();
    s->protocol_error = true;
  } catch (const Error& e) {  // the package could not be read
    stats.end_reason = e.what();
  } catch (const boost::system::system_error& e) {
    stats.end_reason = e.code().message();
  }
  if (s->protocol_error) {
    // Tell the client why, then close; errors here only mean the client is already gone.
    try {
      const wire::Message bye = wire::Bye{stats.end_reason.substr(0, 1000)};
      co_await send(ws, bye);
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
  stats.counters = s->protocol.counters();
  co_return stats;
}

}  // namespace lodstream
