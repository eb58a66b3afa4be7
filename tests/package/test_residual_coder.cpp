// The residual coder (package/residual_coder.hpp): streams decode back to the planes put_planes writes,
// mostly-zero residuals cost well under a bit each, paired streams (built-in tables, component 1 in the
// context of component 0) decode back and code pairs of related scale smaller than one table of their own,
// and corrupted or hostile streams are errors, never reads or writes out of bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>

#include "core/error.hpp"
#include "package/byte_planes.hpp"
#include "package/residual_coder.hpp"
#include "package/residual_tables.hpp"
#include "support/expect_error.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// Residuals of `nodes` nodes of `count` values of 3 components, zigzagged, each node's in the order of its
// planes (component by component); residuals of node k below 2^(8 widths[k]).
struct Residuals {
  std::vector<size_t> counts;
  std::vector<uint32_t> widths;
  std::vector<uint64_t> values;  // all nodes, component-major within each
};

Residuals random_residuals(uint32_t seed, double zero_share) {
  std::mt19937_64 rng(seed);
  Residuals r;
  for (uint32_t node = 0; node < 12; ++node) {
    const size_t count = 1 + rng() % 300;
    const uint32_t width = 1 + node % 5;
    r.counts.push_back(count), r.widths.push_back(width);
    for (size_t i = 0; i < 3 * count; ++i) {
      const uint32_t bits = std::uniform_real_distribution<double>(0, 1)(rng) < zero_share
                                ? 0
                                : uint32_t(rng() % (8 * width + 1));
      r.values.push_back(bits == 0 ? 0 : (rng() & ((uint64_t(1) << bits) - 1)) | uint64_t(1) << (bits - 1));
    }
  }
  return r;
}

// The planes of every node of `components` components (its values component-major), as put_planes writes
// them, one after the other.
template <class Count>
std::vector<uint8_t> planes_of(const std::vector<Count>& counts, const std::vector<uint32_t>& widths,
                               const std::vector<uint64_t>& values, uint32_t components) {
  std::vector<uint8_t> out;
  size_t at = 0;
  for (size_t node = 0; node < counts.size(); ++node) {
    const size_t n = counts[node];
    std::vector<uint64_t> records(components * n);
    for (uint32_t a = 0; a < components; ++a)
      for (size_t i = 0; i < n; ++i) records[components * i + a] = values[at + a * n + i];
    put_planes(out, records, components, widths[node]);
    at += components * n;
  }
  return out;
}

// What a ResidualDecoder of `stream` (named `where`; paired: encode_paired_residuals') gives for every node,
// into planes filled with 0xa5 first (every byte must be written over).
template <class Count>
std::vector<uint8_t> decoded_planes_of(std::span<const uint8_t> stream, const std::string& where, bool paired,
                                       const std::vector<Count>& counts, const std::vector<uint32_t>& widths,
                                       uint32_t components) {
  ResidualDecoder decoder(stream, where, paired);
  std::vector<uint8_t> out;
  for (size_t node = 0; node < counts.size(); ++node) {
    const size_t at = out.size();
    out.resize(at + components * counts[node] * widths[node], 0xa5);
    decoder.planes(counts[node], components, widths[node], out.data() + at);
  }
  decoder.finish();
  return out;
}

std::vector<uint8_t> expected_planes(const Residuals& r) {
  return planes_of(r.counts, r.widths, r.values, 3);
}
std::vector<uint8_t> decoded_planes(std::span<const uint8_t> stream, const Residuals& r) {
  return decoded_planes_of(stream, "stream 3", false, r.counts, r.widths, 3);
}

TEST(ResidualCoder, DecodesToThePlanesOfTheResiduals) {
  for (uint32_t seed = 0; seed < 6; ++seed) {
    const Residuals r = random_residuals(seed, seed * 0.15);
    const std::vector<uint8_t> stream = encode_residuals(r.values);
    EXPECT_EQ(decoded_planes(stream, r), expected_planes(r)) << "seed " << seed;
  }
}

