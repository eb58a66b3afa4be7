#include "package/residual_coder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/rans.hpp"
#include "package/residual_tables.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kScaleBits = 12, kScale = 1u << kScaleBits;
using rans::kLow;
constexpr uint32_t kStates = 4;
constexpr uint32_t kMaxBits = 40, kMinDirect = 1, kMaxDirect = 6;
// The size a larger D may cost for its speed (residual_coder.hpp).
constexpr double kDirectTolerance = 0.005;
constexpr uint32_t kMaxSymbols = (1u << kMaxDirect) + kMaxBits - kMaxDirect;  // 98: 7 bits
static_assert(residual_tables::kSymbols == kMaxSymbols && residual_tables::kDirectBits == kMaxDirect);
// A decode table's words: 2^12 slots (ResidualDecoder::slot_), then its 2^12 symbols as bytes.
constexpr uint32_t kTableWords = kScale + kScale / 4;

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
constexpr uint32_t raw_bits_of(uint32_t s, uint32_t D) {
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

// A table's starts and frequencies, as the encoder takes them.
struct Coding {
  std::array<uint32_t, kMaxSymbols> start{}, f{};
};
Coding coding_of(std::span<const uint32_t> f) {
  Coding c;
  std::copy(f.begin(), f.end(), c.f.begin());
  for (size_t s = 1; s < f.size(); ++s) c.start[s] = c.start[s - 1] + c.f[s - 1];
  return c;
}

// Appends the varint size of the rANS bytes, the rANS bytes and the raw bits of `values`
// (residual_coder.hpp), value i coded with the Coding table_of(i); `symbols` holds each value's bit length
// and takes its symbol with D direct bits. Cost: O(values.size()), a division a value.
template <typename TableOf>
void write_codes(std::span<const uint64_t> values, std::vector<uint8_t>& symbols, uint32_t D,
                 TableOf table_of, ByteWriter& w) {
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
    const Coding& c = table_of(i);
    rans::encode(x, c.start[s], c.f[s], kScaleBits, reversed);
  }
  w.varint(4 * kStates + reversed.size());
  for (uint32_t x : state)
    for (int b = 0; b < 4; ++b) w.u8(uint8_t(x >> (8 * b)));
  w.bytes.insert(w.bytes.end(), reversed.rbegin(), reversed.rend());
  w.raw(raw);
}

// A decode table (kTableWords words: ResidualDecoder::slot_'s layout) of the frequencies frequency(s) of
// symbols 0..A-1, which add up to kScale; returns false when they do not (the table then partly written).
// Cost: O(2^12).
template <typename Frequency>
bool fill_table(uint32_t* table, uint32_t A, Frequency frequency) {
  uint8_t* const symbols = reinterpret_cast<uint8_t*>(table + kScale);
  uint32_t sum = 0;
  for (uint32_t s = 0; s < A; ++s) {
    const uint64_t f = frequency(s);
    if (f > kScale - sum) return false;
    rans::fill_slots(table + sum, uint32_t(f), uint32_t(f), 16);
    std::memset(symbols + sum, int(s), f);
    sum += uint32_t(f);
  }
  return sum == kScale;
}

// The built-in tables of residual_tables.hpp: per set, the encoder's Codings and code lengths (bits, raw
// bits not counted) of every context, built on first use.
struct PairedSet {
  std::array<Coding, residual_tables::kContexts> coding;
  std::array<std::array<float, kMaxSymbols>, residual_tables::kContexts> bits;
};
const std::array<PairedSet, residual_tables::kSets>& paired_sets() {
  static const std::array<PairedSet, residual_tables::kSets> sets = [] {
    std::array<PairedSet, residual_tables::kSets> out;
    for (uint32_t k = 0; k < residual_tables::kSets; ++k)
      for (uint32_t c = 0; c < residual_tables::kContexts; ++c) {
        std::array<uint32_t, kMaxSymbols> f;
        std::copy_n(residual_tables::kFrequencies[k][c], kMaxSymbols, f.begin());
        out[k].coding[c] = coding_of(f);
        for (uint32_t s = 0; s < kMaxSymbols; ++s)
          out[k].bits[c][s] = float(kScaleBits - std::log2(double(f[s])));
      }
    return out;
  }();
  return sets;
}

