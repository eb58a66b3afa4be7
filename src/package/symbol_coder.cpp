#include "package/symbol_coder.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/rans.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kScaleBits = 8, kScale = 1u << kScaleBits;
constexpr uint32_t kKinds = 6, kClasses = 2 * kKinds, kClusterCodes = 31;
constexpr uint32_t kTables = kClasses + 1, kCodeTable = kClasses;  // the ranks' table comes last
constexpr uint32_t kStates = 2;
// The alphabet of table t.
constexpr uint32_t alphabet(uint32_t t) {
  return t == kCodeTable ? kClusterCodes : kClasses;
}

// Move-to-front (Bentley, Sleator, Tarjan & Wei 1986, "A locally adaptive data compression scheme", CACM
// 29(4)) over the recent cluster codes (symbol_coder.hpp): the code of rank r, which then moves to the front.
// Cost: a few instructions for r < 16 (most ranks: the codes of bytes 0..r of one or two little-endian
// words move up a byte, without a loop), a memmove above. Measured (`bench decode --runs 1` under
// callgrind, read_page): a byte loop for every rank from 8 took elephant_1m 257.20 M instructions,
// refined_elephant 15.50 M (~180 a rank above 16, 14,172 of them in elephant_1m), these 255.92 / 15.37.
uint32_t to_front(RecentClusterCodes& recent, uint32_t r) {
  const uint8_t code = recent[r];
  if (r < 8) [[likely]] {
    uint64_t word;
    std::memcpy(&word, recent.data(), 8);
    const uint64_t moved = ~uint64_t(0) >> (56 - 8 * r);  // bytes 0..r
    word = (word & ~moved) | ((word << 8) & moved) | code;
    std::memcpy(recent.data(), &word, 8);
    return code;
  }
  if (r < 16) {
    uint64_t word[2];
    std::memcpy(word, recent.data(), 16);
    const uint64_t moved = ~uint64_t(0) >> (56 - 8 * (r - 8));  // bytes 8..r
    word[1] = (word[1] & ~moved) | (((word[1] << 8) | (word[0] >> 56)) & moved);
    word[0] = (word[0] << 8) | code;
    std::memcpy(recent.data(), word, 16);
    return code;
  }
  std::memmove(recent.data() + 1, recent.data(), r);
  recent[0] = code;
  return code;
}

}  // namespace

std::optional<std::vector<uint8_t>> encode_symbols(std::span<const uint8_t> symbols) {
  std::array<std::array<uint32_t, kClusterCodes>, kTables> counts{};
  std::vector<uint8_t> ranks;  // of the cluster codes, in order
  RecentClusterCodes recent = kFirstClusterCodes;
  uint32_t context = 0;
  for (const uint8_t b : symbols) {
    const uint32_t kind = b & 7, code = b >> 3;
    if (kind >= kKinds) return std::nullopt;
    const uint32_t s = kind + (code ? kKinds : 0);
    ++counts[context][s];
    if (code) {
      const uint32_t r = uint32_t(std::find(recent.begin(), recent.end(), code) - recent.begin());
      to_front(recent, r);
      ranks.push_back(uint8_t(r)), ++counts[kCodeTable][r];
    }
    context = s;
  }
  std::array<std::array<uint32_t, kClusterCodes>, kTables> f{}, start{};
  ByteWriter w;
  for (uint32_t t = 0; t < kTables; ++t) {
    const std::span<const uint32_t> c = std::span(counts[t]).first(alphabet(t));
    uint64_t total = 0, mask = 0;
    for (uint32_t s = 0; s < c.size(); ++s) total += c[s], mask |= uint64_t(c[s] > 0) << s;
    if (t == kCodeTable)
      w.u32(uint32_t(mask));
    else
      w.u16(uint16_t(mask));
    if (!total) continue;
    rans::normalize(c, total, kScaleBits, std::span(f[t]).first(c.size()));
    uint32_t last = 0;
    for (uint32_t s = 0; s < c.size(); ++s)
      if (f[t][s]) last = s;
    for (uint32_t s = 0, at = 0; s < c.size(); at += f[t][s++]) {
      start[t][s] = at;
      if (f[t][s] && s != last) w.varint(f[t][s]);
    }
  }
  // The coding steps in order (start and frequency), then rANS last step first.
  std::vector<std::array<uint32_t, 2>> steps;
  steps.reserve(symbols.size() + symbols.size() / 8);
  context = 0;
  const uint8_t* rank = ranks.data();
  for (const uint8_t b : symbols) {
    const uint32_t code = b >> 3, s = (b & 7) + (code ? kKinds : 0);
    steps.push_back({start[context][s], f[context][s]});
    if (code) steps.push_back({start[kCodeTable][*rank], f[kCodeTable][*rank]}), ++rank;
    context = s;
  }
  std::vector<uint8_t> reversed;
  uint32_t state[kStates] = {rans::kLow, rans::kLow};
  for (size_t i = steps.size(); i-- > 0;)
    rans::encode(state[i % kStates], steps[i][0], steps[i][1], kScaleBits, reversed);
  w.varint(4 * kStates + reversed.size());
  for (const uint32_t x : state) w.u32(x);
  w.bytes.insert(w.bytes.end(), reversed.rbegin(), reversed.rend());
  return std::move(w.bytes);
}