// The decoder writes every byte of the planes it is asked for, over whatever they held: a value of raw bits
// writes only its own bytes, the planes above them zeroed first (the page buffer is reused across pages).
TEST(ResidualCoder, WritesEveryByteOfItsPlanesOverOldBytes) {
  for (uint32_t seed = 0; seed < 4; ++seed) {
    const Residuals r = random_residuals(seed + 10, 0.3);
    ResidualDecoder decoder(encode_residuals(r.values), "stream 3");
    std::vector<uint8_t> out;
    for (size_t node = 0; node < r.counts.size(); ++node) {
      const size_t at = out.size(), n = r.counts[node];
      out.resize(at + 3 * n * r.widths[node], 0xa5);
      // Component 0, then components 1 and 2 (the split form's two calls).
      decoder.planes(n, 3, r.widths[node], out.data() + at, 0, 1);
      decoder.planes(n, 3, r.widths[node], out.data() + at, 1, 2);
    }
    decoder.finish();
    EXPECT_EQ(out, expected_planes(r)) << "seed " << seed;
  }
}

TEST(ResidualCoder, OneSymbolAloneAndNoResiduals) {
  const std::vector<uint64_t> zeros(1000, 0);
  const std::vector<uint8_t> stream = encode_residuals(zeros);
  EXPECT_LE(stream.size(), 21u);  // one symbol of probability 1 costs nothing: D, A, its frequency, the
                                  // size and the four states
  std::vector<uint8_t> planes(3000, 7);
  ResidualDecoder decoder(stream, "s");
  decoder.planes(500, 2, 3, planes.data());
  decoder.finish();
  EXPECT_EQ(planes, std::vector<uint8_t>(3000, 0));

  EXPECT_TRUE(encode_residuals({}).empty());
  ResidualDecoder none({}, "s");
  none.planes(0, 3, 1, nullptr);
  none.finish();
  EXPECT_THROW(none.planes(1, 3, 1, planes.data()), Error);
}

TEST(ResidualCoder, EveryDirectWidthTheEncoderPicksDecodes) {
  // Geometric residuals of growing scale, in short and longer streams, and residuals 0, 1, 2^(d-1) + 1 and
  // 2^d - 1 with 2 % of 13 bits (values of raw bits rare: D = d): the encoder's D (the stream's first byte)
  // follows the scale and the table's cost, every D occurs, and each stream decodes back, its values of raw
  // bits included.
  std::set<uint8_t> picked;
  auto check = [&](const Residuals& r, uint32_t scale) {
    const std::vector<uint8_t> stream = encode_residuals(r.values);
    picked.insert(stream[0]);
    EXPECT_EQ(decoded_planes(stream, r), expected_planes(r)) << "scale " << scale;
  };
  for (size_t count : {100, 1000})
    for (uint32_t scale = 0; scale < 12; ++scale) {
      std::mt19937_64 rng(scale);
      std::geometric_distribution<uint64_t> geometric(1.0 / (1 + (uint64_t(1) << scale)));
      Residuals r;
      r.counts = {count}, r.widths = {5};
      for (size_t i = 0; i < 3 * count; ++i) r.values.push_back(geometric(rng) & ((uint64_t(1) << 40) - 1));
      check(r, scale);
    }
  for (uint32_t d = 1; d <= 6; ++d) {
    std::mt19937_64 rng(d);
    Residuals r;
    r.counts = {300}, r.widths = {2};
    const uint64_t top = (uint64_t(1) << d) - 1, middle = (uint64_t(1) << (d - 1)) | 1;
    for (size_t i = 0; i < 900; ++i) {
      const uint32_t x = uint32_t(rng() % 100);
      r.values.push_back(x < 2 ? 4096 + rng() % 4096 : x < 50 ? 0 : x < 70 ? 1 : x < 85 ? top : middle);
    }
    check(r, 100 + d);
  }
  EXPECT_EQ(picked, (std::set<uint8_t>{1, 2, 3, 4, 5, 6}));
}

