#include "package/residual_coder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/rans.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kScaleBits = 12, kScale = 1u << kScaleBits;
using rans::kLow;
constexpr uint32_t kStates = 4;
constexpr uint32_t kMaxBits = 40, kMinDirect = 1, kMaxDirect = 6;
// The size a larger D may cost for its speed (residual_coder.hpp).
constexpr double kDirectTolerance = 0.005;
constexpr uint32_t kMaxSymbols = (1u << kMaxDirect) + kMaxBits - kMaxDirect;  // 98: 7 bits

inline uint32_t bit_length(uint64_t z) {
  return z ? 64 - uint32_t(__builtin_clzll(z)) : 0;
}
// The symbol of value z with D direct bits (residual_coder.hpp); its raw bits are the k - 1 below the
// leading one when z >= 2^D.
inline uint32_t symbol_of(uint64_t z, uint32_t k, uint32_t D) {  // k = bit_length(z)
  return k <= D ? uint32_t(z) : (1u << D) + k - D - 1;
}
inline uint32_t symbol_of(uint64_t z, uint32_t D) {
  return symbol_of(z, bit_length(z), D);
}
// The raw bits of symbol s >= 2^D: k - 1.
inline uint32_t raw_bits_of(uint32_t s, uint32_t D) {
  return s - (1u << D) + D;
}
inline uint32_t symbols_for(uint32_t D) {
  return (1u << D) + kMaxBits - D;
}

// Frequencies adding up to kScale, every symbol that occurs at least 1, about proportional to `counts`.
std::array<uint32_t, kMaxSymbols> normalized(const std::array<uint32_t, kMaxSymbols>& counts,
                                             uint64_t total) {
  std::array<uint32_t, kMaxSymbols> f{};
  rans::normalize(counts, total, kScaleBits, f);
  return f;
}

// The symbols' counts with D direct bits, from the counts of the values below 2^kMaxDirect (`low`) and of
// the bit lengths k > kMaxDirect of the others (`lengths`, at k).
std::array<uint32_t, kMaxSymbols> symbol_counts(const std::array<uint32_t, 1u << kMaxDirect>& low,
                                                const std::array<uint32_t, kMaxBits + 1>& lengths,
                                                uint32_t D) {
  std::array<uint32_t, kMaxSymbols> counts{};
  for (uint32_t z = 0; z < (1u << kMaxDirect); ++z) counts[symbol_of(z, D)] += low[z];
  for (uint32_t k = kMaxDirect + 1; k <= kMaxBits; ++k) counts[(1u << D) + k - D - 1] += lengths[k];
  return counts;
}

// The estimated size in bits of a stream with D direct bits: the table, the symbols' codes under the
// normalized frequencies (-log2 f / 2^12 each), the raw bits.
double estimated_bits(const std::array<uint32_t, 1u << kMaxDirect>& low,
                      const std::array<uint32_t, kMaxBits + 1>& lengths, uint32_t D, uint64_t total) {
  const std::array<uint32_t, kMaxSymbols> counts = symbol_counts(low, lengths, D);
  const std::array<uint32_t, kMaxSymbols> f = normalized(counts, total);
  double bits = 8 * (2 + 4 * kStates);
  uint32_t A = symbols_for(D);
  while (counts[A - 1] == 0) --A;
  for (uint32_t s = 0; s < A; ++s) {
    bits += 8 * (f[s] < 128 ? 1 : 2);
    if (counts[s])
      bits += counts[s] * (kScaleBits - std::log2(double(f[s])) + (s < (1u << D) ? 0 : raw_bits_of(s, D)));
  }
  return bits;
}

}  // namespace

