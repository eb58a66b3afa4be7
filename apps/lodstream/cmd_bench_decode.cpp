// `lodstream bench decode SCENE.lods [--runs N] [--json]`: decodes every codec node of a package on one core,
// page by page as a client does (runtime/cut_geometry.hpp: read, checksum, zstd and the page's parts, then
// each record of the page once, its clusters drawn as views into it: PackageReader::decode_record and
// cluster_of, no cluster copied out), and prints triangles decoded per second of that thread's CPU time, per
// level and in all. Issue 4's floor is 25 M triangles per second per core; the package
// benchmark (bench/bench_package) times level-0 meshlets of one mesh, this times a real package's every
// level, whose coarse nodes may choose other predictors. A page's time is shared among its nodes' levels by
// their bytes, and a record's (decoded once, with its first cluster) among its clusters by their triangles.
// Thread CPU time rather than wall: steadier on a loaded machine, and one core by construction. The levels
// split it by steady-clock times of each page and record, each the median of its runs (a preemption during
// one run of a node then leaves its level's figure alone); the thread's CPU clock per node would count no
// preemption at all, but it is a system call (no vDSO), 2.2 us a call on this VM against 26-47 ns for the
// steady clock (a throwaway harness, 200,000 calls of each): ~10 ms a run for motorBike's 4,467 nodes, whose
// decode takes ~22 ms.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "bench.hpp"
#include "core/error.hpp"
#include "package/reader.hpp"
#include "timing.hpp"