// The decoder takes a stream's values of raw bits with a branch, or without one in one byte or in two
// (residual_coder.cpp's raw_bytes_of, by their share in the stream's table): every way decodes to the planes,
// values of more raw bits than the way takes included, in nodes of 1 to 3 bytes and odd counts (values one
// by one after the blocks of 4), and a stream cut short is an error in each (its raw bits: one that says so).
// Values: small (below 2^3) but for a share `raw` of values of 6 to 7 raw bits, `wide` of 8 to 14 and `huge`
// of 15 to 22 (where they fit).
TEST(ResidualCoder, ValuesOfRawBitsDecodeAlikeWhicheverWayTheDecoderTakes) {
  struct Mix {
    double raw, wide, huge;
  };
  // A branch (0.5 %, 3 %), one byte (10 %, 40 %), two bytes (wide 3 %, 10 %), either with huge values.
  const Mix mixes[] = {{0.005, 0, 0},  {0.03, 0.002, 0}, {0.1, 0, 0},        {0.4, 0.003, 0},
                       {0.1, 0.03, 0}, {0.3, 0.1, 0},    {0.3, 0.004, 0.01}, {0.3, 0.1, 0.02}};
  uint32_t seed = 0;
  for (const Mix& mix : mixes)
    for (uint32_t width = 1; width <= 3; ++width) {
      std::mt19937_64 rng(++seed);
      std::uniform_real_distribution<double> u(0, 1);
      auto draw = [&](uint32_t low, uint32_t high) {  // a value of bit length low + 1 .. high
        const uint32_t k = low + 1 + uint32_t(rng() % (high - low));
        return uint64_t(1) << (k - 1) | (rng() & ((uint64_t(1) << (k - 1)) - 1));
      };
      Residuals r;
      for (uint32_t node = 0; node < 6; ++node) {
        const size_t count = 301 + rng() % 700;
        r.counts.push_back(count), r.widths.push_back(width);
        for (size_t i = 0; i < 3 * count; ++i) {
          const double x = u(rng);
          r.values.push_back(x < mix.huge && width >= 3              ? draw(15, 23)
                             : x < mix.huge + mix.wide && width >= 2 ? draw(8, 15)
                             : x < mix.huge + mix.wide + mix.raw     ? draw(6, 8)
                                                                     : rng() % 8);
        }
      }
      const std::vector<uint8_t> stream = encode_residuals(r.values);
      EXPECT_EQ(decoded_planes(stream, r), expected_planes(r)) << "mix " << seed / 3 << " width " << width;
      // Cut in its raw bits (the stream's last bytes), then in its rANS bytes.
      for (size_t cut : {1, 9})
        expect_error_naming("stream 3: residual raw bits end early", "raw bits cut", [&] {
          decoded_planes(std::vector<uint8_t>(stream.begin(), stream.end() - cut), r);
        });
      expect_error_naming("stream 3", "cut in half", [&] {
        decoded_planes(std::vector<uint8_t>(stream.begin(), stream.begin() + stream.size() / 2), r);
      });
    }
}

// Where values of raw bits are common whatever D (geometric residuals of scale 2^5 to 2^9: most have raw
// bits even with D = 6), the decoder takes them without a branch at any D, and the encoder takes the
// smallest stream rather than the largest D within 0.5 % of it (its estimate: within 0.2 % and 4 bytes of
// the smallest of the six D's streams, and smaller than D = 6's); each decodes back.
TEST(ResidualCoder, WhereRawBitsAreCommonTheSmallestStreamIsTaken) {
  for (size_t count : {300, 1000, 3000})
    for (uint32_t scale = 5; scale < 10; ++scale) {
      std::mt19937_64 rng(scale);
      std::geometric_distribution<uint64_t> geometric(1.0 / (1 + (uint64_t(1) << scale)));
      Residuals r;
      r.counts = {count}, r.widths = {3};
      for (size_t i = 0; i < 3 * count; ++i) r.values.push_back(geometric(rng));
      const std::vector<uint8_t> chosen = encode_residuals(r.values);
      size_t smallest = chosen.size();
      for (uint32_t D = 1; D <= 6; ++D) {
        const std::vector<uint8_t> stream = encode_residuals(r.values, D);
        ASSERT_EQ(stream[0], D);
        EXPECT_EQ(decoded_planes(stream, r), expected_planes(r)) << "D " << D;
        smallest = std::min(smallest, stream.size());
        if (D == 6) {
          EXPECT_LT(chosen.size(), stream.size()) << count << " " << scale;
        }
      }
      EXPECT_LE(double(chosen.size()), 1.002 * double(smallest) + 4) << count << " " << scale;
      EXPECT_EQ(decoded_planes(chosen, r), expected_planes(r));
    }
  EXPECT_THROW(encode_residuals(std::vector<uint64_t>{1}, 0), Error);
  EXPECT_THROW(encode_residuals(std::vector<uint64_t>{1}, 7), Error);
}

TEST(ResidualCoder, MostlyZeroResidualsTakeWellUnderABitEach) {
  std::mt19937 rng(1);
  std::vector<uint64_t> values(30000);
  for (uint64_t& v : values) v = rng() % 20 == 0 ? 1 + rng() % 3 : 0;  // 5 % small, the rest 0
  // H = 0.286 + 0.05 log2(3) bits per value (about 0.37): zstd's Huffman stage takes at least 1 bit a byte.
  const size_t bytes = encode_residuals(values).size();
  EXPECT_LT(bytes, values.size() * 0.40 / 8);
  EXPECT_GT(bytes, values.size() * 0.33 / 8);
}

