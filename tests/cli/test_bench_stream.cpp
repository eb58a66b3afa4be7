// `lodstream bench stream` end to end on a small real scene (CGAL's elephant, baked by the command itself):
// simulated runs are reproducible byte for byte, every policy converges on a static path, `full` draws
// nothing before all of its pages arrived, the outputs follow DESIGN.md's contract, and bad arguments are
// one-line errors.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "support/run.hpp"

using namespace lodstream;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kPolicies{"full", "sse-pull", "sse-pull-3", "push", "oracle"};
const char* kHeader = "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The package, baked once by the first run (the model is given, so bench stream bakes it into --out).
fs::path elephant_package() {
  static const fs::path file = [] {
    const fs::path out = test::temp_dir() / "bake";
    auto r = test::run_lodstream({"bench", "stream", test::data_file("elephant.off").string(), "--path",
                                  "gen:orbit", "--policy", "sse-pull", "--psnr-every", "0", "--settle", "0",
                                  "--out", out.string()});
    EXPECT_EQ(r.status, 0) << r.err;
    return out / "elephant.lods";
  }();
  return file;
}

test::RunResult bench(const fs::path& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args{
      "bench", "stream",    elephant_package().string(), "--link", "bandwidth=2mbit,rtt=150ms,jitter=5ms",
      "--out", out.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_lodstream(args);
}

struct Row {
  double t = 0, benefit = 0;
  uint64_t bytes = 0, nodes = 0;
};

std::vector<Row> rows(const fs::path& csv) {
  std::istringstream in(slurp(csv));
  std::string line;
  std::getline(in, line);
  std::vector<Row> out;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    EXPECT_GE(f.size(), 8u) << line;
    if (f.size() < 8) break;
    out.push_back({std::stod(f[0]), std::stod(f[6]), std::stoull(f[1]), std::stoull(f[2])});
  }
  return out;
}

// A fixed camera looking at the elephant, written into `dir` (created).
fs::path static_path(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path path = dir / "static-path.json";
  std::ofstream(path) << R"({"fov": 50, "size": [320, 180], "keyframes": [{"t": 0, "eye": [0.2, 0.3, 1.4],
                           "target": [0, 0, 0]}]})";
  return path;
}

}  // namespace

// Same input, same outputs: every CSV (image metrics included) and summary.json, byte for byte.
TEST(BenchStream, SimulatedRunsAreReproducibleByteForByte) {
  const fs::path a = test::temp_dir() / "a", b = test::temp_dir() / "b";
  const std::vector<std::string> args{"--path", "gen:teleport", "--size", "320x180", "--psnr-every",
                                      "3",      "--settle",     "2"};
  auto ra = bench(a, args), rb = bench(b, args);
  ASSERT_EQ(ra.status, 0) << ra.err;
  ASSERT_EQ(rb.status, 0) << rb.err;
  for (const std::string& p : kPolicies) {
    const std::string csv = slurp(a / (p + ".csv"));
    EXPECT_GT(csv.size(), 1000u) << p;
    EXPECT_EQ(csv, slurp(b / (p + ".csv"))) << p;
    EXPECT_NE(csv.find(",psnr,ssim\n"), std::string::npos);
  }
  EXPECT_EQ(slurp(a / "summary.json"), slurp(b / "summary.json"));
  EXPECT_EQ(slurp(a / "summary.md"), slurp(b / "summary.md"));
}

