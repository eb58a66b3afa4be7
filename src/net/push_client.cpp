#include "net/push_client.hpp"

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>

#include "net/url.hpp"

namespace lodstream {

namespace asio = boost::asio;
namespace beast = boost::beast;
using asio::awaitable;
using asio::use_awaitable;
using tcp = asio::ip::tcp;

struct PushClient::Impl {
  asio::io_context io;
  beast::websocket::stream<beast::tcp_stream> ws{asio::make_strand(io)};
  asio::steady_timer wake{ws.get_executor()};
  asio::steady_timer stop_timer{ws.get_executor()};  // cuts off a close the server does not answer
  UrlParts url;
  wire::Hello hello;
  PageInbox* inbox = nullptr;
  PushClient* owner = nullptr;
  // Owned by the strand:
  std::optional<wire::ViewUpdate> view;
  std::optional<wire::Ack> ack;
  bool open = false, closing = false, done = false;
  uint64_t received = 0;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

  double now() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  awaitable<void> send(const wire::Message& m) {
    const std::vector<uint8_t> frame = wire::encode(m);
    co_await ws.async_write(asio::buffer(frame), use_awaitable);
  }

  awaitable<void> writer() {
    try {
      while (open) {
        if (ack) {
          const wire::Message m = *std::exchange(ack, std::nullopt);
          co_await send(m);
        } else if (view) {
          const wire::Message m = *std::exchange(view, std::nullopt);
          co_await send(m);
        } else if (closing) {
          open = false;
          co_await ws.async_close(beast::websocket::close_code::normal, use_awaitable);
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

  awaitable<void> session() {
    try {
      tcp::resolver resolver(ws.get_executor());
      auto endpoints = co_await resolver.async_resolve(url.host, url.port, use_awaitable);
      beast::get_lowest_layer(ws).expires_after(std::chrono::seconds(30));
      co_await beast::get_lowest_layer(ws).async_connect(endpoints, use_awaitable);
      beast::get_lowest_layer(ws).socket().set_option(tcp::no_delay(true));
      beast::get_lowest_layer(ws).expires_never();
      ws.set_option(beast::websocket::stream_base::timeout::suggested(beast::role_type::client));
      ws.binary(true);
      ws.read_message_max(wire::kMaxMessageBytes);
      co_await ws.async_handshake(url.host + ":" + url.port, url.target, use_awaitable);
      open = true;
      const wire::Message first = hello;
      co_await send(first);
      asio::co_spawn(ws.get_executor(), writer(), asio::detached);
      for (;;) {
        beast::flat_buffer buffer;
        co_await ws.async_read(buffer, use_awaitable);
        const auto* data = static_cast<const uint8_t*>(buffer.data().data());
        wire::Message m = wire::decode(std::span<const uint8_t>(data, buffer.size()));
        if (auto* page = std::get_if<wire::Page>(&m)) {
          received += page->bytes.size();
          ack = wire::Ack{page->sequence, received, now(), page->server_time_s};
          inbox->put({{page->kind, page->page_id, uint32_t(page->bytes.size())}, std::move(page->bytes)});
          ++owner->pages_;
          wake.cancel();
        } else if (std::holds_alternative<wire::Welcome>(m)) {
          owner->welcomed_ = true;
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
      if (!closing) inbox->fail("ws://" + url.host + ":" + url.port + url.target + ": " + e.code().message());
    }
    open = false;
    done = true;
    wake.cancel();
    stop_timer.cancel();
  }
};

PushClient::PushClient(const std::string& url, wire::Hello hello, PageInbox& inbox)
    : impl_(std::make_unique<Impl>()) {
  impl_->url = split_url(url, "ws://");
  impl_->hello = std::move(hello);
  impl_->inbox = &inbox;
  impl_->owner = this;
  asio::co_spawn(impl_->ws.get_executor(), impl_->session(), asio::detached);
  thread_ = std::thread([this] { impl_->io.run(); });
}

PushClient::~PushClient() {
  asio::post(impl_->ws.get_executor(), [m = impl_.get()] {
    m->closing = true;
    m->wake.cancel();
    if (m->done) return;
    // A normal close takes a round trip; a server that does not answer is cut off.
    m->stop_timer.expires_after(std::chrono::seconds(2));
    m->stop_timer.async_wait([m](boost::system::error_code ec) {
      if (!ec) m->io.stop();
    });
  });
  thread_.join();
}

void PushClient::send_view(const wire::ViewUpdate& view) {
  asio::post(impl_->ws.get_executor(), [m = impl_.get(), view] {
    m->view = view;
    m->wake.cancel();
  });
}

}  // namespace lodstream