// A paired set's decode table of one context, compact (4.5 KB, where a table of fill_table's layout takes
// 20 KB): per slot of 2^12 its symbol as a byte, then per symbol s a word of its frequency (bits 0-15) and
// start (16-31). A step takes a load more on the state's chain (the symbol's word after the symbol), but a
// set's 4 tables (18 KB) stay in L1 where 4 of fill_table's (80 KB) did not: refined_elephant's bench
// decode (cachegrind, its default caches), planes()' L1 read misses 56.2 k -> 23.2 k, its instructions 6.71
// -> 7.25 M; bench decode's page time (decompress_page, the median of 25 pairs) 0.85 times the old,
// elephant_1m's 0.92 (12 pairs).
constexpr uint32_t kPairedWords = kScale / 4 + kMaxSymbols + 2;  // 1124: tables 8-byte aligned

// The decode tables of set `set`'s kContexts contexts (kPairedWords words each), one after the other, built
// on first use (once per set and process). Cost after the first: a call_once check.
const uint32_t* paired_tables(uint32_t set) {
  static std::once_flag once[residual_tables::kSets];
  static std::unique_ptr<uint32_t[]> tables[residual_tables::kSets];
  std::call_once(once[set], [set] {
    tables[set] = std::make_unique<uint32_t[]>(residual_tables::kContexts * kPairedWords);
    for (uint32_t c = 0; c < residual_tables::kContexts; ++c) {
      uint8_t* const symbols = reinterpret_cast<uint8_t*>(tables[set].get() + c * kPairedWords);
      uint32_t* const starts = tables[set].get() + c * kPairedWords + kScale / 4;
      for (uint32_t s = 0, start = 0; s < kMaxSymbols; ++s) {
        const uint32_t f =
            residual_tables::kFrequencies[set][c][s];  // adding up to 2^12 (test_residual_coder)
        starts[s] = f | start << 16;
        std::memset(symbols + start, int(s), f);
        start += f;
      }
    }
  });
  return tables[set].get();
}

// Per low byte of a component-0 value: the word offset of its component-1 value's decode table in a set's
// tables (residual_tables::context_of).
constexpr std::array<uint32_t, 256> kContextOffset = [] {
  std::array<uint32_t, 256> out{};
  for (uint32_t b = 0; b < 256; ++b) out[b] = residual_tables::context_of(uint8_t(b)) * kPairedWords;
  return out;
}();

// Per D, per symbol: what a value's raw bits make of it when it has at most kFastRawBits (its bit length 15
// or less, two bytes). n: its raw bits (0 for a direct value); the value is lead | (the n raw bits & mask),
// lead s for a direct value and 2^n (the leading one) for the others, mask 2^n - 1. Symbols of more raw bits
// have their n only (the decoder takes them one by one).
constexpr uint32_t kFastRawBits = 14;  // 4 values' in the 57 bits of one 8-byte read
struct RawCodes {
  std::array<uint8_t, kMaxSymbols> n{};
  std::array<uint16_t, kMaxSymbols> lead{}, mask{};
};
constexpr std::array<RawCodes, kMaxDirect + 1> kRawCodes = [] {
  std::array<RawCodes, kMaxDirect + 1> out{};
  for (uint32_t D = kMinDirect; D <= kMaxDirect; ++D)
    for (uint32_t s = 0; s < kMaxSymbols; ++s) {
      const uint32_t n = s < (1u << D) ? 0 : raw_bits_of(s, D);
      out[D].n[s] = uint8_t(n);
      if (n == 0) out[D].lead[s] = uint16_t(s);
      if (n > 0 && n <= kFastRawBits)
        out[D].lead[s] = uint16_t(1u << n), out[D].mask[s] = uint16_t((1u << n) - 1);
    }
  return out;
}();

