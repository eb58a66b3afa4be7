// Learns the traversal symbols' fixed rANS tables (src/package/traversal_tables.hpp) from baked packages and
// prints src/package/traversal_tables.cpp. Usage: bench_learn_traversal_tables PACKAGE.lods... (the bakes of
// horse and motorBike: never the meshes the package is measured on). Each codec-3 record of every package is
// decoded and its triangles traversed again (encode_traversal on the decoded order, the traversal the
// writer stores up to where a record's first triangle lies), counting each gate's class by context and
// each tagged class's cluster rank. A context's frequencies: its counts plus kPrior pseudo-counts spread as
// the same gate context without the previous class, plus half a count a class; normalized to 2^12 with at
// least 1 a class (rans::normalize). On stderr, per package: its gates at level 0 and above, and the bits a
// gate they take under the tables built in (their cost before and after a new learning). Cost: a decode
// and an encode of every record.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/node_header.hpp"
#include "package/rans.hpp"
#include "package/reader.hpp"
#include "package/traversal_connectivity.hpp"
#include "package/traversal_tables.hpp"

using namespace lodstream;
using namespace lodstream::package;

namespace {

constexpr double kPrior = 4;
constexpr uint8_t kTraversalFormat = 2;  // traversal_codec.cpp: a traversal node's format byte

// The frequencies (adding up to 2^12, each >= 1) of `counts` smoothed by `prior` (pseudo-counts that add up
// to `weight`, each class also 0.5).
std::vector<uint32_t> frequencies(const std::vector<double>& counts, const std::vector<double>& prior,
                                  double weight) {
  double prior_total = 0;
  for (double p : prior) prior_total += p;
  std::vector<uint32_t> scaled(counts.size());
  uint64_t total = 0;
  for (size_t s = 0; s < counts.size(); ++s) {
    const double p = prior_total > 0 ? prior[s] / prior_total : 1.0 / double(counts.size());
    scaled[s] = uint32_t(std::lround(64 * (counts[s] + weight * p + 0.5)));  // in 1/64 counts
    total += scaled[s];
  }
  std::vector<uint32_t> f(counts.size());
  rans::normalize(scaled, total, kTraversalScaleBits, f);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s PACKAGE.lods...\n", argv[0]);
    return 2;
  }
  std::vector<std::vector<double>> counts(kTraversalContexts, std::vector<double>(kTraversalClasses));
  std::vector<double> ranks(kClusterRanks);
  size_t records = 0, gates = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      PackageReader reader = PackageReader::open(argv[i]);
      double bits[2] = {0, 0};  // under the built-in tables: level 0, above
      size_t level_gates[2] = {0, 0};
      std::set<std::array<uint32_t, 2>> seen;  // records by page and offset
      std::map<uint32_t, std::vector<uint8_t>> pages;
      for (uint32_t id = 0; id < reader.node_count(); ++id) {
        const NodeRecord n = reader.node(id);
        if (n.encoding != NodeEncoding::codec || !seen.insert({n.page, n.offset}).second) continue;
        if (!pages.count(n.page)) pages[n.page] = reader.read_page(n.page);
        const std::span<const uint8_t> bytes = reader.node_bytes(id, pages[n.page]);
        if (bytes.empty() || bytes[0] != kTraversalFormat) continue;  // codec 2's bytes: no traversal
        ByteReader r(bytes, "record");
        const NodeHeader header = NodeHeader::read(r, kTraversalFormat, 0xff, bytes.size());
        const Representation& rep = reader.scene().representations[n.representation];
        const DecodedNode decoded = reader.codec().decode(bytes, rep.grid, "record");
        const TraversalCode code =
            encode_traversal(decoded.mesh.indices, uint32_t(decoded.mesh.positions.size()), header.shift == 0,
                             decoded.cluster_triangles);
        for (const TraversalStep& s : code.steps) {
          ++counts[s.context][s.symbol_class];
          const uint16_t* row = kTraversalClassStarts[s.context];
          double p = double(row[s.symbol_class + 1] - row[s.symbol_class]) / 4096;
          if (s.symbol_class >= kTraversalClasses / 2)
            ++ranks[s.rank], p *= double(kClusterRankFrequencies[s.rank]) / 4096;
          bits[header.shift != 0] -= std::log2(p);
        }
        level_gates[header.shift != 0] += code.steps.size();
        ++records, gates += code.steps.size();
      }
      std::fprintf(stderr, "%s: level 0 %zu gates %.3f bits a gate, above %zu gates %.3f\n",
                   std::filesystem::path(argv[i]).filename().c_str(), level_gates[0],
                   bits[0] / double(level_gates[0]), level_gates[1], bits[1] / double(level_gates[1]));
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  std::printf("// Generated by bench/learn_traversal_tables.cpp from %zu records, %zu gates (", records,
              gates);
  for (int i = 1; i < argc; ++i)
    std::printf("%s%s", i > 1 ? ", " : "", std::filesystem::path(argv[i]).filename().c_str());
  std::printf(
      "): do not edit.\n#include \"package/traversal_tables.hpp\"\n\nnamespace lodstream::package {\n\n");
  std::printf("alignas(64) const uint16_t kTraversalClassStarts[kTraversalContexts][16] = {\n");
  for (uint32_t c = 0; c < kTraversalContexts; ++c) {
    // The same gate context (level, t_a, t_b) over every previous class.
    std::vector<double> prior(kTraversalClasses);
    for (uint32_t previous = 0; previous < kTraversalClasses; ++previous)
      for (uint32_t s = 0; s < kTraversalClasses; ++s)
        prior[s] += counts[c / (12 * 64) * 12 * 64 + previous * 64 + c % 64][s];
    const std::vector<uint32_t> f = frequencies(counts[c], prior, kPrior);
    std::printf("    {0");
    for (uint32_t s = 0, at = 0; s < kTraversalClasses; ++s) std::printf(", %u", at += f[s]);
    std::printf(", 4096, 4096, 4096},\n");
  }
  std::printf("};\n\nconst uint16_t kClusterRankFrequencies[kClusterRanks] = {");
  const std::vector<uint32_t> f = frequencies(ranks, std::vector<double>(kClusterRanks, 1), 0);
  for (uint32_t r = 0; r < kClusterRanks; ++r) std::printf("%s%u", r ? ", " : "", f[r]);
  std::printf("};\n\n}  // namespace lodstream::package\n");
  return 0;
}
