#include "net/link_proxy.hpp"

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <deque>
#include <thread>

#include "core/error.hpp"

namespace lodstream {

namespace asio = boost::asio;
using asio::awaitable;
using asio::use_awaitable;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

constexpr size_t kPacket = 1460;  // bytes scheduled as one unit (an Ethernet TCP segment's payload)

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}
Clock::duration to_duration(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// One direction of one connection: reads from `from`, delays through `link` (that direction's bottleneck,
// shared by every connection through the proxy), writes to `to`.
class Pipe {
 public:
  Pipe(std::shared_ptr<tcp::socket> from, std::shared_ptr<tcp::socket> to,
       std::shared_ptr<LinkDirection> link, double buffer_s, Clock::time_point start)
      : from_(std::move(from)),
        to_(std::move(to)),
        link_(std::move(link)),
        start_(start),
        buffer_s_(buffer_s),
        wake_(from_->get_executor()) {}

  // Coroutines take the owning pointer as a parameter: it is copied into the frame before the first
  // suspension, which keeps the pipe alive for as long as either loop runs.
  static awaitable<void> read_loop(std::shared_ptr<Pipe> self) { return self->read(self); }
  static awaitable<void> write_loop(std::shared_ptr<Pipe> self) { return self->write(self); }

 private:
  awaitable<void> read(std::shared_ptr<Pipe>) {
    std::vector<uint8_t> buffer(16 * 1024);
    asio::steady_timer pause(from_->get_executor());
    try {
      for (;;) {
        // Backpressure: the bottleneck queue holds at most buffer_s_ of transmission time.
        double backlog = link_->busy_until() - seconds_since(start_);
        if (backlog > buffer_s_) {
          pause.expires_after(to_duration(backlog - buffer_s_));
          co_await pause.async_wait(use_awaitable);
        }
        size_t n = co_await from_->async_read_some(asio::buffer(buffer), use_awaitable);
        for (size_t off = 0; off < n; off += kPacket) {
          size_t len = std::min(kPacket, n - off);
          double at = link_->send(seconds_since(start_), len);
          queue_.push_back({at, std::vector<uint8_t>(buffer.begin() + off, buffer.begin() + off + len)});
        }
        wake_.cancel();
      }
    } catch (const boost::system::system_error&) {
      // End of stream or error: deliver what is queued, then pass the end on.
    }
    queue_.push_back({link_->send(seconds_since(start_), 0), {}});
    wake_.cancel();
  }

  awaitable<void> write(std::shared_ptr<Pipe>) {
    try {
      for (;;) {
        if (queue_.empty()) {
          wake_.expires_at(Clock::time_point::max());
          boost::system::error_code ec;
          co_await wake_.async_wait(asio::redirect_error(use_awaitable, ec));
          continue;
        }
        double wait = queue_.front().deliver_at - seconds_since(start_);
        if (wait > 0) {
          asio::steady_timer timer(to_->get_executor(), to_duration(wait));
          co_await timer.async_wait(use_awaitable);
        }
        // Write every packet that is due in one call.
        std::vector<uint8_t> out;
        bool end = false;
        double now = seconds_since(start_);
        while (!queue_.empty() && queue_.front().deliver_at <= now) {
          if (queue_.front().bytes.empty()) end = true;
          out.insert(out.end(), queue_.front().bytes.begin(), queue_.front().bytes.end());
          queue_.pop_front();
          if (end) break;
        }
        if (!out.empty()) co_await asio::async_write(*to_, asio::buffer(out), use_awaitable);
        if (end) {
          boost::system::error_code ec;
          to_->shutdown(tcp::socket::shutdown_send, ec);
          co_return;
        }
      }
    } catch (const boost::system::system_error&) {
      boost::system::error_code ec;
      from_->close(ec);
      to_->close(ec);
    }
  }

  struct Packet {
    double deliver_at;
    std::vector<uint8_t> bytes;  // empty: the end of the stream
  };
  std::shared_ptr<tcp::socket> from_, to_;
  std::shared_ptr<LinkDirection> link_;
  Clock::time_point start_;
  double buffer_s_;
  std::deque<Packet> queue_;
  asio::steady_timer wake_;
};

}  // namespace

