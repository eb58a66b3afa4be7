#include "package/residual_coder.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/error.hpp"
#include "package/bytes.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kScaleBits = 12, kScale = 1u << kScaleBits;
// rANS states lie in [kLow, 2^32), renormalized 16 bits at a time: a decode step reads at most once.
constexpr uint32_t kLow = 1u << 16;
constexpr uint32_t kMaxBits = 40, kSymbols = 2 * kMaxBits;

inline uint32_t bit_length(uint64_t z) {
  return z ? 64 - uint32_t(__builtin_clzll(z)) : 0;
}
// The symbol of value z (residual_coder.hpp); its raw bits are the k - 2 below.
inline uint32_t symbol_of(uint64_t z) {
  const uint32_t k = bit_length(z);
  return k < 2 ? uint32_t(z) : 2 * (k - 1) + uint32_t((z >> (k - 2)) & 1);
}

// Frequencies adding up to kScale, every symbol that occurs at least 1, about proportional to `counts`.
std::array<uint32_t, kSymbols> normalized(const std::array<uint32_t, kSymbols>& counts, uint64_t total) {
  std::array<uint32_t, kSymbols> f{};
  uint64_t sum = 0;
  for (uint32_t s = 0; s < kSymbols; ++s) {
    if (counts[s]) f[s] = std::max<uint32_t>(1, uint32_t(uint64_t(counts[s]) * kScale / total));
    sum += f[s];
  }
  // Rounding down leaves at most kSymbols short; rounding up to 1 at most kSymbols over: the largest
  // frequency takes the difference (over several steps if it would fall below 1).
  while (sum != kScale) {
    const uint32_t largest = uint32_t(std::max_element(f.begin(), f.end()) - f.begin());
    if (sum < kScale) {
      f[largest] += uint32_t(kScale - sum), sum = kScale;
    } else {
      const uint32_t d = std::min<uint32_t>(uint32_t(sum - kScale), f[largest] - 1);
      f[largest] -= d, sum -= d;
    }
  }
  return f;
}

}  // namespace

std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values) {
  if (values.empty()) return {};
  std::vector<uint8_t> symbols(values.size());
  std::array<uint32_t, kSymbols> counts{};
  std::vector<uint8_t> raw;
  uint64_t bits = 0;
  uint32_t bit_count = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const uint64_t z = values[i];
    const uint32_t s = symbol_of(z), k = bit_length(z);
    if (k > kMaxBits) throw Error("residual coder: a residual of more than 40 bits");
    symbols[i] = uint8_t(s), ++counts[s];
    if (k > 2) {
      bits |= (z & ((uint64_t(1) << (k - 2)) - 1)) << bit_count, bit_count += k - 2;
      for (; bit_count >= 8; bit_count -= 8, bits >>= 8) raw.push_back(uint8_t(bits));
    }
  }
  if (bit_count) raw.push_back(uint8_t(bits));
  uint32_t A = kSymbols;
  while (counts[A - 1] == 0) --A;
  const std::array<uint32_t, kSymbols> f = normalized(counts, values.size());
  std::array<uint32_t, kSymbols> start{};
  for (uint32_t s = 1; s < A; ++s) start[s] = start[s - 1] + f[s - 1];

  // rANS, last value first; the bytes come out last first and are reversed after.
  std::vector<uint8_t> reversed;
  uint32_t state[2] = {kLow, kLow};
  for (size_t i = values.size(); i-- > 0;) {
    uint32_t& x = state[i & 1];
    const uint32_t s = symbols[i];
    if (x >= (uint64_t(kLow >> kScaleBits) << 16) * f[s]) {
      reversed.push_back(uint8_t(x >> 8)), reversed.push_back(uint8_t(x));  // read back as a u16 LE
      x >>= 16;
    }
    x = ((x / f[s]) << kScaleBits) + x % f[s] + start[s];
  }
  ByteWriter w;
  w.u8(uint8_t(A));
  for (uint32_t s = 0; s < A; ++s) w.varint(f[s]);
  w.varint(8 + reversed.size());
  for (uint32_t x : state)
    for (int b = 0; b < 4; ++b) w.u8(uint8_t(x >> (8 * b)));
  w.bytes.insert(w.bytes.end(), reversed.rbegin(), reversed.rend());
  w.raw(raw);
  return std::move(w.bytes);
}

ResidualDecoder::ResidualDecoder(std::span<const uint8_t> stream, const std::string& where) : where_(where) {
  if (stream.empty()) return;  // no values
  ByteReader r(stream, where);
  const uint32_t A = r.u8();
  if (A == 0 || A > kSymbols) r.fail("residual table of an invalid size");
  slot_.resize(kScale);
  uint32_t sum = 0;
  for (uint32_t s = 0; s < A; ++s) {
    const uint64_t f = r.varint();
    if (f > kScale - sum) r.fail("residual frequencies add up past the scale");
    for (uint32_t slot = sum; slot < sum + f; ++slot)
      slot_[slot] = uint32_t(f) | (slot - sum) << 13 | s << 25;
    sum += uint32_t(f);
  }
  if (sum != kScale) r.fail("residual frequencies do not add up to the scale");
  const uint64_t size = r.varint();
  if (size < 8 || size > r.remaining()) r.fail("residual rANS stream past the stream's end");
  rans_ = r.bytes(size, "residual rANS stream");
  raw_ = r.bytes(r.remaining(), "residual raw bits");
  for (int k = 0; k < 2; ++k) {
    uint32_t x = 0;
    for (int b = 0; b < 4; ++b) x |= uint32_t(rans_[4 * k + b]) << (8 * b);
    if (x < kLow) throw Error(where + ": invalid residual rANS state");
    state_[k] = x;
  }
  rans_at_ = 8;
}