// How ResidualDecoder::decode takes the values of raw bits of a stream whose table gives symbol s < A the
// frequency f[s] (D direct bits): with a branch (0) unless their frequencies add up to kCommonRaw of 2^12 or
// more; then without one, in one byte (1: values of up to 7 raw bits) unless those of 8 or more add up to
// kWideRaw (2: up to kFastRawBits, in two bytes). Measured (a throwaway harness: rdtsc around planes(), the
// median of 400 decodes cycling through 64 streams of 12,000 geometric residuals in planes of 2 bytes, all
// with D = 6; cycles a value): the branch 2.40 with no raw bits, 2.76 at 2.1 % of the values, 3.17 at 4.4 %,
// 4.42 at 12 %, 6.14 at 21 %, 12.35 at 53 %; the one-byte way 3.03-3.13 up to 12 % (3.20 at 21 %), then
// with values of 8 raw bits or more 3.32 (0.6 % of them), 3.42 (1.1 %), 3.60 (1.9 %), 4.92 (7.9 %); the
// two-byte way 3.27-3.37 throughout. Hence the thresholds: 4.2 % and 0.8 %.
constexpr uint32_t kCommonRaw = kScale / 24, kWideRaw = kScale / 128;
template <typename Frequencies>
uint32_t raw_bytes_of(const Frequencies& f, uint32_t A, uint32_t D) {
  uint32_t raw = 0, wide = 0;
  for (uint32_t s = 1u << D; s < A; ++s) (raw_bits_of(s, D) < 8 ? raw : wide) += f[s];
  return raw + wide < kCommonRaw ? 0 : wide < kWideRaw ? 1 : 2;
}
// The same for a paired set: the most of its contexts'.
uint32_t paired_raw_bytes(uint32_t set) {
  uint32_t bytes = 0;
  for (uint32_t c = 0; c < residual_tables::kContexts; ++c)
    bytes = std::max(bytes, raw_bytes_of(residual_tables::kFrequencies[set][c], kMaxSymbols,
                                         residual_tables::kDirectBits));
  return bytes;
}

// The decoder's step (rANS, Duda 2013, eq. 9: D(x) = (s, f_s floor(x / 2^12) + x mod 2^12 - start_s)) with a
// table of fill_table's layout at `slots`: returns s and steps x.
inline __attribute__((always_inline)) uint32_t own_step(uint32_t& x, const uint32_t* slots) {
  const size_t slot = x & (kScale - 1);  // 64-bit: the symbol's address is slots + slot + 4 * kScale
  const uint32_t s = reinterpret_cast<const uint8_t*>(slots)[4 * kScale + slot];
  x = rans::step(x, slots, slot, kScaleBits);
  return s;
}
// The same with a paired set's compact table at `table`.
inline __attribute__((always_inline)) uint32_t paired_step(uint32_t& x, const uint32_t* table) {
  const uint8_t* const bytes = reinterpret_cast<const uint8_t*>(table);
  const size_t slot = x & (kScale - 1);
  const uint32_t s = bytes[slot];
  uint16_t f, start;
  std::memcpy(&f, bytes + kScale + 4 * size_t(s), 2);
  std::memcpy(&start, bytes + kScale + 4 * size_t(s) + 2, 2);
  x = f * (x >> kScaleBits) - start + uint32_t(slot);
  return s;
}

// The values' counts below 2^kMaxDirect (`low`) and of each bit length above (`lengths`), and each value's
// bit length (`symbols`, which write_codes makes its symbol). Throws lodstream::Error on a value of more
// than 40 bits.
struct Histogram {
  std::array<uint32_t, 1u << kMaxDirect> low{};
  std::array<uint32_t, kMaxBits + 1> lengths{};
  std::vector<uint8_t> symbols;
};
Histogram histogram_of(std::span<const uint64_t> values) {
  Histogram h;
  h.symbols.resize(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const uint64_t z = values[i];
    const uint32_t k = bit_length(z);
    if (k > kMaxBits) throw Error("residual coder: a residual of more than 40 bits");
    h.symbols[i] = uint8_t(k);
    if (k <= kMaxDirect)
      ++h.low[z];
    else
      ++h.lengths[k];
  }
  return h;
}

