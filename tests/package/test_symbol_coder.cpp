// The traversal symbol coder (package/symbol_coder.hpp): streams decode back to the symbols, in pieces of
// any size; symbols that follow each other in a pattern, and cluster codes that recur, cost far under a bit
// each; bytes that are no traversal symbols are refused; corrupted or hostile streams are errors, never reads
// out of bounds.
#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "package/symbol_coder.hpp"
#include "package/traversal_connectivity.hpp"
#include "support/expect_error.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// `count` symbols of a Markov chain: each kind depends on the previous one; a share `tagged` carries a
// cluster code 1..31 (mostly a few of them).
std::vector<uint8_t> random_symbols(uint32_t seed, size_t count, double tagged) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<uint8_t> out;
  uint32_t kind = uint32_t(kVertex);
  for (size_t i = 0; i < count; ++i) {
    const double p = u(rng);
    const uint32_t after_vertex = p < 0.7 ? kRight : p < 0.9 ? kBoundary : kSplit;
    const uint32_t other = p < 0.8 ? uint32_t(kVertex) : uint32_t(rng() % 6);
    kind = kind == kVertex ? after_vertex : other;
    const uint32_t code = u(rng) < tagged ? (rng() % 4 == 0 ? 1 + rng() % 31 : 1 + rng() % 3) : 0;
    out.push_back(uint8_t(kind | code << 3));
  }
  return out;
}

// Decodes `stream` in pieces of `pieces` sizes (adding up to the symbols), then checks its end.
std::vector<uint8_t> decoded(std::span<const uint8_t> stream, std::span<const size_t> pieces) {
  SymbolDecoder decoder(stream, "stream 5");
  std::vector<uint8_t> out;
  for (size_t n : pieces) {
    const size_t at = out.size();
    out.resize(at + n);
    decoder.symbols(n, out.data() + at);
  }
  decoder.finish();
  return out;
}

TEST(SymbolCoder, DecodesToTheSymbolsInPiecesOfAnySize) {
  for (uint32_t seed = 0; seed < 6; ++seed) {
    const std::vector<uint8_t> symbols = random_symbols(seed, 100 + 3000 * seed, 0.02 * seed);
    const std::optional<std::vector<uint8_t>> stream = encode_symbols(symbols);
    ASSERT_TRUE(stream);
    std::vector<size_t> pieces;
    std::mt19937 rng(seed);
    for (size_t left = symbols.size(); left > 0;)
      pieces.push_back(std::min<size_t>(left, rng() % 200)), left -= pieces.back();
    EXPECT_EQ(decoded(*stream, pieces), symbols) << "seed " << seed;
  }
}

TEST(SymbolCoder, APatternCostsFarUnderABitASymbol) {
  // kVertex, kRight alternating (a strip, as at level 0 of a regular mesh): each predicts the next one
  // exactly; zstd's Huffman stage would take a bit a symbol before its matches, an order-0 coder one bit.
  std::vector<uint8_t> strip;
  for (int i = 0; i < 20000; ++i) strip.push_back(uint8_t(i % 2 ? kRight : kVertex));
  const std::optional<std::vector<uint8_t>> stream = encode_symbols(strip);
  ASSERT_TRUE(stream);
  EXPECT_LT(stream->size(), 60u);  // the tables, the size and the two states: the symbols cost nothing
  const size_t all[] = {strip.size()};
  EXPECT_EQ(decoded(*stream, all), strip);

  // A context followed by two kinds equally often costs a bit a symbol of it, the others nothing.
  std::vector<uint8_t> coin;
  std::mt19937 rng(4);
  for (int i = 0; i < 40000; ++i) coin.push_back(uint8_t(i % 2 ? (rng() % 2 ? kLeft : kRight) : kVertex));
  const size_t bytes = encode_symbols(coin)->size();
  EXPECT_GT(bytes, 20000 / 8 * 0.99);
  EXPECT_LT(bytes, 20000 / 8 * 1.03);
}

