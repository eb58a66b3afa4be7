#include <gtest/gtest.h>

#include <utility>  // Boost 1.74 awaitable.hpp uses std::exchange without including it

#include <boost/asio.hpp>
#include <chrono>
#include <thread>

#include "core/error.hpp"
#include "net/link_model.hpp"
#include "net/link_proxy.hpp"

using namespace lodstream;
namespace asio = boost::asio;
using asio::ip::tcp;

TEST(LinkModel, SerializesAtBandwidthThenDelaysHalfTheRtt) {
  LinkDirection link({8e6, 0.1, 0.0, 1});  // 1 MB/s, 50 ms one way
  EXPECT_DOUBLE_EQ(link.send(0.0, 1000), 0.001 + 0.05);
  // Sent at once: queued behind the first packet.
  EXPECT_DOUBLE_EQ(link.send(0.0, 1000), 0.002 + 0.05);
  // After the link went idle, no queueing.
  EXPECT_DOUBLE_EQ(link.send(1.0, 1000), 1.001 + 0.05);
  EXPECT_DOUBLE_EQ(link.busy_until(), 1.001);
}

TEST(LinkModel, JitterKeepsOrderAndStaysWithinBounds) {
  LinkDirection link({1e9, 0.1, 0.02, 7});
  double last = 0;
  for (int i = 0; i < 1000; ++i) {
    double t = double(i) * 0.001;
    double at = link.send(t, 100);
    EXPECT_GE(at, last);
    EXPECT_GE(at - t, 0.05 - 0.02);
    EXPECT_LE(at - t, 0.05 + 0.02 + 0.01);  // +0.01: reordering prevented by waiting for the previous packet
    last = at;
  }
}

TEST(LinkModel, ParsesUnitsAndRejectsGarbage) {
  EXPECT_DOUBLE_EQ(parse_bandwidth("10mbit", "--bandwidth"), 10e6);
  EXPECT_DOUBLE_EQ(parse_bandwidth("500kbit", "--bandwidth"), 500e3);
  EXPECT_DOUBLE_EQ(parse_bandwidth("1gbit", "--bandwidth"), 1e9);
  EXPECT_DOUBLE_EQ(parse_duration("80ms", "--rtt"), 0.08);
  EXPECT_DOUBLE_EQ(parse_duration("0.5s", "--rtt"), 0.5);
  EXPECT_DOUBLE_EQ(parse_duration("250us", "--rtt"), 250e-6);
  for (const char* bad : {"", "fast", "10 mbit", "-1mbit", "10mbps", "0"})
    EXPECT_THROW(parse_bandwidth(bad, "--bandwidth"), Error) << bad;
  for (const char* bad : {"", "80 ms", "-5ms", "2min", "100s"})
    EXPECT_THROW(parse_duration(bad, "--rtt"), Error) << bad;
  EXPECT_EQ(parse_host_port("[::1]:80", "--to"), std::make_pair(std::string("::1"), uint16_t(80)));
  EXPECT_THROW(parse_host_port("127.0.0.1", "--to"), Error);
  EXPECT_THROW(parse_host_port("127.0.0.1:70000", "--to"), Error);
}

namespace {
// A loopback server that echoes one byte for each byte and otherwise discards: enough to time a round trip
// and a bulk transfer through the proxy.
struct EchoServer {
  asio::io_context io;
  tcp::acceptor acceptor{io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0)};
  std::thread thread;
  size_t received = 0;
  EchoServer() {
    thread = std::thread([this] {
      tcp::socket s = acceptor.accept();
      std::vector<uint8_t> buf(65536);
      boost::system::error_code ec;
      for (;;) {
        size_t n = s.read_some(asio::buffer(buf), ec);
        if (ec) break;
        received += n;
        if (n == 1) asio::write(s, asio::buffer(buf, 1), ec);
      }
    });
  }
  ~EchoServer() { thread.join(); }
};

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

