#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <map>
#include <memory>
#include <set>
#include <thread>

#include "net/http_server.hpp"
#include "net/push_client.hpp"
#include "net/wire.hpp"
#include "package/reader.hpp"
#include "raw_package.hpp"
#include "support/run.hpp"

using namespace lodstream;
namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

namespace {

// A synchronous WebSocket client speaking the push protocol.
class RawPushClient {
 public:
  RawPushClient(uint16_t port, const std::string& target) : ws_(io_) {
    tcp::resolver resolver(io_);
    asio::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.binary(true);
    ws_.handshake("127.0.0.1:" + std::to_string(port), target);
  }
  void send(const wire::Message& m) { send_raw(wire::encode(m)); }
  void send_raw(const std::vector<uint8_t>& frame) { ws_.write(asio::buffer(frame)); }
  wire::Message receive() {
    beast::flat_buffer buffer;
    ws_.read(buffer);
    auto data = static_cast<const uint8_t*>(buffer.data().data());
    return wire::decode(std::span<const uint8_t>(data, buffer.size()));
  }
  // Receives pages until `count` data pages have arrived, acknowledging each page (index pages too); returns
  // the data pages by page id.
  std::map<uint32_t, std::vector<uint8_t>> receive_pages(size_t count) {
    std::map<uint32_t, std::vector<uint8_t>> pages;
    for (size_t i = 0; pages.size() < count; ++i) {
      wire::Message m = receive();
      auto* page = std::get_if<wire::Page>(&m);
      if (!page) {
        ADD_FAILURE() << "expected a page, got " << wire::type_name(m);
        break;
      }
      received_ += page->bytes.size();
      if (page->kind == wire::PageKind::index) {
        EXPECT_TRUE(index_pages_.insert(page->page_id).second) << "index page " << page->page_id << " twice";
      } else {
        EXPECT_TRUE(pages.emplace(page->page_id, page->bytes).second) << "page " << page->page_id << " twice";
      }
      send(wire::Ack{page->sequence, received_, 0.001 * double(i), page->server_time_s});
    }
    return pages;
  }
  void close() { ws_.close(beast::websocket::close_code::normal); }

 private:
  asio::io_context io_;
  beast::websocket::stream<tcp::socket> ws_;
  uint64_t received_ = 0;
  std::set<uint32_t> index_pages_;
};

struct PushServer {
  std::filesystem::path file = test::temp_dir() / "scene.lods";
  package::WrittenPackage written = test::write_raw_package(file, 60, 3);
  std::shared_ptr<const package::PackageReader> reader =
      std::make_shared<const package::PackageReader>(package::PackageReader::open(file));
  HttpServer server{"127.0.0.1", 0,
                    std::vector<ServedFile>{{"scene.lods", file, written.content_hash.hex(), reader}}};

