#include "net/wire.hpp"

#include <cmath>
#include <cstring>

namespace lodstream::wire {

namespace {

enum class Type : uint16_t {
  kHello = 1,
  kView = 2,
  kAck = 3,
  kWelcome = 4,
  kPage = 5,
  kBye = 6,
  kReleased = 7,
  kRestore = 8
};

class Writer {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));  // x86-64 and ARM64 are little-endian, as the wire is
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }
  void put(const glm::vec3& v) { put(v.x), put(v.y), put(v.z); }
  void put_bytes(std::span<const uint8_t> b) {
    put(uint32_t(b.size()));
    bytes.insert(bytes.end(), b.begin(), b.end());
  }
  void put_string(const std::string& s) { put_bytes({reinterpret_cast<const uint8_t*>(s.data()), s.size()}); }
  std::vector<uint8_t> bytes;
};

class Reader {
 public:
  Reader(std::span<const uint8_t> data, const char* type) : data_(data), type_(type) {}
  template <typename T>
  T get(const char* field) {
    need(sizeof(T), field);
    T value;
    std::memcpy(&value, data_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    if constexpr (std::is_floating_point_v<T>)
      if (!std::isfinite(value)) fail(field, "is not a finite number");
    return value;
  }
  glm::vec3 vec3(const char* field) { return {get<float>(field), get<float>(field), get<float>(field)}; }
  std::span<const uint8_t> bytes(const char* field, size_t max) {
    uint32_t n = get<uint32_t>(field);
    if (n > max) fail(field, "is longer than " + std::to_string(max) + " bytes");
    need(n, field);
    auto out = data_.subspan(at_, n);
    at_ += n;
    return out;
  }
  std::string string(const char* field, size_t max) {
    auto b = bytes(field, max);
    return {b.begin(), b.end()};
  }
  size_t remaining() const { return data_.size() - at_; }
  void done() {
    if (at_ != data_.size()) fail("payload", "has " + std::to_string(data_.size() - at_) + " trailing bytes");
  }
  [[noreturn]] void fail(const char* field, const std::string& what) {
    throw WireError(std::string("wire: ") + type_ + " message: " + field + " " + what);
  }

 private:
  void need(size_t n, const char* field) {
    if (n > data_.size() - at_) fail(field, "is cut off (message truncated)");
  }
  std::span<const uint8_t> data_;
  size_t at_ = 0;
  const char* type_;
};

glm::vec3 unit(Reader& r, const char* field) {
  glm::vec3 v = r.vec3(field);
  if (std::abs(glm::length(v) - 1.0f) > 1e-3f) r.fail(field, "is not a unit vector");
  return v;
}

void put_runs(Writer& w, const std::vector<PageRun>& runs) {
  w.put(uint32_t(runs.size()));
  for (const auto& run : runs) w.put(run.first), w.put(run.count);
}

// Page runs; `field` names them in errors ("held runs", "released runs").
std::vector<PageRun> get_runs(Reader& r, const char* field) {
  uint32_t count = r.get<uint32_t>(field);
  if (count > r.remaining() / 8) r.fail(field, "count is larger than the message");
  std::vector<PageRun> runs(count);
  uint64_t end = 0;
  for (auto& run : runs) {
    run.first = r.get<uint32_t>(field);
    run.count = r.get<uint32_t>(field);
    if (run.count == 0 || run.first < end || uint64_t(run.first) + run.count > UINT32_MAX)
      r.fail(field, "must be non-empty, sorted and non-overlapping");
    end = uint64_t(run.first) + run.count;
  }
  return runs;
}

void encode_payload(Writer& w, const Hello& m) {
  w.put_string(m.package);
  w.put(m.cached_hash.low), w.put(m.cached_hash.high);
  put_runs(w, m.held);
  put_runs(w, m.held_index);
  put_runs(w, m.on_disk);
  w.put(m.cache_budget_bytes), w.put(m.triangles_per_frame), w.put(m.viewport_width),
      w.put(m.viewport_height);
}
void encode_payload(Writer& w, const ViewUpdate& m) {
  w.put(m.client_time_s), w.put(m.eye), w.put(m.forward), w.put(m.up), w.put(m.velocity),
      w.put(m.angular_velocity);
  w.put(m.fov_y_radians), w.put(m.viewport_width), w.put(m.viewport_height);
}
void encode_payload(Writer& w, const Ack& m) {
  w.put(m.last_sequence), w.put(m.bytes_received), w.put(m.client_time_s), w.put(m.echo_server_time_s);
}
void encode_payload(Writer& w, const Welcome& m) {
  w.put(m.package_hash.low), w.put(m.package_hash.high);
  w.put(m.package_bytes), w.put(m.page_count);
}
void encode_payload(Writer& w, const Page& m) {
  w.put(m.sequence), w.put(m.page_id), w.put(uint8_t(m.kind)), w.put(m.server_time_s);
  w.put_bytes(m.bytes);
}
void encode_payload(Writer& w, const Bye& m) {
  w.put_string(m.reason);
}
void encode_payload(Writer& w, const Released& m) {
  put_runs(w, m.pages);
  w.put(uint8_t(m.on_disk));
}
void encode_payload(Writer& w, const Restore& m) {
  w.put(m.sequence), w.put(m.page_id), w.put(m.server_time_s);
}

constexpr Type type_of(const Message& m) {
  return Type(uint16_t(m.index() + 1));
}

ContentHash hash(Reader& r, const char* field) {
  ContentHash h;
  h.low = r.get<uint64_t>(field);
  h.high = r.get<uint64_t>(field);
  return h;
}

void viewport(Reader& r, uint16_t& w, uint16_t& h) {
  w = r.get<uint16_t>("viewport width");
  h = r.get<uint16_t>("viewport height");
  if (w == 0 || h == 0 || w > 16384 || h > 16384) r.fail("viewport", "must be between 1x1 and 16384x16384");
}

}  // namespace

