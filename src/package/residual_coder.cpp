#include "package/residual_coder.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/error.hpp"
#include "package/bytes.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kScaleBits = 12, kScale = 1u << kScaleBits;
constexpr uint32_t kLow = 1u << 23;  // rANS states lie in [kLow, 2^31)
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
    const uint32_t x_max = ((kLow >> kScaleBits) << 8) * f[s];
    for (; x >= x_max; x >>= 8) reversed.push_back(uint8_t(x));
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
  frequency_.resize(A), start_.resize(A);
  symbol_.resize(kScale);
  uint32_t sum = 0;
  for (uint32_t s = 0; s < A; ++s) {
    const uint64_t f = r.varint();
    if (f > kScale - sum) r.fail("residual frequencies add up past the scale");
    frequency_[s] = uint16_t(f), start_[s] = uint16_t(sum);
    std::memset(symbol_.data() + sum, int(s), f);
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
    if (x < kLow || x >= kLow << 8) throw Error(where + ": invalid residual rANS state");
    state_[k] = x;
  }
  rans_at_ = 8;
}

inline uint32_t ResidualDecoder::next_symbol() {
  uint32_t& x = state_[values_++ & 1];
  const uint32_t slot = x & (kScale - 1), s = symbol_[slot];
  x = frequency_[s] * (x >> kScaleBits) + slot - start_[s];
  while (x < kLow) {
    if (rans_at_ == rans_.size()) throw Error(where_ + ": residual rANS stream ends early");
    x = x << 8 | rans_[rans_at_++];
  }
  return s;
}

inline uint64_t ResidualDecoder::raw_bits(uint32_t n) {
  while (bit_count_ < n) {
    if (raw_at_ == raw_.size()) throw Error(where_ + ": residual raw bits end early");
    bits_ |= uint64_t(raw_[raw_at_++]) << bit_count_, bit_count_ += 8;
  }
  const uint64_t v = bits_ & ((uint64_t(1) << n) - 1);
  bits_ >>= n, bit_count_ -= n;
  return v;
}

void ResidualDecoder::planes(size_t count, uint32_t components, uint32_t width, uint8_t* planes) {
  if (count == 0) return;
  if (symbol_.empty()) throw Error(where_ + ": residuals past the residual stream's end");
  const uint32_t max_bits = 8 * width;
  for (uint32_t a = 0; a < components; ++a)
    for (size_t i = 0; i < count; ++i) {
      const uint32_t s = next_symbol();
      uint64_t z = s;
      if (s >= 2) {
        const uint32_t k = s / 2 + 1;
        if (k > max_bits) throw Error(where_ + ": residual wider than its node's planes");
        z = (uint64_t(2 | (s & 1)) << (k - 2)) | raw_bits(k - 2);
      } else if (max_bits == 0) {
        throw Error(where_ + ": residual wider than its node's planes");
      }
      for (uint32_t b = 0; b < width; ++b, z >>= 8) planes[(b * components + a) * count + i] = uint8_t(z);
    }
}

void ResidualDecoder::finish() const {
  if (symbol_.empty()) return;
  if (rans_at_ != rans_.size() || state_[0] != kLow || state_[1] != kLow || raw_at_ != raw_.size() ||
      bit_count_ >= 8 || bits_ != 0)
    throw Error(where_ + ": residual stream holds bytes of no residual");
}

}  // namespace lodstream::package