TEST(ResidualCoder, CorruptedStreamsAreErrorsNeverOutOfBounds) {
  const Residuals r = random_residuals(9, 0.5);
  const std::vector<uint8_t> good = encode_residuals(r.values);
  const std::vector<uint8_t> planes = expected_planes(r);
  auto expect_error = [&](const std::vector<uint8_t>& stream, const char* what) {
    expect_error_naming("stream 3", what, [&] { decoded_planes(stream, r); });
  };
  // Every proper prefix and a byte too many: the symbols or bits run out, or the states do not end at
  // their start.
  for (size_t n = 0; n < good.size(); n += 1 + n / 64)
    expect_error(std::vector<uint8_t>(good.begin(), good.begin() + n), "a prefix");
  std::vector<uint8_t> bad = good;
  bad.push_back(0);
  expect_error(bad, "a byte too many");
  for (uint8_t D : {0, 8, 255}) {
    bad = good;
    bad[0] = D;  // direct bits outside 1..7
    expect_error(bad, "direct bits");
  }
  bad = good;
  bad[1] = uint8_t((1u << good[0]) + 2 * (40 - good[0]) + 1);  // more symbols than 40-bit residuals have
  expect_error(bad, "table size");
  bad = good;
  bad[2] ^= 1;  // the first frequency: the table no longer adds up to 2^12
  expect_error(bad, "table sum");
  bad = good;
  bad.insert(bad.begin() + 2, {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x7f});  // a huge frequency
  expect_error(bad, "huge frequency");
  // A huge rANS size, and a first state below the states' range, in a stream of one symbol.
  const std::vector<uint8_t> zeros = encode_residuals(std::vector<uint64_t>(100, 0));
  ASSERT_EQ(zeros.size(), 21u);  // D, A = 1, frequency 4096 (2 bytes), size 16, four states
  bad = zeros;
  bad[4] = 0xff, bad.insert(bad.begin() + 5, {0xff, 0xff, 0xff, 0x7f});
  EXPECT_THROW(ResidualDecoder(bad, "s"), Error);
  bad = zeros;
  bad[5] = bad[6] = bad[7] = bad[8] = 0;
  EXPECT_THROW(ResidualDecoder(bad, "s"), Error);
  // A residual of 9 bits in a node of 1-byte planes.
  const std::vector<uint64_t> wide = {0, 300, 1};
  std::vector<uint8_t> out(3);
  ResidualDecoder decoder(encode_residuals(wide), "stream 3");
  EXPECT_THROW(decoder.planes(1, 3, 1, out.data()), Error);

  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    bad = good;
    for (int k = 0; k < 1 + i % 3; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    try {
      EXPECT_EQ(decoded_planes(bad, r).size(), planes.size());  // wrong values, right size: possible
    } catch (const Error&) {
    }
  }
}

// Pairs as a page's normal residuals hold them (node by node, component 0 then component 1), drawn from the
// built-in set `set` (residual_tables.hpp): component 0 from its first context's table, component 1 from the
// table of its vertex's component 0's context, a value of a raw-bits symbol uniform among its bit length's;
// nodes of 1- and 2-byte planes (values that do not fit are drawn again).
struct Pairs {
  std::vector<uint32_t> counts, widths;
  std::vector<uint64_t> values;
};
Pairs drawn_pairs(uint32_t seed, uint32_t set) {
  using namespace residual_tables;
  std::mt19937_64 rng(seed);
  auto draw = [&](uint32_t context, uint32_t width) {
    const uint16_t* f = kFrequencies[set][context];
    for (;;) {
      uint32_t slot = uint32_t(rng() % 4096), s = 0;
      while (slot >= f[s]) slot -= f[s++];
      if (s < (1u << kDirectBits)) return uint64_t(s);
      const uint32_t k = s - (1u << kDirectBits) + kDirectBits + 1;  // the bit length
      if (k > 8 * width) continue;
      return uint64_t(1) << (k - 1) | (rng() & ((uint64_t(1) << (k - 1)) - 1));
    }
  };
  Pairs r;
  for (uint32_t node = 0; node < 10; ++node) {
    const uint32_t count = 1 + uint32_t(rng() % 400), width = 1 + node % 2;
    r.counts.push_back(count), r.widths.push_back(width);
    const size_t at = r.values.size();
    for (uint32_t i = 0; i < count; ++i) r.values.push_back(draw(kFirstContext, width));
    for (uint32_t i = 0; i < count; ++i)
      r.values.push_back(draw(context_of(uint8_t(r.values[at + i])), width));
  }
  return r;
}