struct LinkProxy::Impl {
  asio::io_context io;
  tcp::acceptor acceptor{io};
  tcp::endpoint to;
  LinkSettings settings;
  // One bottleneck each way, shared by every connection (as a client's access link is): a client with N
  // connections gets the link's bandwidth, not N times it. One thread runs every pipe: no locking.
  std::shared_ptr<LinkDirection> up, down;
  Clock::time_point start = Clock::now();
  std::thread thread;

  awaitable<void> accept_loop() {
    for (;;) {
      auto client = std::make_shared<tcp::socket>(co_await acceptor.async_accept(use_awaitable));
      asio::co_spawn(io, connect(std::move(client)), asio::detached);
    }
  }

  awaitable<void> connect(std::shared_ptr<tcp::socket> client) {
    auto server = std::make_shared<tcp::socket>(io);
    try {
      co_await server->async_connect(to, use_awaitable);
    } catch (const boost::system::system_error& e) {
      std::fprintf(stderr, "link: cannot connect to %s:%u: %s\n", to.address().to_string().c_str(), to.port(),
                   e.code().message().c_str());
      co_return;
    }
    client->set_option(tcp::no_delay(true));
    server->set_option(tcp::no_delay(true));
    const double buffer_s = std::max(settings.rtt_s, 0.02);
    start_pipe(std::make_shared<Pipe>(client, server, up, buffer_s, start));
    start_pipe(std::make_shared<Pipe>(server, client, down, buffer_s, start));
  }

  void start_pipe(const std::shared_ptr<Pipe>& pipe) {
    asio::co_spawn(io, Pipe::read_loop(pipe), asio::detached);
    asio::co_spawn(io, Pipe::write_loop(pipe), asio::detached);
  }
};

LinkProxy::LinkProxy(const std::string& listen_host, uint16_t listen_port, const std::string& to_host,
                     uint16_t to_port, const LinkSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  // Each direction gets its own jitter sequence, reproducible.
  LinkSettings down = settings;
  ++down.seed;
  impl_->up = std::make_shared<LinkDirection>(settings);
  impl_->down = std::make_shared<LinkDirection>(down);
  boost::system::error_code ec;
  auto listen_address = asio::ip::make_address(listen_host, ec);
  if (ec) throw Error("--listen: '" + listen_host + "' is not an IP address");
  auto to_address = asio::ip::make_address(to_host, ec);
  if (ec) throw Error("--to: '" + to_host + "' is not an IP address");
  impl_->to = tcp::endpoint(to_address, to_port);
  tcp::endpoint endpoint(listen_address, listen_port);
  impl_->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(endpoint, ec);
  if (!ec) impl_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw Error("--listen: cannot listen on " + listen_host + ":" + std::to_string(listen_port) + ": " +
                ec.message());
  asio::co_spawn(impl_->io, impl_->accept_loop(), asio::detached);
  impl_->thread = std::thread([this] { impl_->io.run(); });
}

LinkProxy::~LinkProxy() {
  impl_->io.stop();
  impl_->thread.join();
}

uint16_t LinkProxy::port() const {
  return impl_->acceptor.local_endpoint().port();
}

std::pair<std::string, uint16_t> parse_host_port(const std::string& text, const std::string& option) {
  size_t colon = text.rfind(':');
  if (colon != std::string::npos && colon > 0) {
    std::string host = text.substr(0, colon);
    if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
    unsigned port = 0;
    auto [ptr, ec] = std::from_chars(text.data() + colon + 1, text.data() + text.size(), port);
    if (ec == std::errc() && ptr == text.data() + text.size() && port <= 65535) return {host, uint16_t(port)};
  }
  throw Error(option + " must be HOST:PORT such as 127.0.0.1:8080 or [::1]:8080, got '" + text + "'");
}

}  // namespace lodstream