std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values) {
  if (values.empty()) return {};
  std::array<uint32_t, 1u << kMaxDirect> low{};
  std::array<uint32_t, kMaxBits + 1> lengths{};
  // Each value's bit length, kept for the symbol pass (becomes its symbol there).
  std::vector<uint8_t> symbols(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const uint64_t z = values[i];
    const uint32_t k = bit_length(z);
    if (k > kMaxBits) throw Error("residual coder: a residual of more than 40 bits");
    symbols[i] = uint8_t(k);
    if (k <= kMaxDirect)
      ++low[z];
    else
      ++lengths[k];
  }
  // D: the largest whose estimate is within kDirectTolerance of the smallest (residual_coder.hpp).
  std::array<double, kMaxDirect + 1> bits{};
  for (uint32_t d = kMinDirect; d <= kMaxDirect; ++d)
    bits[d] = estimated_bits(low, lengths, d, values.size());
  const double fewest = *std::min_element(bits.begin() + kMinDirect, bits.end());
  uint32_t D = kMaxDirect;
  while (bits[D] > fewest * (1 + kDirectTolerance)) --D;

  const std::array<uint32_t, kMaxSymbols> counts = symbol_counts(low, lengths, D);
  uint32_t A = symbols_for(D);
  while (counts[A - 1] == 0) --A;
  const std::array<uint32_t, kMaxSymbols> f = normalized(counts, values.size());
  std::array<uint32_t, kMaxSymbols> start{};
  for (uint32_t s = 1; s < A; ++s) start[s] = start[s - 1] + f[s - 1];

  std::vector<uint8_t> raw;
  uint64_t raw_bits = 0;
  uint32_t bit_count = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const uint64_t z = values[i];
    const uint32_t k = symbols[i];
    symbols[i] = uint8_t(symbol_of(z, k, D));
    if (k > D) {
      raw_bits |= (z & ((uint64_t(1) << (k - 1)) - 1)) << bit_count, bit_count += k - 1;
      for (; bit_count >= 8; bit_count -= 8, raw_bits >>= 8) raw.push_back(uint8_t(raw_bits));
    }
  }
  if (bit_count) raw.push_back(uint8_t(raw_bits));

  // rANS, last value first (value i in state i mod kStates); the bytes come out last first and are
  // reversed after.
  std::vector<uint8_t> reversed;
  reversed.reserve(2 * values.size());  // a step moves out at most 16 bits: never regrown
  uint32_t state[kStates];
  std::fill(state, state + kStates, kLow);
  for (size_t i = values.size(); i-- > 0;) {
    uint32_t& x = state[i % kStates];
    const uint32_t s = symbols[i];
    rans::encode(x, start[s], f[s], kScaleBits, reversed);
  }
  ByteWriter w;
  w.u8(uint8_t(D));
  w.u8(uint8_t(A));
  for (uint32_t s = 0; s < A; ++s) w.varint(f[s]);
  w.varint(4 * kStates + reversed.size());
  for (uint32_t x : state)
    for (int b = 0; b < 4; ++b) w.u8(uint8_t(x >> (8 * b)));
  w.bytes.insert(w.bytes.end(), reversed.rbegin(), reversed.rend());
  w.raw(raw);
  return std::move(w.bytes);
}

ResidualDecoder::ResidualDecoder(std::span<const uint8_t> stream, const std::string& where) : where_(where) {
  if (stream.empty()) return;  // no values
  ByteReader r(stream, where);
  const uint32_t D = r.u8(), A = r.u8();
  if (D < kMinDirect || D > kMaxDirect) r.fail("residual direct bits out of range");
  direct_bits_ = D;
  if (A == 0 || A > symbols_for(D)) r.fail("residual table of an invalid size");
  slot_ = std::make_unique_for_overwrite<uint32_t[]>(kScale + kScale / 4);  // the slots, then the symbols
  uint8_t* const symbols = reinterpret_cast<uint8_t*>(slot_.get() + kScale);
  uint32_t sum = 0;
  for (uint32_t s = 0; s < A; ++s) {
    const uint64_t f = r.varint();
    if (f > kScale - sum) r.fail("residual frequencies add up past the scale");
    rans::fill_slots(slot_.get() + sum, uint32_t(f), uint32_t(f), 16);
    std::memset(symbols + sum, int(s), f);
    sum += uint32_t(f);
  }
  if (sum != kScale) r.fail("residual frequencies do not add up to the scale");
  const uint64_t size = r.varint();
  if (size < 4 * kStates || size > r.remaining()) r.fail("residual rANS stream past the stream's end");
  const std::span<const uint8_t> rest = r.bytes(r.remaining(), "residual rANS stream");
  rans::copy_padded(rest, bytes_);
  rans_end_ = size, raw_bit_at_ = 8 * size, raw_bit_end_ = 8 * uint64_t(rest.size());
  for (uint32_t k = 0; k < kStates; ++k) {
    uint32_t x;
    std::memcpy(&x, bytes_.data() + 4 * k, 4);
    if (x < kLow) fail("invalid residual rANS state");
    state_[k] = x;
  }
  rans_at_ = 4 * kStates;
}

void ResidualDecoder::fail(const char* what) const {
  throw Error(where_ + ": " + what);
}

