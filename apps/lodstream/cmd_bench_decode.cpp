// `lodstream bench decode SCENE.lods [--runs N] [--json]`: decodes every codec node of a package on one core,
// page by page as a client does (runtime/cut_geometry.hpp: read, checksum, zstd and the page's parts, then
// each record of the page once, its clusters drawn as views into it: PackageReader::decode_record and
// cluster_of, no cluster copied out), and prints triangles decoded per second of that thread's CPU time, per
// level and in all. Issue 4's floor is 25 M triangles per second per core; the package
// benchmark (bench/bench_package) times level-0 meshlets of one mesh, this times a real package's every
// level, whose coarse nodes may choose other predictors. A page's time is shared among its nodes' levels by
// their bytes, and a record's (decoded once, with its first cluster) among its clusters by their triangles.
// Thread CPU time rather than wall: steadier on a loaded machine, and one core by construction.
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
  std::vector<double> page_s, node_s;  // per run
};

int run_bench(const BenchArgs& args) {
  package::PackageReader reader = package::PackageReader::open(args.package);
  const uint32_t N = reader.node_count();
  std::vector<std::vector<uint32_t>> on_page(reader.root().pages.size());
  std::map<uint32_t, LevelTimes> levels;
  for (uint32_t id = 0; id < N; ++id) {
    const package::NodeRecord& n = reader.node(id);
    if (n.encoding != package::NodeEncoding::codec) continue;
    on_page[n.page].push_back(id);
    LevelTimes& l = levels[n.level];
    ++l.nodes, l.triangles += n.triangles;
  }
  if (levels.empty()) throw Error(args.package + ": no codec nodes to decode");
  std::vector<double> total_s;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  std::vector<uint8_t> buffer;  // the pages', one for all (PackageReader::read_page)
  // Every record decoded into this one, its buffers reused as a client recycles those of the records it drops
  // (runtime/cut_geometry.hpp).
  package::DecodedNode record;
  for (int run = 0; run < args.runs; ++run) {
    // Each page and node timed by the steady clock (cheap), the run by the thread's CPU clock (a system call
    // here): the levels share the run's CPU seconds as they share its clock time.
    std::map<uint32_t, double> page_s, node_s;
    double clocked = 0.0;
    const double cpu0 = thread_cpu_s();
    for (uint32_t page = 0; page < on_page.size(); ++page) {
      if (on_page[page].empty()) continue;
      const Clock::time_point t0 = Clock::now();
      const std::span<const uint8_t> raw = reader.read_page(page, buffer);
      const double unpack = since(t0);
      uint64_t page_bytes = 0;
      std::map<uint32_t, std::pair<double, uint64_t>> records;  // by offset: decode seconds, triangles
      for (uint32_t id : on_page[page]) {
        const package::NodeRecord& n = reader.node(id);
        page_bytes += n.size;
        records[n.offset].second += n.triangles;
      }
      uint32_t decoded_offset = UINT32_MAX;  // of the record in `record`
      for (uint32_t id : on_page[page]) {
        const Clock::time_point t1 = Clock::now();
        const uint32_t offset = reader.node(id).offset;
        if (offset != decoded_offset) reader.decode_record(id, raw, record), decoded_offset = offset;
        reader.cluster_of(id, record);  // the cluster's view, checked
        const double decode = since(t1);
        records[offset].first += decode;
        clocked += decode;
      }
      for (uint32_t id : on_page[page]) {
        const package::NodeRecord& n = reader.node(id);
        const auto& [seconds, triangles] = records[n.offset];
        node_s[n.level] += seconds * double(n.triangles) / double(std::max<uint64_t>(1, triangles));
        page_s[n.level] += unpack * double(n.size) / double(std::max<uint64_t>(1, page_bytes));
      }
      clocked += unpack;
    }
    const double cpu = thread_cpu_s() - cpu0, scale = clocked > 0.0 ? cpu / clocked : 0.0;
    for (auto& [level, l] : levels) {
      l.page_s.push_back(page_s[level] * scale), l.node_s.push_back(node_s[level] * scale);
    }
    total_s.push_back(cpu);
  }

  uint64_t nodes = 0, triangles = 0;
  nlohmann::json per_level = nlohmann::json::array();
  for (const auto& [level, l] : levels) {
    nodes += l.nodes, triangles += l.triangles;
    const double pages = median(l.page_s), decode = median(l.node_s);
    per_level.push_back({{"level", level},
                         {"nodes", l.nodes},
                         {"triangles", l.triangles},
                         {"pages_s", pages},
                         {"nodes_s", decode},
                         {"mtris_per_s", double(l.triangles) / (pages + decode) * 1e-6},
                         {"mtris_per_s_nodes_only", double(l.triangles) / decode * 1e-6}});
  }
  const double total = median(total_s);
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