TEST(SymbolCoder, ACodeThatRecursCostsFarUnderItsShareOfTheCodes) {
  // Every symbol tagged, the code changing every 500 symbols through all 31: each code takes a 31st of the
  // stream, about 5 bits a code to an order-0 table of codes; by recency, a code that was just coded again
  // has rank 0 and costs about 0.18 bit (226 of the table's 256 slots: the 30 changes take one each).
  std::vector<uint8_t> runs;
  for (uint32_t i = 0; i < 31 * 500; ++i) runs.push_back(uint8_t(kVertex | (1 + (i / 500) % 31) << 3));
  const std::optional<std::vector<uint8_t>> stream = encode_symbols(runs);
  ASSERT_TRUE(stream);
  EXPECT_LT(stream->size(), runs.size() / 8 / 4);  // under a quarter of a bit a symbol
  const size_t all[] = {runs.size()};
  EXPECT_EQ(decoded(*stream, all), runs);
}

TEST(SymbolCoder, OneSymbolAloneNoSymbolsAndNoTraversalSymbols) {
  const std::vector<uint8_t> same(1000, uint8_t(kBoundary | 7 << 3));
  const std::optional<std::vector<uint8_t>> stream = encode_symbols(same);
  ASSERT_TRUE(stream);
  const size_t all[] = {1000};
  EXPECT_EQ(decoded(*stream, all), same);
  SymbolDecoder none({}, "s");
  none.symbols(0, nullptr);
  none.finish();
  uint8_t out;
  EXPECT_THROW(none.symbols(1, &out), Error);
  // Kinds 6 and 7 are no traversal symbols (the connectivity bytes of a node in codec 2's form).
  EXPECT_FALSE(encode_symbols(std::vector<uint8_t>{kVertex, 6}));
  EXPECT_FALSE(encode_symbols(std::vector<uint8_t>{0xff}));
}

TEST(SymbolCoder, CorruptedStreamsAreErrorsNeverOutOfBounds) {
  const std::vector<uint8_t> symbols = random_symbols(9, 3000, 0.1);
  const std::vector<uint8_t> good = *encode_symbols(symbols);
  const size_t all[] = {symbols.size()};
  auto expect_error = [&](const std::vector<uint8_t>& stream, const char* what) {
    expect_error_naming("stream 5", what, [&] { decoded(stream, all); });
  };
  // Every proper prefix and a byte too many: the tables, the size or the rANS bytes run out, or the
  // states do not end at their start.
  for (size_t n = 0; n < good.size(); n += 1 + n / 64)
    expect_error(std::vector<uint8_t>(good.begin(), good.begin() + n), "a prefix");
  std::vector<uint8_t> bad = good;
  bad.push_back(0);
  expect_error(bad, "a byte too many");
  bad = good;
  bad[1] |= 0x10;  // context 0's mask: class 12 is none
  expect_error(bad, "unknown class");
  bad = good;
  bad.insert(bad.begin() + 2, {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x7f});  // a huge frequency
  expect_error(bad, "huge frequency");
  bad = good;
  bad[2] = 0;  // a frequency of 0 for a class the mask names
  expect_error(bad, "zero frequency");
  // More symbols asked for than the stream holds.
  const size_t more[] = {symbols.size() + 10};
  EXPECT_THROW(decoded(good, more), Error);
  // A huge rANS size and a first state below the states' range, in a stream of one symbol.
  const std::vector<uint8_t> one = *encode_symbols(std::vector<uint8_t>(100, kVertex));
  ASSERT_EQ(one.size(), 12 * 2 + 4 + 1 + 8u);  // 13 masks, the size, two states
  bad = one;
  bad[28] = 0xff, bad.insert(bad.begin() + 29, {0xff, 0xff, 0xff, 0x7f});
  EXPECT_THROW(SymbolDecoder(bad, "s"), Error);
  bad = one;
  bad[29] = bad[30] = bad[31] = bad[32] = 0;
  EXPECT_THROW(SymbolDecoder(bad, "s"), Error);

  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    bad = good;
    for (int k = 0; k < 1 + i % 3; ++k) bad[rng() % bad.size()] = uint8_t(rng());
    try {
      EXPECT_EQ(decoded(bad, all).size(), symbols.size());  // other symbols, right count: possible
    } catch (const Error&) {
    }
  }
}

}  // namespace
}  // namespace lodstream::test