std::vector<PageRun> page_runs(std::span<const uint32_t> sorted_pages) {
  std::vector<PageRun> runs;
  for (uint32_t page : sorted_pages) {
    if (!runs.empty() && runs.back().first + runs.back().count == page)
      ++runs.back().count;
    else
      runs.push_back({page, 1});
  }
  return runs;
}

const char* type_name(const Message& message) {
  static const char* names[] = {"hello", "view", "ack", "welcome", "page", "bye", "released", "restore"};
  return names[message.index()];
}

std::vector<uint8_t> encode(const Message& message) {
  Writer w;
  w.put(kProtocolVersion);
  w.put(uint16_t(type_of(message)));
  w.put(uint32_t(0));
  std::visit([&w](const auto& m) { encode_payload(w, m); }, message);
  uint32_t payload = uint32_t(w.bytes.size() - kHeaderBytes);
  std::memcpy(w.bytes.data() + 4, &payload, 4);
  return std::move(w.bytes);
}

Message decode(std::span<const uint8_t> frame) {
  Reader header(frame, "any");
  if (frame.size() < kHeaderBytes)
    header.fail("header", "is cut off (" + std::to_string(frame.size()) + " bytes)");
  if (frame.size() > kMaxMessageBytes) header.fail("frame", "is larger than the 16 MiB limit");
  auto version = header.get<uint16_t>("version");
  if (version != kProtocolVersion)
    header.fail("version", std::to_string(version) + " is not supported (this is " +
                               std::to_string(kProtocolVersion) + ")");
  auto type = header.get<uint16_t>("type");
  auto payload = header.get<uint32_t>("length");
  if (payload != frame.size() - kHeaderBytes)
    header.fail("length", std::to_string(payload) + " does not match the " +
                              std::to_string(frame.size() - kHeaderBytes) + " payload bytes present");
  auto body = frame.subspan(kHeaderBytes);
  switch (Type(type)) {
    case Type::kHello: {
      Reader r(body, "hello");
      Hello m;
      m.package = r.string("package", kMaxNameBytes);
      if (m.package.empty()) r.fail("package", "is empty");
      m.cached_hash = hash(r, "cached hash");
      m.held = get_runs(r, "held runs");
      m.held_index = get_runs(r, "held index runs");
      m.on_disk = get_runs(r, "on-disk runs");
      m.cache_budget_bytes = r.get<uint64_t>("cache budget");
      m.triangles_per_frame = r.get<uint32_t>("triangles per frame");
      viewport(r, m.viewport_width, m.viewport_height);
      r.done();
      return m;
    }
    case Type::kView: {
      Reader r(body, "view");
      ViewUpdate m;
      m.client_time_s = r.get<double>("time");
      m.eye = r.vec3("eye");
      m.forward = unit(r, "forward");
      m.up = unit(r, "up");
      m.velocity = r.vec3("velocity");
      m.angular_velocity = r.vec3("angular velocity");
      m.fov_y_radians = r.get<float>("fov");
      if (!(m.fov_y_radians > 0.0f && m.fov_y_radians < 3.14159f))
        r.fail("fov", "must be in (0, pi) radians");
      viewport(r, m.viewport_width, m.viewport_height);
      r.done();
      return m;
    }
    case Type::kAck: {
      Reader r(body, "ack");
      Ack m{r.get<uint32_t>("sequence"), r.get<uint64_t>("bytes received"), r.get<double>("client time"),
            r.get<double>("echoed server time")};
      r.done();
      return m;
    }
    case Type::kWelcome: {
      Reader r(body, "welcome");
      Welcome m;
      m.package_hash = hash(r, "package hash");
      m.package_bytes = r.get<uint64_t>("package bytes");
      m.page_count = r.get<uint32_t>("page count");
      r.done();
      return m;
    }
    case Type::kPage: {
      Reader r(body, "page");
      Page m;
      m.sequence = r.get<uint32_t>("sequence");
      m.page_id = r.get<uint32_t>("page id");
      const uint8_t kind = r.get<uint8_t>("page kind");
      if (kind > uint8_t(PageKind::index)) r.fail("page kind", std::to_string(kind) + " is unknown");
      m.kind = PageKind(kind);
      m.server_time_s = r.get<double>("server time");
      auto bytes = r.bytes("bytes", kMaxMessageBytes);
      m.bytes.assign(bytes.begin(), bytes.end());
      r.done();
      return m;
    }
    case Type::kBye: {
      Reader r(body, "bye");
      Bye m{r.string("reason", 1024)};
      r.done();
      return m;
    }
    case Type::kReleased: {
      Reader r(body, "released");
      Released m{get_runs(r, "released runs")};
      if (m.pages.empty()) r.fail("released runs", "are empty");
      const uint8_t on_disk = r.get<uint8_t>("on-disk flag");
      if (on_disk > 1) r.fail("on-disk flag", std::to_string(on_disk) + " is neither 0 nor 1");
      m.on_disk = on_disk == 1;
      r.done();
      return m;
    }
    case Type::kRestore: {
      Reader r(body, "restore");
      Restore m;
      m.sequence = r.get<uint32_t>("sequence");
      m.page_id = r.get<uint32_t>("page id");
      m.server_time_s = r.get<double>("server time");
      r.done();
      return m;
    }
  }
  header.fail("type", std::to_string(type) + " is unknown");
}

}  // namespace lodstream::wire