namespace {

// One decode step (residual_coder.hpp) from state x (then the other state's turn), reading the rANS bytes at
// `rans` and the raw bits into bits / bit_count. kChecked: bounds-checked reads; unchecked, the caller
// guarantees 2 rANS bytes and 8 raw bytes (a refill's worth) past the current positions.
template <bool kChecked>
inline uint64_t decode_value(const uint32_t* slots, uint32_t& x, const uint8_t* rans, size_t& rans_at,
                             size_t rans_end, const uint8_t* raw, size_t& raw_at, size_t raw_end,
                             uint64_t& bits, uint32_t& bit_count, uint32_t max_symbol,
                             const std::string& where) {
  // The slot's entry: the frequency, the slot's offset in its symbol's range, the symbol.
  const uint32_t e = slots[x & (kScale - 1)], s = e >> 25;
  x = (e & 0x1fff) * (x >> kScaleBits) + ((e >> 13) & 0xfff);
  const bool low = x < kLow;  // x >= 16 here: one read of 16 bits restores x >= kLow
  if constexpr (kChecked) {
    if (low) {
      if (rans_end - rans_at < 2) throw Error(where + ": residual rANS stream ends early");
      x = x << 16 | uint32_t(rans[rans_at]) | uint32_t(rans[rans_at + 1]) << 8, rans_at += 2;
    }
  } else {
    const uint32_t next = uint32_t(rans[rans_at]) | uint32_t(rans[rans_at + 1]) << 8;
    x = low ? x << 16 | next : x, rans_at += low ? 2 : 0;
  }
  if (s > max_symbol) throw Error(where + ": residual wider than its node's planes");
  // z = s below 2; else (2 | bit 0 of s) << n | n raw bits, n = s / 2 - 1.
  const uint32_t n = (s >> 1) - (s >= 2), top = (s & 1) | (s >= 2 ? 2 : 0);
  if constexpr (kChecked) {
    while (bit_count < n) {
      if (raw_at == raw_end) throw Error(where + ": residual raw bits end early");
      bits |= uint64_t(raw[raw_at++]) << bit_count, bit_count += 8;
    }
  } else {  // whole bytes up to 56 bits or more (bytes past bit_count are loaded again, the same)
    uint64_t next;
    std::memcpy(&next, raw + raw_at, 8);
    bits |= next << bit_count;
    raw_at += (63 - bit_count) >> 3, bit_count |= 56;
  }
  const uint64_t z = uint64_t(top) << n | (bits & ((uint64_t(1) << n) - 1));
  bits >>= n, bit_count -= n;
  return z;
}

}  // namespace

void ResidualDecoder::planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes) {
  if (count == 0) return;
  if (slot_.empty()) throw Error(where_ + ": residuals past the residual stream's end");
  // The decoder's state in locals (registers) for the loop, written back after it; x0 decodes next.
  const uint32_t* slots = slot_.data();
  const uint8_t *rans = rans_.data(), *raw = raw_.data();
  size_t rans_at = rans_at_, raw_at = raw_at_;
  const size_t rans_end = rans_.size(), raw_end = raw_.size();
  uint32_t x0 = state_[0], x1 = state_[1];
  uint64_t bits = bits_;
  uint32_t bit_count = bit_count_;
  const uint32_t max_symbol = 2 * (8 * width - 1) + 1;  // symbols of values of at most 8 width bits
  const size_t plane = components * count;
  // Blocks of kBlock values with no bounds check while the streams hold a block's worth (2 rANS bytes and
  // at most 38 raw bits a value, then a refill), the rest checked value by value.
  constexpr size_t kBlock = 16;
  for (uint32_t a = 0; a < components; ++a) {
    uint8_t* out = planes + a * count;
    for (size_t i = 0; i < count;) {
      const bool fast =
          count - i >= kBlock && rans_end - rans_at >= 2 * kBlock && raw_end - raw_at >= 5 * kBlock + 8;
      const size_t end = fast ? i + kBlock : i + 1;
      for (; i < end; ++i) {
        const uint64_t z = fast ? decode_value<false>(slots, x0, rans, rans_at, rans_end, raw, raw_at,
                                                      raw_end, bits, bit_count, max_symbol, where_)
                                : decode_value<true>(slots, x0, rans, rans_at, rans_end, raw, raw_at, raw_end,
                                                     bits, bit_count, max_symbol, where_);
        std::swap(x0, x1);
        out[i] = uint8_t(z);
        if (width > 1)
          for (uint32_t b = 1; b < width; ++b) out[b * plane + i] = uint8_t(z >> (8 * b));
      }
    }
  }
  state_[0] = x0, state_[1] = x1;
  rans_at_ = rans_at, raw_at_ = raw_at, bits_ = bits, bit_count_ = bit_count;
}

void ResidualDecoder::finish() const {
  if (slot_.empty()) return;
  if (rans_at_ != rans_.size() || state_[0] != kLow || state_[1] != kLow || raw_at_ != raw_.size() ||
      bit_count_ >= 8 || bits_ != 0)
    throw Error(where_ + ": residual stream holds bytes of no residual");
}

}  // namespace lodstream::package