std::vector<uint8_t> expected_pair_planes(const Pairs& r) {
  return planes_of(r.counts, r.widths, r.values, 2);
}
std::vector<uint8_t> decoded_pair_planes(std::span<const uint8_t> stream, const Pairs& r) {
  return decoded_planes_of(stream, "stream 5", true, r.counts, r.widths, 2);
}

// The built-in tables are what residual_tables.hpp says: each adds up to 2^12 and codes every symbol.
TEST(ResidualCoder, BuiltInTablesAddUpToTheScaleAndCodeEverySymbol) {
  using namespace residual_tables;
  for (uint32_t set = 0; set < kSets; ++set)
    for (uint32_t c = 0; c < kContexts; ++c) {
      uint32_t sum = 0;
      for (uint32_t s = 0; s < kSymbols; ++s) {
        EXPECT_GE(kFrequencies[set][c][s], 1u) << set << " " << c << " " << s;
        sum += kFrequencies[set][c][s];
      }
      EXPECT_EQ(sum, 4096u) << set << " " << c;
    }
}

TEST(ResidualCoder, PairedStreamsDecodeToThePlanesAndCodeRelatedPairsSmaller) {
  for (uint32_t set = 0; set < residual_tables::kSets; ++set) {
    const Pairs r = drawn_pairs(set, set);
    const std::vector<uint8_t> paired = encode_paired_residuals(r.values, r.counts);
    EXPECT_EQ(paired[0], set);  // the set the values follow codes them shortest
    EXPECT_EQ(decoded_pair_planes(paired, r), expected_pair_planes(r)) << "set " << set;
    // Component 1's table follows component 0 (its context), which one table of the stream's own cannot.
    EXPECT_LT(double(paired.size()), 0.97 * double(encode_residuals(r.values).size())) << "set " << set;
  }
  EXPECT_TRUE(encode_paired_residuals({}, {}).empty());
  const std::vector<uint64_t> three = {1, 2, 3};
  EXPECT_THROW(encode_paired_residuals(three, std::vector<uint32_t>{1}), Error);  // counts short of values
  EXPECT_THROW(encode_paired_residuals(three, std::vector<uint32_t>{2}), Error);  // counts past them
}

TEST(ResidualCoder, CorruptedPairedStreamsAreErrorsNeverOutOfBounds) {
  const Pairs r = drawn_pairs(7, 3);
  const std::vector<uint8_t> good = encode_paired_residuals(r.values, r.counts);
  auto expect_error = [&](const std::vector<uint8_t>& stream, const char* what) {
    expect_error_naming("stream 5", what, [&] { decoded_pair_planes(stream, r); });
  };
  for (size_t n = 0; n < good.size(); n += 1 + n / 64)
    expect_error(std::vector<uint8_t>(good.begin(), good.begin() + n), "a prefix");
  std::vector<uint8_t> bad = good;
  bad.push_back(0);
  expect_error(bad, "a byte too many");
  for (uint32_t set : {residual_tables::kSets, 255u}) {
    bad = good;
    bad[0] = uint8_t(set);
    expect_error(bad, "table set");
  }
  // A paired stream is read as pairs only: other components are an error.
  std::vector<uint8_t> out(3 * r.widths[0] * r.counts[0]);
  ResidualDecoder decoder(good, "stream 5", true);
  EXPECT_THROW(decoder.planes(r.counts[0], 3, r.widths[0], out.data()), Error);
  EXPECT_THROW(decoder.planes(r.counts[0], 2, r.widths[0], out.data(), 1, 1), Error);

  const size_t size = expected_pair_planes(r).size();
  std::mt19937 rng(5);
  for (int i = 0; i < 2000; ++i) {
    bad = good;
    for (int k = 0; k < 1 + i % 3; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    try {
      EXPECT_EQ(decoded_pair_planes(bad, r).size(), size);  // wrong values, right size: possible
    } catch (const Error&) {
    }
  }
}

}  // namespace
}  // namespace lodstream::test