// The stream of `values` (histogram h) with D direct bits.
std::vector<uint8_t> encode_with(std::span<const uint64_t> values, Histogram& h, uint32_t D) {
  const std::array<uint32_t, kMaxSymbols> counts = symbol_counts(h.low, h.lengths, D);
  uint32_t A = symbols_for(D);
  while (counts[A - 1] == 0) --A;
  const Coding c = coding_of(normalized(counts, values.size()));
  ByteWriter w;
  w.u8(uint8_t(D));
  w.u8(uint8_t(A));
  for (uint32_t s = 0; s < A; ++s) w.varint(c.f[s]);
  write_codes(
      values, h.symbols, D, [&c](size_t) -> const Coding& { return c; }, w);
  return std::move(w.bytes);
}

}  // namespace

std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values) {
  if (values.empty()) return {};
  Histogram h = histogram_of(values);
  // D: the largest whose estimate is within kDirectTolerance of the smallest (residual_coder.hpp).
  std::array<double, kMaxDirect + 1> bits{};
  for (uint32_t d = kMinDirect; d <= kMaxDirect; ++d)
    bits[d] = estimated_bits(h.low, h.lengths, d, values.size());
  const double fewest = *std::min_element(bits.begin() + kMinDirect, bits.end());
  uint32_t D = kMaxDirect;
  while (bits[D] > fewest * (1 + kDirectTolerance)) --D;
  // Unless its values of raw bits are common enough for the decoder to take them without a branch
  // (raw_bytes_of): then they are with any smaller D too (more values with raw bits, each as many), and the
  // decode costs the same; the smallest D is taken.
  const std::array<uint32_t, kMaxSymbols> counts = symbol_counts(h.low, h.lengths, D);
  uint32_t A = symbols_for(D);
  while (counts[A - 1] == 0) --A;
  if (raw_bytes_of(normalized(counts, values.size()), A, D) > 0)
    D = uint32_t(std::min_element(bits.begin() + kMinDirect, bits.end()) - bits.begin());
  return encode_with(values, h, D);
}

std::vector<uint8_t> encode_residuals(std::span<const uint64_t> values, uint32_t direct_bits) {
  if (direct_bits < kMinDirect || direct_bits > kMaxDirect)
    throw Error("residual coder: direct bits out of range");
  if (values.empty()) return {};
  Histogram h = histogram_of(values);
  return encode_with(values, h, direct_bits);
}

std::vector<uint8_t> encode_paired_residuals(std::span<const uint64_t> values,
                                             std::span<const uint32_t> counts) {
  if (values.empty()) return {};
  using namespace residual_tables;
  // Each value's context (residual_tables.hpp) and bit length.
  std::vector<uint8_t> context(values.size()), symbols(values.size());
  size_t at = 0;
  for (uint32_t n : counts) {
    if (2 * uint64_t(n) > values.size() - at) throw Error("residual coder: paired counts past the residuals");
    std::fill_n(context.begin() + at, n, uint8_t(kFirstContext));
    for (size_t i = 0; i < n; ++i) context[at + n + i] = uint8_t(context_of(uint8_t(values[at + i])));
    at += 2 * size_t(n);
  }
  if (at != values.size()) throw Error("residual coder: paired counts short of the residuals");
  // The set coding the values shortest (raw bits are the same under every set), from the symbols' counts
  // per context (a count a value, where summing each set's code lengths value by value took 8 additions:
  // refined_elephant's bake 2,084.3 -> 2,071.2 M instructions, callgrind; format 12's 2,059.4).
  std::array<std::array<uint32_t, kMaxSymbols>, kContexts> histogram{};
  for (size_t i = 0; i < values.size(); ++i) {
    const uint32_t k = bit_length(values[i]);
    if (k > kMaxBits) throw Error("residual coder: a residual of more than 40 bits");
    symbols[i] = uint8_t(k);
    ++histogram[context[i]][symbol_of(values[i], k, kDirectBits)];
  }
  const std::array<PairedSet, kSets>& sets = paired_sets();
  std::array<double, kSets> bits{};
  for (uint32_t set = 0; set < kSets; ++set)
    for (uint32_t c = 0; c < kContexts; ++c)
      for (uint32_t s = 0; s < kMaxSymbols; ++s) bits[set] += histogram[c][s] * double(sets[set].bits[c][s]);
  const uint32_t set = uint32_t(std::min_element(bits.begin(), bits.end()) - bits.begin());
  ByteWriter w;
  w.u8(uint8_t(set));
  write_codes(
      values, symbols, kDirectBits, [&](size_t i) -> const Coding& { return sets[set].coding[context[i]]; },
      w);
  return std::move(w.bytes);
}

