#include "package/bytes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.hpp"

namespace lodstream::package {

void ByteWriter::u16(uint16_t v) {
  u8(static_cast<uint8_t>(v));
  u8(static_cast<uint8_t>(v >> 8));
}
void ByteWriter::u32(uint32_t v) {
  for (int i = 0; i < 4; ++i) u8(static_cast<uint8_t>(v >> (8 * i)));
}
void ByteWriter::u64(uint64_t v) {
  for (int i = 0; i < 8; ++i) u8(static_cast<uint8_t>(v >> (8 * i)));
}
void ByteWriter::f32(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  u32(bits);
}
void ByteWriter::varint(uint64_t v) {
  while (v >= 0x80) {
    u8(static_cast<uint8_t>(v | 0x80));
    v >>= 7;
  }
  u8(static_cast<uint8_t>(v));
}
void ByteWriter::string(std::string_view s) {
  varint(s.size());
  bytes.insert(bytes.end(), s.begin(), s.end());
}

ByteReader::ByteReader(std::span<const uint8_t> data, std::string_view context, uint64_t base)
    : data_(data), context_(context), base_(base) {}

void ByteReader::fail(const std::string& what) const {
  throw Error(std::string(context_) + " at byte " + std::to_string(base_ + pos_) + ": " + what);
}

const uint8_t* ByteReader::take(size_t n, const char* what) {
  if (n > remaining()) {
    fail(std::string("truncated ") + what + " (" + std::to_string(n) + " bytes needed, " +
         std::to_string(remaining()) + " left)");
  }
  const uint8_t* p = data_.data() + pos_;
  pos_ += n;
  return p;
}

uint8_t ByteReader::u8() {
  return *take(1, "u8");
}
uint16_t ByteReader::u16() {
  const uint8_t* p = take(2, "u16");
  return static_cast<uint16_t>(p[0] | (p[1] << 8));
}
uint32_t ByteReader::u32() {
  const uint8_t* p = take(4, "u32");
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
uint64_t ByteReader::u64() {
  const uint8_t* p = take(8, "u64");
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
float ByteReader::f32() {
  uint32_t bits = u32();
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}
float ByteReader::finite_f32(const char* what) {
  float v = f32();
  if (!std::isfinite(v)) {
    pos_ -= 4;
    fail(std::string("non-finite ") + what);
  }
  return v;
}
uint64_t ByteReader::varint() {
  // The bytes at hand read without a check each (every varint of a valid stream ends within them); a varint
  // that does not is read again by varint_checked, for its error. A byte at a time through take() cost ~90
  // instructions a varint (the error message's set-up in every call): elephant_1m's bench decode -7 M
  // instructions (callgrind), the parse of its index pages 58.9 -> 48.1 M.
  const uint8_t* p = data_.data() + pos_;
  const size_t n = std::min<size_t>(remaining(), 10);
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) {
    v |= static_cast<uint64_t>(p[i] & 0x7f) << (7 * i);
    if (!(p[i] & 0x80)) {
      pos_ += i + 1;
      return v;
    }
  }
  return varint_checked();
}
uint64_t ByteReader::varint_checked() {
  uint64_t v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    uint8_t b = *take(1, "varint");
    v |= static_cast<uint64_t>(b & 0x7f) << shift;
    if (!(b & 0x80)) return v;
  }
  fail("varint longer than 10 bytes");
}
int64_t ByteReader::svarint() {
  uint64_t z = varint();
  return static_cast<int64_t>(z >> 1) ^ -static_cast<int64_t>(z & 1);
}
uint32_t ByteReader::index(uint64_t limit, const char* what) {
  size_t at = pos_;
  uint64_t v = varint();
  if (v >= limit) {
    pos_ = at;
    fail(std::string(what) + " " + std::to_string(v) + " out of range (" + std::to_string(limit) +
         " entries)");
  }
  return static_cast<uint32_t>(v);
}
size_t ByteReader::count(size_t min_record_bytes, const char* what, uint64_t limit) {
  size_t at = pos_;
  uint64_t n = varint();
  if (n > limit || (min_record_bytes > 0 && n > remaining() / min_record_bytes)) {
    pos_ = at;
    fail(std::string("impossible ") + what + " count " + std::to_string(n) + " (" +
         std::to_string(remaining()) + " bytes left)");
  }
  return static_cast<size_t>(n);
}
std::string ByteReader::string(const char* what) {
  size_t n = count(1, what);
  const uint8_t* p = take(n, what);
  return std::string(reinterpret_cast<const char*>(p), n);
}
std::span<const uint8_t> ByteReader::bytes(size_t n, const char* what) {
  return {take(n, what), n};
}

void ByteReader::expect_end() {
  if (!at_end()) fail(std::to_string(remaining()) + " unexpected trailing bytes");
}

}  // namespace lodstream::package