// A static camera: each policy ends with the converged cut (benefit 1, the run stopping once converged), and
// `full` draws nothing until every byte it fetches has arrived.
TEST(BenchStream, EveryPolicyConvergesOnAStaticPathAndFullWaitsForEverything) {
  const fs::path dir = test::temp_dir() / "static";
  const fs::path path = static_path(dir);
  auto r = bench(dir, {"--path", path.string(), "--psnr-every", "0", "--settle", "20", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json summary = r.json();
  for (const std::string& p : kPolicies) {
    const auto& s = summary["policies"][p];
    ASSERT_FALSE(s["converged_s"].is_null()) << p;
    const std::vector<Row> f = rows(dir / (p + ".csv"));
    ASSERT_FALSE(f.empty());
    EXPECT_NEAR(f.back().t, s["converged_s"].get<double>(), 1e-3) << p;
    EXPECT_LT(f.back().t, 20.0) << p;  // stopped once converged, before the settle time ran out
    EXPECT_GT(f.back().benefit, 0.999) << p;
    EXPECT_EQ(f.back().bytes, s["bytes"].get<uint64_t>()) << p;
    EXPECT_FALSE(s["time_to_095_s"].is_null()) << p;
  }
  const std::vector<Row> full = rows(dir / "full.csv");
  const uint64_t total = full.back().bytes;
  size_t drawn = 0;
  for (const Row& row : full) {
    if (row.nodes > 0) ++drawn;
    if (row.bytes < total) {
      EXPECT_EQ(row.nodes, 0u) << "t=" << row.t;
      EXPECT_EQ(row.benefit, 0.0) << "t=" << row.t;
    }
  }
  EXPECT_GT(drawn, 0u);
  EXPECT_EQ(full.front().nodes, 0u);
  // the pull policies draw before everything they fetch has arrived
  const std::vector<Row> pull = rows(dir / "sse-pull.csv");
  EXPECT_TRUE(std::any_of(pull.begin(), pull.end(),
                          [&](const Row& row) { return row.nodes > 0 && row.bytes < pull.back().bytes; }));
}

// DESIGN.md's CSV header and summary keys; --json prints summary.json's object; plots and frames are written.
TEST(BenchStream, OutputsFollowTheContract) {
  const fs::path dir = test::temp_dir() / "contract";
  auto r = bench(
      dir, {"--path", "gen:drive", "--size", "320x180", "--psnr-every", "2", "--settle", "1", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json printed = r.json();
  EXPECT_EQ(printed, nlohmann::json::parse(slurp(dir / "summary.json")));
  ASSERT_EQ(printed["policies"].size(), kPolicies.size());
  for (const std::string& p : kPolicies) {
    const auto& s = printed["policies"][p];
    for (const char* key : {"time_to_first_frame_s", "time_to_095_s", "benefit_auc", "bytes", "psnr_at_1s",
                            "psnr_at_2s", "psnr_at_5s", "frame_ms_p50", "frame_ms_p99"})
      EXPECT_TRUE(s.contains(key)) << p << " " << key;
    EXPECT_GE(s["benefit_auc"].get<double>(), 0.0);
    EXPECT_LE(s["benefit_auc"].get<double>(), 1.0);
    EXPECT_EQ(slurp(dir / (p + ".csv")).rfind(kHeader, 0), 0u) << p;
  }
  const std::string md = slurp(dir / "summary.md");
  for (const std::string& p : kPolicies) EXPECT_NE(md.find("| " + p + " |"), std::string::npos) << md;
  for (const char* png : {"benefit.png", "psnr.png", "bytes.png"}) EXPECT_TRUE(fs::exists(dir / png)) << png;
  EXPECT_TRUE(fs::exists(dir / "frames" / "reference_001.00s.png"));

  // path.json records the generated path: replaying it gives the same frames.
  const fs::path replay = test::temp_dir() / "replay";
  auto rr = bench(replay, {"--path", (dir / "path.json").string(), "--psnr-every", "0", "--settle", "1"});
  ASSERT_EQ(rr.status, 0) << rr.err;
  for (const std::string& p : kPolicies) {
    std::string a = slurp(dir / (p + ".csv")), b = slurp(replay / (p + ".csv"));
    // without image metrics: compare the DESIGN.md columns
    auto strip = [](const std::string& csv) {
      std::string out;
      std::istringstream in(csv);
      for (std::string line; std::getline(in, line);)
        out += line.substr(0, line.rfind(',', line.rfind(',') - 1)) + "\n";
      return out;
    };
    EXPECT_EQ(strip(a), strip(b)) << p;
  }
}

// --real: lodstream serve, a lodstream link per policy and a headless lodstream view per policy on loopback.
// A fixed camera and a fast link keep it to a few seconds: every real policy converges (benefit 1 at the last
// row), the summary sets the simulated figures beside the real ones (oracle simulated only) and the CPU time
// of the server and the view, and every child process was stopped (serve and link log their stop signal).
TEST(BenchStream, RealModeRunsEveryPolicyThroughServeLinkAndView) {
  const fs::path dir = test::temp_dir() / "real";
  const fs::path path = static_path(dir);
  auto r = test::run_lodstream({"bench", "stream", elephant_package().string(), "--real", "--path",
                                path.string(), "--link", "bandwidth=20mbit,rtt=20ms", "--settle", "5",
                                "--psnr-every", "1", "--out", dir.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json summary = r.json();
  EXPECT_EQ(summary["mode"], "real");
  EXPECT_EQ(summary, nlohmann::json::parse(slurp(dir / "summary.json")));
  const std::string md = slurp(dir / "summary.md");
  EXPECT_NE(md.find("How far the two modes agree"), std::string::npos) << md;
  EXPECT_NE(md.find("CPU seconds (user + system) during each run: full server "), std::string::npos) << md;
  for (const std::string p : {"full", "sse-pull", "sse-pull-3", "push"}) {
    SCOPED_TRACE(p);
    const auto& s = summary["policies"][p];
    EXPECT_EQ(s["mode"], "real");
    for (const char* key : {"time_to_first_frame_s", "time_to_095_s", "benefit_auc", "bytes", "psnr_at_1s",
                            "psnr_at_2s", "psnr_at_5s", "frame_ms_p50", "frame_ms_p99"}) {
      EXPECT_TRUE(s.contains(key)) << key;
      EXPECT_TRUE(s["simulated"].contains(key)) << key;
    }
    EXPECT_FALSE(s["converged_s"].is_null());
    EXPECT_FALSE(s["time_to_095_s"].is_null());
    EXPECT_FALSE(s["simulated"]["time_to_095_s"].is_null());
    EXPECT_FALSE(s["psnr_at_5s"].is_null());  // the view's last frame was drawn and compared
    EXPECT_GT(s["psnr_at_5s"].get<double>(), 30.0);
    // The processes' CPU time during the run: the view decodes and selects cuts for 5 s and more.
    ASSERT_TRUE(s["server_cpu_s"].is_number());
    EXPECT_GE(s["server_cpu_s"].get<double>(), 0.0);
    ASSERT_TRUE(s["client_cpu_s"].is_number());
    EXPECT_GT(s["client_cpu_s"].get<double>(), 0.0);
    const std::vector<Row> f = rows(dir / (p + ".csv"));
    ASSERT_FALSE(f.empty());
    EXPECT_EQ(f.back().benefit, 1.0);
    EXPECT_EQ(f.back().bytes, s["bytes"].get<uint64_t>());
    EXPECT_EQ(slurp(dir / (p + ".csv")).rfind(kHeader, 0), 0u);
    EXPECT_TRUE(fs::exists(dir / "simulated" / (p + ".csv")));
    EXPECT_NE(md.find("| " + p + " |"), std::string::npos) << md;
    EXPECT_NE(slurp(dir / "real" / p / "link.log").find("stopped by signal"), std::string::npos);
  }
  EXPECT_EQ(summary["policies"]["oracle"]["mode"], "simulated only");
  EXPECT_NE(md.find("| oracle (simulated only) |"), std::string::npos) << md;
  // full drew nothing before all it fetched had arrived
  for (const Row& row : rows(dir / "full.csv")) {
    if (row.bytes < summary["policies"]["full"]["bytes"].get<uint64_t>()) {
      EXPECT_EQ(row.nodes, 0u) << row.t;
    }
  }
  EXPECT_NE(slurp(dir / "real" / "serve.log").find("stopped by signal"), std::string::npos);
}

TEST(BenchStream, BadArgumentsAreOneLineErrors) {
  const fs::path out = test::temp_dir() / "bad";
  const std::string pkg = elephant_package().string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--path", "gen:orbit", "--policy", "full,warp"}, "--policy"},
      {{"--path", "gen:orbit", "--link", "bandwidth=10mbit"}, "--link"},
      {{"--path", "gen:orbit", "--link", "bandwidth=fast,rtt=80ms"}, "--link bandwidth"},
      {{"--path", "gen:spiral"}, "gen:spiral"},
      {{"--path", (out / "none.json").string()}, "none.json"},
      {{"--path", "gen:orbit", "--real", "--policy", "oracle"}, "--real"},
      {{"--path", "gen:orbit", "--up", "0,0"}, "--up"},
  };
  for (const auto& [extra, what] : cases) {
    std::vector<std::string> args{"bench", "stream", pkg, "--out", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    auto r = test::run_lodstream(args);
    EXPECT_EQ(r.status, 1) << what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("lodstream: error:", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  auto r = test::run_lodstream(
      {"bench", "stream", (out / "missing.lods").string(), "--path", "gen:orbit", "--out", out.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing.lods"), std::string::npos) << r.err;
}