ResidualDecoder::ResidualDecoder(std::span<const uint8_t> stream, const std::string& where, bool paired)
    : where_(where), paired_(paired) {
  if (stream.empty()) return;  // no values
  ByteReader r(stream, where);
  if (paired) {
    const uint32_t set = r.u8();
    if (set >= residual_tables::kSets) r.fail("residual table set out of range");
    direct_bits_ = residual_tables::kDirectBits, slots_ = paired_tables(set);
    raw_bytes_ = paired_raw_bytes(set);
  } else {
    const uint32_t D = r.u8(), A = r.u8();
    if (D < kMinDirect || D > kMaxDirect) r.fail("residual direct bits out of range");
    direct_bits_ = D;
    if (A == 0 || A > symbols_for(D)) r.fail("residual table of an invalid size");
    own_slots_ = std::make_unique_for_overwrite<uint32_t[]>(kTableWords);
    std::array<uint32_t, kMaxSymbols> f{};  // the frequencies (each at most 2^12 once the table adds up)
    if (!fill_table(own_slots_.get(), A, [&r, &f](uint32_t s) {
          const uint64_t frequency = r.varint();
          f[s] = uint32_t(std::min<uint64_t>(frequency, kScale + 1));
          return frequency;
        }))
      r.fail("residual frequencies do not add up to the scale");
    slots_ = own_slots_.get(), raw_bytes_ = raw_bytes_of(f, A, D);
  }
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
  if (!slots_) fail("residuals past the residual stream's end");
  if (paired_ && (components != 2 || first != 0 || taken != 2)) fail("paired residuals of other components");
  const size_t values = taken * count, stride = components * count;  // stride: from one plane to the next
  planes += first * count;
  // The higher planes are zero but for values of raw bits, which write their higher bytes themselves.
  for (uint32_t b = 1; b < width; ++b) std::memset(planes + b * stride, 0, values);
  const uint64_t largest = width >= 8 ? ~uint64_t(0) : (uint64_t(1) << (8 * width)) - 1;
  // The stream's step, then its raw bits' way (decode): with a branch, or without in one or two bytes.
  const auto decode_with = [&](uint8_t* at, size_t n, auto step_of) {
    if (raw_bytes_ == 0)
      decode<0>(at, n, stride, largest, step_of);
    else if (raw_bytes_ == 1 || width == 1)
      decode<1>(at, n, stride, largest, step_of);
    else
      decode<2>(at, n, stride, largest, step_of);
  };
  if (!paired_) {
    decode_with(planes, values, [slots = slots_](uint32_t& x, const uint8_t*) { return own_step(x, slots); });
    return;
  }
  // Component 0 with the first context's table, then component 1 with the table of its vertex's component-0
  // low byte, count bytes back (residual_tables.hpp).
  const uint32_t* const tables = slots_;
  decode_with(planes, count,
              [first = tables + residual_tables::kFirstContext * kPairedWords](uint32_t& x, const uint8_t*) {
                return paired_step(x, first);
              });
  decode_with(planes + count, count, [tables, count](uint32_t& x, const uint8_t* out) {
    return paired_step(x, tables + kContextOffset[out[-ptrdiff_t(count)]]);
  });
}