  // Page `p`'s bytes as stored in the file.
  std::vector<uint8_t> stored(uint32_t p) const {
    const auto& range = reader->root().pages.at(p);
    std::vector<uint8_t> bytes(range.size);
    reader->source().read(range.offset, bytes);
    return bytes;
  }
};

wire::Hello hello(const std::string& name) {
  wire::Hello h;
  h.package = name;
  h.cache_budget_bytes = 64u << 20;
  h.triangles_per_frame = 1000000;
  h.viewport_width = 640;
  h.viewport_height = 480;
  return h;
}

// A view update (the server sends nothing before the first one): the idle fill then sends the rest.
wire::ViewUpdate a_view() {
  wire::ViewUpdate v;
  v.eye = {0.0f, 0.0f, 5.0f};
  v.forward = {0.0f, 0.0f, -1.0f};
  v.up = {0.0f, 1.0f, 0.0f};
  v.fov_y_radians = 1.0f;
  v.viewport_width = 640;
  v.viewport_height = 480;
  return v;
}

TEST(PushSession, SendsEveryPageOnceWithTheStoredBytes) {
  PushServer s;
  const uint32_t page_count = uint32_t(s.reader->root().pages.size());
  ASSERT_GT(page_count, 5u);
  RawPushClient client(s.server.port(), "/scene");
  client.send(hello("scene"));
  client.send(a_view());
  wire::Message m = client.receive();
  auto* welcome = std::get_if<wire::Welcome>(&m);
  ASSERT_NE(welcome, nullptr) << wire::type_name(m);
  EXPECT_EQ(welcome->package_hash, s.written.content_hash);
  EXPECT_EQ(welcome->page_count, page_count);
  EXPECT_EQ(welcome->package_bytes, s.written.bytes);
  auto pages = client.receive_pages(page_count);
  ASSERT_EQ(pages.size(), page_count);
  for (const auto& [id, bytes] : pages) EXPECT_EQ(bytes, s.stored(id)) << "page " << id;
  client.close();
}

TEST(PushSession, NeverSendsWhatTheClientHolds) {
  PushServer s;
  const uint32_t page_count = uint32_t(s.reader->root().pages.size());
  RawPushClient client(s.server.port(), "/scene");
  wire::Hello h = hello("scene");
  h.cached_hash = s.written.content_hash;
  h.held = {{0, 2}, {4, 1}};  // pages 0, 1 and 4
  client.send(h);
  client.send(a_view());
  ASSERT_TRUE(std::holds_alternative<wire::Welcome>(client.receive()));
  auto pages = client.receive_pages(page_count - 3);
  EXPECT_EQ(pages.count(0) + pages.count(1) + pages.count(4), 0u);
  EXPECT_EQ(pages.size(), page_count - 3);
  client.close();
}

TEST(PushSession, HeldPagesOfAnotherPackageVersionAreIgnored) {
  PushServer s;
  const uint32_t page_count = uint32_t(s.reader->root().pages.size());
  RawPushClient client(s.server.port(), "/scene");
  wire::Hello h = hello("scene");
  h.cached_hash = {1, 2};  // not this package
  h.held = {{0, page_count}};
  client.send(h);
  client.send(a_view());
  ASSERT_TRUE(std::holds_alternative<wire::Welcome>(client.receive()));
  EXPECT_EQ(client.receive_pages(page_count).size(), page_count);
  client.close();
}

TEST(PushSession, AMalformedMessageEndsOnlyThatSession) {
  PushServer s;
  const uint32_t page_count = uint32_t(s.reader->root().pages.size());
  RawPushClient good(s.server.port(), "/scene");
  good.send(hello("scene"));
  good.send(a_view());
  ASSERT_TRUE(std::holds_alternative<wire::Welcome>(good.receive()));
  auto first = good.receive_pages(2);

  RawPushClient bad(s.server.port(), "/scene");
  bad.send_raw(
      {wire::kProtocolVersion, 0, 99, 0, 0, 0, 0, 0});  // this version, unknown type 99, empty payload
  wire::Message m = bad.receive();
  auto* bye = std::get_if<wire::Bye>(&m);
  ASSERT_NE(bye, nullptr) << wire::type_name(m);
  EXPECT_NE(bye->reason.find("type"), std::string::npos) << bye->reason;

  // The first client goes on to receive everything.
  auto rest = good.receive_pages(page_count - 2);
  for (const auto& [id, bytes] : first) EXPECT_EQ(rest.count(id), 0u);
  EXPECT_EQ(first.size() + rest.size(), page_count);
  good.close();
}

TEST(PushSession, AHelloForAnotherPackageOrNoHelloEndsTheSession) {
  PushServer s;
  {
    RawPushClient client(s.server.port(), "/scene");
    client.send(hello("other"));
    wire::Message m = client.receive();
    ASSERT_TRUE(std::holds_alternative<wire::Bye>(m)) << wire::type_name(m);
    EXPECT_NE(std::get<wire::Bye>(m).reason.find("other"), std::string::npos);
  }
  {
    RawPushClient client(s.server.port(), "/scene");
    client.send(wire::Ack{1, 0, 0.0, 0.0});
    wire::Message m = client.receive();
    ASSERT_TRUE(std::holds_alternative<wire::Bye>(m)) << wire::type_name(m);
    EXPECT_NE(std::get<wire::Bye>(m).reason.find("hello"), std::string::npos);
  }
}

TEST(PushSession, NoStreamAtAnUnknownAddress) {
  PushServer s;
  EXPECT_THROW(RawPushClient(s.server.port(), "/nothing"), boost::system::system_error);
}

}  // namespace

// A client opened before its Hello is known (view --cache-dir must read the root index first) connects at
// once but says nothing until say_hello(); then it is welcomed and streamed to like any other, and one that
// never says hello closes without hanging.
TEST(PushSession, AClientOpenedBeforeItsHelloWaitsForIt) {
  PushServer s;
  const std::string url = "ws://127.0.0.1:" + std::to_string(s.server.port()) + "/scene";
  {
    PageInbox silent;
    lodstream::PushClient never(url, silent);
  }
  PageInbox inbox;
  lodstream::PushClient client(url, inbox);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(client.welcomed());
  EXPECT_TRUE(inbox.take().empty());
  EXPECT_EQ(inbox.error(), "");

  client.say_hello(hello("scene"));
  client.send_view(a_view());
  const size_t page_count = s.reader->root().pages.size();
  std::set<uint32_t> data_pages;
  for (int i = 0; i < 500 && data_pages.size() < page_count && inbox.error().empty(); ++i) {
    for (const ArrivedPage& a : inbox.take())
      if (a.page.kind == schedule::PageKind::data) {
        EXPECT_EQ(a.bytes, s.stored(a.page.id)) << "page " << a.page.id;
        data_pages.insert(a.page.id);
      }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(inbox.error(), "");
  EXPECT_TRUE(client.welcomed());
  EXPECT_EQ(data_pages.size(), page_count);
}