SymbolDecoder::SymbolDecoder(std::span<const uint8_t> stream, const std::string& where) : where_(where) {
  if (stream.empty()) return;  // no symbols
  ByteReader r(stream, where);
  slot_ = std::make_unique_for_overwrite<uint32_t[]>(size_t(kTables) * kScale);
  symbol_ = std::make_unique_for_overwrite<uint8_t[]>(size_t(kTables) * kScale);
  for (uint32_t t = 0; t < kTables; ++t) {
    const uint32_t A = alphabet(t);
    const uint32_t mask = t == kCodeTable ? r.u32() : r.u16();
    if (mask >> A) r.fail("symbol table of an unknown symbol");
    uint32_t* slots = slot_.get() + size_t(t) * kScale;
    uint8_t* symbols = symbol_.get() + size_t(t) * kScale;
    if (!mask) {
      std::fill_n(slots, kScale, 0);
      std::fill_n(symbols, kScale, 0);
      continue;
    }
    const uint32_t last = 31 - uint32_t(__builtin_clz(mask));
    uint32_t sum = 0;
    for (uint32_t s = 0; s <= last; ++s) {
      if (!(mask >> s & 1)) continue;
      uint64_t f = kScale - sum;  // the last takes the rest
      if (s != last) {
        f = r.varint();
        if (f == 0 || f >= kScale - sum) r.fail("symbol frequencies add up past the scale");
      }
      rans::fill_slots(slots + sum, uint32_t(f), uint32_t(f), 16);
      std::memset(symbols + sum, int(s), f);
      sum += uint32_t(f);
    }
  }
  const uint64_t size = r.varint();
  if (size < 4 * kStates || size != r.remaining()) r.fail("symbol rANS stream not the stream's rest");
  const std::span<const uint8_t> rest = r.bytes(r.remaining(), "symbol rANS stream");
  rans::copy_padded(rest, bytes_);
  rans_end_ = size;
  for (uint32_t k = 0; k < kStates; ++k) {
    std::memcpy(&state_[k], bytes_.data() + 4 * k, 4);
    if (state_[k] < rans::kLow) fail("invalid symbol rANS state");
  }
  rans_at_ = 4 * kStates;
}

void SymbolDecoder::fail(const char* what) const {
  throw Error(where_ + ": " + what);
}

void SymbolDecoder::symbols(size_t count, uint8_t* out) {
  if (count == 0) return;
  if (!slot_) fail("symbols past the symbol stream's end");
  const uint32_t* slots = slot_.get();
  const uint8_t* symbol_of = symbol_.get();
  const uint8_t* bytes = bytes_.data();
  size_t at = rans_at_;
  const size_t rans_end = rans_end_;
  uint32_t x0 = state_[0], x1 = state_[1], context = context_;
  RecentClusterCodes recent = recent_;  // a local: the loop's stores to `out` cannot alias it
  // One step (rANS, Duda 2013, eq. 9: D(x) = (s, f_s floor(x / 2^8) + x mod 2^8 - start_s), s the symbol
  // of slot x mod 2^8 of `table`), then x read back up to kLow from the next 2 rANS bytes; the states
  // alternate.
  const auto step = [&](uint32_t & x, uint32_t table) __attribute__((always_inline)) {
    const size_t slot = table * kScale + (x & (kScale - 1));
    x = rans::step(x, slots, slot, kScaleBits);
    uint16_t next;
    std::memcpy(&next, bytes + at, 2);
    rans::renormalize(x, at, next);
    return uint32_t(symbol_of[slot]);
  };
  // A symbol whose class steps state x (the next step's); a tagged symbol's rank steps y, then the two swap
  // names, so that x names the next step's state again. A class of a table that never occurs decodes as
  // class 0 (its slots are 0).
  const auto symbol = [&](uint32_t & x, uint32_t & y) __attribute__((always_inline)) {
    const uint32_t s = step(x, context);
    uint32_t byte = s;
    if (s >= kKinds) [[unlikely]] {
      byte = (s - kKinds) | to_front(recent, step(y, kCodeTable)) << 3;
      std::swap(x, y);
    }
    context = s;  // below kClasses: the tables hold no other classes
    return uint8_t(byte);
  };
  // Two symbols a step, the first on x0, the second on x1 (no moves between the states): they read at most
  // 8 bytes, so a pair starts only while at is within the rANS bytes, and no read leaves the padding.
  uint8_t* const pairs_end = out + (count - count % 2);
  for (; out != pairs_end; out += 2) {
    if (at > rans_end) fail("symbol rANS stream ends early");
    out[0] = symbol(x0, x1), out[1] = symbol(x1, x0);
  }
  if (count % 2) {
    if (at > rans_end) fail("symbol rANS stream ends early");
    *out = symbol(x0, x1);
    std::swap(x0, x1);  // x1 steps next
  }
  if (at > rans_end) fail("symbol rANS stream ends early");
  state_[0] = x0, state_[1] = x1, context_ = context, recent_ = recent;
  rans_at_ = at;
}

void SymbolDecoder::finish() const {
  if (!slot_) return;
  if (rans_at_ != rans_end_ || state_[0] != rans::kLow || state_[1] != rans::kLow)
    fail("symbol stream holds bytes of no symbol");
}

}  // namespace lodstream::package
