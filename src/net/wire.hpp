// The push protocol's messages (DESIGN.md, Serving and the wire). Every message is one WebSocket binary
// frame: an 8-byte header {u16 protocol version, u16 type, u32 payload bytes} then the payload,
// little-endian, with no padding. Decoding validates every length and count against the bytes actually
// present and against fixed limits (a hostile peer cannot make the decoder allocate more than the message
// holds); any violation is a WireError naming the message type and field. Encoding and decoding are O(message
// size).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "package/format.hpp"
#include "schedule/page_scheduler.hpp"

namespace lodstream::wire {

// 2: pages carry their kind (data or index page), hello lists held index pages too.
// 3: the client says which data pages its cache let go (Released).
// 4: a client with a disk cache says which pages it keeps there (Hello's on_disk, Released's on_disk), and
//    the server tells it to load such a page from its disk (Restore) instead of sending the bytes again.
constexpr uint16_t kProtocolVersion = 4;
constexpr size_t kHeaderBytes = 8;
constexpr size_t kMaxMessageBytes = 16u << 20;  // larger frames are refused before they are read
constexpr size_t kMaxNameBytes = 256;

class WireError : public Error {
 public:
  using Error::Error;
};

using ContentHash = package::ContentHash;
using PageKind = schedule::PageKind;  // the package content hash; all zero: none

// Page ids as sorted, non-overlapping half-open runs [first, first + count): what a client holds.
struct PageRun {
  uint32_t first = 0;
  uint32_t count = 0;
};

// `sorted_pages` (ascending, no repeats) as runs. Cost: O(pages).
std::vector<PageRun> page_runs(std::span<const uint32_t> sorted_pages);

// Client → server, first message: which package, what the client holds, what it can do.
struct Hello {
  std::string package;        // NAME, as in ws://HOST:PORT/NAME
  ContentHash cached_hash{};  // content hash of the package the held pages came from (zero: nothing cached)
  std::vector<PageRun> held;  // data pages the client already holds (ignored when the hash differs)
  std::vector<PageRun> held_index;  // index pages it holds (likewise)
  // Data pages it does not hold in memory but keeps on disk, whole and checked (likewise): the server sends
  // a Restore for them instead of their bytes.
  std::vector<PageRun> on_disk;
  uint64_t cache_budget_bytes = 0;
  uint32_t triangles_per_frame = 0;
  uint16_t viewport_width = 0, viewport_height = 0;
};

// Client → server: the current view and its motion, for the scheduler's prediction.
struct ViewUpdate {
  double client_time_s = 0;  // the client's clock when the pose was taken
  glm::vec3 eye{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit view direction
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  glm::vec3 velocity{0.0f};          // of the eye, units per second
  glm::vec3 angular_velocity{0.0f};  // radians per second, axis × rate, world space
  float fov_y_radians = 1.0472f;
  uint16_t viewport_width = 0, viewport_height = 0;
};

// Client → server: every page up to `last_sequence` arrived; `client_time_s` and `echo_server_time_s` (the
// send time stamped on that page) let the server measure the round-trip time and the delivered bandwidth.
struct Ack {
  uint32_t last_sequence = 0;
  uint64_t bytes_received = 0;
  double client_time_s = 0;
  double echo_server_time_s = 0;
};

// Server → client, answer to Hello: the package the session streams.
struct Welcome {
  ContentHash package_hash{};
  uint64_t package_bytes = 0;
  uint32_t page_count = 0;
};

// Server → client: one page's bytes, exactly as stored in the package at its offset: a data page
// (root().pages[page_id]) or an index page of node records (root().index_pages[page_id]).
struct Page {
  uint32_t sequence = 0;  // 1, 2, 3… within the session
  uint32_t page_id = 0;
  double server_time_s = 0;
  std::vector<uint8_t> bytes;
  PageKind kind = PageKind::data;
};

// Either direction: the session ends, with the reason.
struct Bye {
  std::string reason;
};

// Client → server: data pages the client's cache evicted. It no longer holds them, so the server may send
// them again when a view needs them (without this, a client whose cache is smaller than what its path
// needs would never get an evicted page back).
// With `on_disk`, the client still keeps them on disk (its --cache-dir): the server may send a Restore for
// one instead of its bytes. Without it, they are gone, also from disk (a Restore of one failed).
struct Released {
  std::vector<PageRun> pages;
  bool on_disk = false;
};

// Server → client: load data page `page_id` from your disk cache (a page you said you keep there); it counts
// as sent with `sequence`, and is acknowledged like a Page. When the page cannot be loaded, the client says
// so with a Released without on_disk, and the server sends the bytes.
struct Restore {
  uint32_t sequence = 0;
  uint32_t page_id = 0;
  double server_time_s = 0;
};

using Message = std::variant<Hello, ViewUpdate, Ack, Welcome, Page, Bye, Released, Restore>;

std::vector<uint8_t> encode(const Message& message);

// Decodes one whole frame. Throws WireError on a wrong version, unknown type, wrong length, a field out of
// range (non-finite numbers, zero-length vectors, unsorted or overlapping runs, over-long strings) or
// trailing bytes.
Message decode(std::span<const uint8_t> frame);

// The name of a message's type, for logs and errors ("hello", "view", …).
const char* type_name(const Message& message);

}  // namespace lodstream::wire