// The proxy can only be slower than the settings, never faster: the lower bounds are exact consequences of
// the model; the upper bounds are loose so a loaded machine does not fail the test (the benchmark measures
// precision).
TEST(LinkProxy, AddsTheRoundTripTimeAndLimitsThroughput) {
  EchoServer server;
  LinkProxy proxy("127.0.0.1", 0, "127.0.0.1", server.acceptor.local_endpoint().port(), {4e6, 0.06, 0.0, 1});
  asio::io_context io;
  tcp::socket s(io);
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), proxy.port()));
  s.set_option(tcp::no_delay(true));
  uint8_t byte = 42;
  auto t0 = std::chrono::steady_clock::now();
  asio::write(s, asio::buffer(&byte, 1));
  asio::read(s, asio::buffer(&byte, 1));
  double rtt = since(t0);
  EXPECT_GE(rtt, 0.06);
  EXPECT_LT(rtt, 0.06 + 0.2);
  EXPECT_EQ(byte, 42);

  // 200 KB at 4 Mbit/s take at least 0.4 s to cross plus half the RTT.
  std::vector<uint8_t> bulk(200000, 7);
  t0 = std::chrono::steady_clock::now();
  asio::write(s, asio::buffer(bulk));
  s.shutdown(tcp::socket::shutdown_send);
  boost::system::error_code ec;
  s.read_some(asio::buffer(&byte, 1), ec);  // returns at end of stream: the server closed after reading all
  double transfer = since(t0);
  EXPECT_EQ(ec, asio::error::eof);
  EXPECT_GE(transfer, 0.4 + 0.03);
  EXPECT_LT(transfer, 0.4 + 0.03 + 1.0);
  s.close();
  server.thread.join();
  server.thread = std::thread([] {});
  EXPECT_EQ(server.received, 1u + bulk.size());
}

// Two connections at once share the link's bandwidth (one bottleneck each way, as an access link): 2 x 200 KB
// at 4 Mbit/s take at least 0.8 s, where a link per connection would take 0.4 s.
TEST(LinkProxy, ParallelConnectionsShareTheBandwidth) {
  asio::io_context io;
  tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  // The server: reads each of two connections to its end, then closes it.
  std::thread server([&] {
    std::vector<std::thread> readers;
    for (int k = 0; k < 2; ++k)
      readers.emplace_back([s = std::make_shared<tcp::socket>(acceptor.accept())] {
        std::vector<uint8_t> buf(65536);
        boost::system::error_code ec;
        while (!ec) s->read_some(asio::buffer(buf), ec);
      });
    for (auto& r : readers) r.join();
  });
  LinkProxy proxy("127.0.0.1", 0, "127.0.0.1", acceptor.local_endpoint().port(), {4e6, 0.02, 0.0, 1});
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<double> done(2, 0.0);
  std::vector<std::thread> clients;
  for (int k = 0; k < 2; ++k)
    clients.emplace_back([&, k] {
      asio::io_context cio;
      tcp::socket s(cio);
      s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), proxy.port()));
      asio::write(s, asio::buffer(std::vector<uint8_t>(200000, 7)));
      s.shutdown(tcp::socket::shutdown_send);
      uint8_t byte = 0;
      boost::system::error_code ec;
      s.read_some(asio::buffer(&byte, 1), ec);  // end of stream: the server read everything
      done[k] = since(t0);
    });
  for (auto& c : clients) c.join();
  server.join();
  EXPECT_GE(std::max(done[0], done[1]), 0.8 + 0.01);
  EXPECT_LT(std::max(done[0], done[1]), 0.8 + 0.01 + 1.0);
}

TEST(LinkProxy, RejectsAnAddressItCannotBind) {
  asio::io_context io;
  tcp::acceptor taken(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  EXPECT_THROW(LinkProxy("127.0.0.1", taken.local_endpoint().port(), "127.0.0.1", 2, {}), Error);
  EXPECT_THROW(LinkProxy("not-an-ip", 0, "127.0.0.1", 2, {}), Error);
}