template <uint32_t kRawBytes, typename StepOf>
void ResidualDecoder::decode(uint8_t* planes, size_t values, size_t stride, uint64_t largest,
                             StepOf step_of) {
  // The decoder's state in locals (registers) for the loop, written back after it; x0 decodes next.
  const uint8_t* bytes = bytes_.data();
  size_t at = rans_at_;
  uint64_t raw_at = raw_bit_at_;
  const uint64_t raw_end = raw_bit_end_;
  const size_t rans_end = rans_end_;
  const uint32_t D = direct_bits_, direct = 1u << D;
  uint32_t x0 = state_[0], x1 = state_[1], x2 = state_[2], x3 = state_[3];
  // One step (rANS, Duda 2013, eq. 9: D(x) = (s, f_s floor(x / 2^12) + x mod 2^12 - start_s), s the
  // symbol of slot x mod 2^12 of the value's table), then x read back up to kLow from the next 2 rANS bytes;
  // returns s.
  const auto step = [&](uint32_t & x, const uint8_t* out) __attribute__((always_inline)) {
    const uint32_t s = step_of(x, out);
    uint16_t next;
    std::memcpy(&next, bytes + at, 2);
    rans::renormalize(x, at, next);
    return s;
  };
  // The next raw bits from raw_at on, at least 57 (raw_at <= raw_end: the read stays in the padding).
  const auto raw_word = [&]() __attribute__((always_inline)) {
    uint64_t word;
    std::memcpy(&word, bytes + (raw_at >> 3), 8);
    return word >> (raw_at & 7);
  };
  // The value of symbol s at `out`, its raw bits (when it has) taken with a branch.
  const auto raw = [&](uint32_t s, uint8_t * out) __attribute__((always_inline)) {
    *out = uint8_t(s);
    if (s >= direct) [[unlikely]] {
      const uint32_t n = s - direct + D;  // k - 1 raw bits below the leading one
      if (raw_at + n > raw_end) fail("residual raw bits end early");
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
  // The same without a branch when s has at most 7 raw bits (kRawBytes 1) or kFastRawBits (2; the value's
  // second byte written as well, 0 for most), taken from `word` (raw_word at the block's start, at most 56
  // bits of it a block); with the branch above when it has more (raw_at <= raw_end after it, or it throws).
  const RawCodes& codes = kRawCodes[D];
  constexpr uint32_t fast_bits = kRawBytes == 1 ? 7 : kFastRawBits;
  const auto raw_common = [&](uint32_t s, uint8_t * out, uint64_t & word) __attribute__((always_inline)) {
    const uint32_t n = codes.n[s];
    if (n > fast_bits) [[unlikely]] {
      raw(s, out);
      word = raw_word();
      return;
    }
    const uint32_t z = codes.lead[s] | (uint32_t(word) & codes.mask[s]);
    *out = uint8_t(z);
    if constexpr (kRawBytes == 2) out[stride] = uint8_t(z >> 8);
    word >>= n, raw_at += n;
  };
  // Values in blocks of kStates, then one by one, rotating the states. A block reads at most 8 bytes:
  // started only while at is within the rANS bytes, so that no read leaves the padding.
  uint8_t* out = planes;
  uint8_t* const blocks_end = planes + (values - values % kStates);
  for (; out != blocks_end; out += kStates) {
    if (at > rans_end) break;
    if constexpr (kRawBytes > 0) {  // raw_at may pass raw_end within the block: checked after it
      uint64_t word = raw_word();
      raw_common(step(x0, out), out, word), raw_common(step(x1, out + 1), out + 1, word);
      raw_common(step(x2, out + 2), out + 2, word), raw_common(step(x3, out + 3), out + 3, word);
      if (raw_at > raw_end) fail("residual raw bits end early");
    } else {
      raw(step(x0, out), out), raw(step(x1, out + 1), out + 1);
      raw(step(x2, out + 2), out + 2), raw(step(x3, out + 3), out + 3);
    }
  }
  if (at <= rans_end)
    for (; out != planes + values; ++out) {
      raw(step(x0, out), out);
      const uint32_t t = x0;
      x0 = x1, x1 = x2, x2 = x3, x3 = t;
    }
  if (at > rans_end) fail("residual rANS stream ends early");
  state_[0] = x0, state_[1] = x1, state_[2] = x2, state_[3] = x3;
  rans_at_ = at, raw_bit_at_ = raw_at;
}

void ResidualDecoder::finish() const {
  if (!slots_) return;
  bool states_back = true;
  for (uint32_t x : state_) states_back = states_back && x == kLow;
  // Raw bits: up to the last byte, and none set beyond the last one read.
  const bool bits_left = (raw_bit_at_ + 7) / 8 != raw_bit_end_ / 8 ||
                         (raw_bit_at_ % 8 && bytes_[raw_bit_at_ / 8] >> (raw_bit_at_ % 8));
  if (rans_at_ != rans_end_ || !states_back || bits_left) fail("residual stream holds bytes of no residual");
}

}  // namespace lodstream::package