void ResidualDecoder::planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes,
                             uint32_t first, uint32_t taken) {
  if (count == 0) return;
  if (!slot_) fail("residuals past the residual stream's end");
  const size_t values = taken * count, stride = components * count;  // stride: from one plane to the next
  planes += first * count;
  // The higher planes are zero but for values of raw bits, which write their higher bytes themselves.
  for (uint32_t b = 1; b < width; ++b) std::memset(planes + b * stride, 0, values);
  // The decoder's state in locals (registers) for the loop, written back after it; x0 decodes next.
  const uint32_t* slots = slot_.get();  // then the symbols, at byte 4 * kScale
  const uint8_t* bytes = bytes_.data();
  size_t at = rans_at_;
  uint64_t raw_at = raw_bit_at_;
  const uint64_t raw_end = raw_bit_end_;
  const size_t rans_end = rans_end_;
  const uint32_t D = direct_bits_, direct = 1u << D;
  uint32_t x0 = state_[0], x1 = state_[1], x2 = state_[2], x3 = state_[3];
  const uint64_t largest = width >= 8 ? ~uint64_t(0) : (uint64_t(1) << (8 * width)) - 1;
  // One step (rANS, Duda 2013, eq. 9: D(x) = (s, f_s floor(x / 2^12) + x mod 2^12 - start_s), s the
  // symbol of slot x mod 2^12), then x read back up to kLow from the next 2 rANS bytes; a value's raw
  // bits, rare (residual_coder.hpp), take a branch too.
  const auto step = [&](uint32_t & x, uint8_t * out) __attribute__((always_inline)) {
    const size_t slot = x & (kScale - 1);  // 64-bit: the symbol's address is slots + slot + 4 * kScale
    const uint32_t s = reinterpret_cast<const uint8_t*>(slots)[4 * kScale + slot];
    x = rans::step(x, slots, slot, kScaleBits);
    uint16_t next;
    std::memcpy(&next, bytes + at, 2);
    rans::renormalize(x, at, next);
    *out = uint8_t(s);
    if (s >= direct) [[unlikely]] {
      const uint32_t n = s - direct + D;  // k - 1 raw bits below the leading one
      if (raw_end - raw_at < n) fail("residual raw bits end early");
      uint64_t word;  // 8 bytes from the one holding the next bit: at least 57 bits, n <= 39 needed
      std::memcpy(&word, bytes + (raw_at >> 3), 8);
      const uint64_t z = uint64_t(1) << n | ((word >> (raw_at & 7)) & ((uint64_t(1) << n) - 1));
      raw_at += n;
      if (z > largest) fail("residual wider than its node's planes");
      // z < 2^(n + 1): bytes 0..n / 8, fewer than width by the check above; the planes above are zero
      // already (the memset).
      *out = uint8_t(z);
      for (uint32_t b = 1; b <= n / 8; ++b) out[b * stride] = uint8_t(z >> (8 * b));
    }
  };
  // Values in blocks of kStates, then one by one, rotating the states. A block reads at most 8 bytes:
  // started only while at is within the rANS bytes, so that no read leaves the padding.
  uint8_t* out = planes;
  uint8_t* const blocks_end = planes + (values - values % kStates);
  for (; out != blocks_end; out += kStates) {
    if (at > rans_end) break;
    step(x0, out), step(x1, out + 1), step(x2, out + 2), step(x3, out + 3);
  }
  if (at <= rans_end)
    for (; out != planes + values; ++out) {
      step(x0, out);
      const uint32_t t = x0;
      x0 = x1, x1 = x2, x2 = x3, x3 = t;
    }
  if (at > rans_end) fail("residual rANS stream ends early");
  state_[0] = x0, state_[1] = x1, state_[2] = x2, state_[3] = x3;
  rans_at_ = at, raw_bit_at_ = raw_at;
}

void ResidualDecoder::finish() const {
  if (!slot_) return;
  bool states_back = true;
  for (uint32_t x : state_) states_back = states_back && x == kLow;
  // Raw bits: up to the last byte, and none set beyond the last one read.
  const bool bits_left = (raw_bit_at_ + 7) / 8 != raw_bit_end_ / 8 ||
                         (raw_bit_at_ % 8 && bytes_[raw_bit_at_ / 8] >> (raw_bit_at_ % 8));
  if (rans_at_ != rans_end_ || !states_back || bits_left) fail("residual stream holds bytes of no residual");
}

}  // namespace lodstream::package