namespace lodstream::cli {
namespace {

struct BenchArgs {
  std::string package;
  int runs = 5;
  bool json = false;
};

struct LevelTimes {
  uint64_t nodes = 0, triangles = 0;
  double page_s = 0.0, node_s = 0.0;  // the median run's share (clock seconds until scaled)
};

// A page's nodes that share one record (one offset): decoded once, timed together, the time shared among
// them by their triangles.
struct RecordNodes {
  std::vector<uint32_t> ids;
  uint64_t triangles = 0;
  std::vector<double> seconds;  // per run
};

struct PageNodes {
  std::vector<uint32_t> ids;        // in id order
  std::vector<uint32_t> record_of;  // per entry of ids: its record's in `records`
  std::vector<RecordNodes> records;
  uint64_t bytes = 0;           // the nodes' bytes
  std::vector<double> seconds;  // per run: read and unpack
};

int run_bench(const BenchArgs& args) {
  package::PackageReader reader = package::PackageReader::open(args.package);
  const uint32_t N = reader.node_count();
  std::vector<PageNodes> pages(reader.root().pages.size());
  std::map<uint32_t, LevelTimes> levels;
  for (uint32_t id = 0; id < N; ++id) {
    const package::NodeRecord& n = reader.node(id);
    if (n.encoding != package::NodeEncoding::codec) continue;
    PageNodes& p = pages[n.page];
    p.ids.push_back(id), p.bytes += n.size;
    LevelTimes& l = levels[n.level];
    ++l.nodes, l.triangles += n.triangles;
  }
  if (levels.empty()) throw Error(args.package + ": no codec nodes to decode");
  for (PageNodes& p : pages) {
    std::map<uint32_t, size_t> by_offset;
    for (uint32_t id : p.ids) {
      const package::NodeRecord& n = reader.node(id);
      const auto [it, added] = by_offset.emplace(n.offset, p.records.size());
      if (added) p.records.emplace_back();
      RecordNodes& r = p.records[it->second];
      r.ids.push_back(id), r.triangles += n.triangles, r.seconds.reserve(size_t(args.runs));
      p.record_of.push_back(uint32_t(it->second));
    }
    p.seconds.reserve(size_t(args.runs));
  }
  std::vector<double> total_s;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  std::vector<uint8_t> buffer;  // the pages', one for all (PackageReader::read_page)
  // Every record decoded into this one, its buffers reused as a client recycles those of the records it drops
  // (runtime/cut_geometry.hpp).
  package::DecodedNode record;
  for (int run = 0; run < args.runs; ++run) {
    // Each page and record timed by the steady clock (cheap), the run by the thread's CPU clock.
    const double cpu0 = thread_cpu_s();
    for (uint32_t page = 0; page < pages.size(); ++page) {
      PageNodes& p = pages[page];
      if (p.ids.empty()) continue;
      const Clock::time_point t0 = Clock::now();
      const std::span<const uint8_t> raw = reader.read_page(page, buffer);
      p.seconds.push_back(since(t0));
      for (RecordNodes& r : p.records) r.seconds.push_back(0.0);
      uint32_t decoded = UINT32_MAX;  // the record (of p.records) in `record`
      for (size_t k = 0; k < p.ids.size(); ++k) {
        const Clock::time_point t1 = Clock::now();
        if (p.record_of[k] != decoded) reader.decode_record(p.ids[k], raw, record), decoded = p.record_of[k];
        reader.cluster_of(p.ids[k], record);  // the cluster's view, checked
        p.records[p.record_of[k]].seconds.back() += since(t1);
      }
    }
    total_s.push_back(thread_cpu_s() - cpu0);
  }
  // Each page's and record's median time shared among its nodes' levels, then scaled so that the levels add
  // up to the median run's CPU time.
  const double total = median(total_s);
  double clocked = 0.0;
  for (const PageNodes& p : pages) {
    if (p.ids.empty()) continue;
    const double unpack = median(p.seconds);
    clocked += unpack;
    for (uint32_t id : p.ids) {
      const package::NodeRecord& n = reader.node(id);
      levels[n.level].page_s += unpack * double(n.size) / double(std::max<uint64_t>(1, p.bytes));
    }
    for (const RecordNodes& r : p.records) {
      const double seconds = median(r.seconds);
      clocked += seconds;
      for (uint32_t id : r.ids) {
        const package::NodeRecord& n = reader.node(id);
        levels[n.level].node_s += seconds * double(n.triangles) / double(std::max<uint64_t>(1, r.triangles));
      }
    }
  }
  const double scale = clocked > 0.0 ? total / clocked : 0.0;

  uint64_t nodes = 0, triangles = 0;
  nlohmann::json per_level = nlohmann::json::array();
  for (const auto& [level, l] : levels) {
    nodes += l.nodes, triangles += l.triangles;
    const double pages = l.page_s * scale, decode = l.node_s * scale;
    per_level.push_back({{"level", level},
                         {"nodes", l.nodes},
                         {"triangles", l.triangles},
                         {"pages_s", pages},
                         {"nodes_s", decode},
                         {"mtris_per_s", double(l.triangles) / (pages + decode) * 1e-6},
                         {"mtris_per_s_nodes_only", double(l.triangles) / decode * 1e-6}});
  }
  const nlohmann::json out = {{"package", args.package},
                              {"decodes", "each record once, its clusters as views (no cluster copied out)"},
                              {"runs", args.runs},
                              {"nodes", nodes},
                              {"triangles", triangles},
                              {"cpu_s", total},
                              {"mtris_per_s", double(triangles) / total * 1e-6},
                              {"per_level", per_level}};
  if (args.json) {
    print_json(out);
    return 0;
  }
  std::printf(
      "%s: %llu codec nodes, %llu triangles decoded on one core (each record once, its clusters as views); "
      "thread CPU time, median of %d runs\n",
      args.package.c_str(), (unsigned long long)nodes, (unsigned long long)triangles, args.runs);
  std::printf("  level     nodes   triangles   pages (s)   nodes (s)   M tri/s   M tri/s nodes only\n");
  for (const auto& l : per_level)
    std::printf("  %5u  %8llu  %10llu  %10.4f  %10.4f  %8.2f  %19.2f\n", l["level"].get<uint32_t>(),
                (unsigned long long)l["nodes"].get<uint64_t>(),
                (unsigned long long)l["triangles"].get<uint64_t>(), l["pages_s"].get<double>(),
                l["nodes_s"].get<double>(), l["mtris_per_s"].get<double>(),
                l["mtris_per_s_nodes_only"].get<double>());
  std::printf("  all    %8llu  %10llu  %22.4f  %8.2f   (goal: at least 25 M tri/s per core)\n",
              (unsigned long long)nodes, (unsigned long long)triangles, total,
              out["mtris_per_s"].get<double>());
  return 0;
}

const bool registered =
    register_bench({"decode",
                    "every record of a package decoded once on one core, its clusters as views into it (what "
                    "the client does): triangles per second per level",
                    [](CLI::App& sub) {
                      auto args = std::make_shared<BenchArgs>();
                      sub.add_option("SCENE", args->package, "the package (.lods)")->required();
                      sub.add_option("--runs", args->runs,
                                     "times the whole package is decoded; medians are reported (1..50)")
                          ->capture_default_str()
                          ->check(CLI::Range(1, 50));
                      sub.add_flag("--json", args->json, "print one JSON object");
                      return [args] { return run_bench(*args); };
                    }});

}  // namespace
}  // namespace lodstream::cli
