// Little-endian byte serialization for the .lods format: ByteWriter appends, ByteReader reads with a bounds
// check on every access. A ByteReader never trusts a count: `count()` rejects any count whose records could
// not fit in the bytes that remain, so a lying count can never cause a large allocation. Every failure is a
// one-line lodstream::Error naming the context (file and part) and the byte offset.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lodstream::package {

// Unaligned little-endian (the byte order of every supported target) store and load of a trivially copyable
// value in a byte record (vertex records of the node codecs).
template <typename T>
void store_raw(uint8_t* dst, T v) {
  std::memcpy(dst, &v, sizeof v);
}
template <typename T>
T load_raw(const uint8_t* src) {
  T v;
  std::memcpy(&v, src, sizeof v);
  return v;
}

class ByteWriter {
 public:
  std::vector<uint8_t> bytes;

  void u8(uint8_t v) { bytes.push_back(v); }
  void u16(uint16_t v);
  void u32(uint32_t v);
  void u64(uint64_t v);
  void f32(float v);
  // LEB128: 7 bits a byte, low group first.
  void varint(uint64_t v);
  // Zigzag-mapped signed LEB128 (small magnitudes of either sign take few bytes).
  void svarint(int64_t v) { varint((static_cast<uint64_t>(v) << 1) ^ static_cast<uint64_t>(v >> 63)); }
  void string(std::string_view s);
  void raw(std::span<const uint8_t> b) { bytes.insert(bytes.end(), b.begin(), b.end()); }
};

class ByteReader {
 public:
  // `context` names the file and part for error messages (it must outlive the reader); `base` is the position
  // of data[0] in that part.
  ByteReader(std::span<const uint8_t> data, std::string_view context, uint64_t base = 0);

  uint8_t u8();
  uint16_t u16();
  uint32_t u32();
  uint64_t u64();
  float f32();
  // A float that must be finite (positions, errors, transforms): NaN and infinities are rejected.
  float finite_f32(const char* what);
  uint64_t varint();
  int64_t svarint();
  // A varint that must be < limit (an index into a table of `limit` entries).
  uint32_t index(uint64_t limit, const char* what);
  // A varint count of records that take at least `min_record_bytes` each: rejected when they cannot fit in
  // the bytes that remain or exceed `limit`.
  size_t count(size_t min_record_bytes, const char* what, uint64_t limit = UINT32_MAX);
  std::string string(const char* what);
  std::span<const uint8_t> bytes(size_t n, const char* what);

  size_t position() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }
  bool at_end() const { return pos_ == data_.size(); }
  // Throws unless every byte was consumed (trailing garbage is corruption too).
  void expect_end();
  [[noreturn]] void fail(const std::string& what) const;

 private:
  const uint8_t* take(size_t n, const char* what);
  // varint() a byte at a time, each checked: the error of a truncated or overlong varint.
  [[gnu::noinline, gnu::cold]] uint64_t varint_checked();

  std::span<const uint8_t> data_;
  std::string_view context_;
  uint64_t base_;
  size_t pos_ = 0;
};

}  // namespace lodstream::package
