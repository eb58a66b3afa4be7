#include "real_stream.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/error.hpp"

namespace lodstream::cli {

namespace fs = std::filesystem;

namespace {

// The text after `prefix` in `line` up to the first of `ends` (or the line's end); empty when absent.
std::string after(const std::string& line, const std::string& prefix, const std::string& ends) {
  const size_t at = line.find(prefix);
  if (at == std::string::npos) return {};
  const std::string rest = line.substr(at + prefix.size());
  return rest.substr(0, rest.find_first_of(ends));
}

// The last line of a log (what a failed child said last), or a note that it is empty.
std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last.empty() ? "(no message)" : last;
}

std::string number(double v, const char* unit) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g%s", v, unit);
  return buf;
}

}  // namespace

RealStream::RealStream(RealOptions options) : options_(std::move(options)) {
  fs::create_directories(options_.out);
  const fs::path log = options_.out / "serve.log";
  server_ = std::make_unique<ChildProcess>(
      std::vector<std::string>{"serve", options_.package.string(), "--bind", "127.0.0.1", "--port", "0"}, "",
      log);
  server_address_ = after(server_->read_line(60.0), "listening on http://", " \n");
  if (server_address_.empty())
    throw Error("bench stream --real: lodstream serve did not start (" + log.string() + ": " +
                last_line(log) + ")");
}

RealRun RealStream::run(Policy policy, const std::string& label) {
  const std::string name = policy_name(policy);
  if (policy == Policy::oracle) throw Error("bench stream --real: oracle has no real counterpart");
  const fs::path dir = options_.out / name;
  fs::create_directories(dir);
  const LinkSettings& l = options_.link;
  const fs::path link_log = dir / "link.log";
  ChildProcess link({"link", "--listen", "127.0.0.1:0", "--to", server_address_, "--bandwidth",
                     number(l.bandwidth_bps, "bit"), "--rtt", number(l.rtt_s * 1e3, "ms"), "--jitter",
                     number(l.jitter_s * 1e3, "ms")},
                    "", link_log);
  const std::string address = after(link.read_line(30.0), "link: listening on ", ", \n");
  if (address.empty())
    throw Error("bench stream --real: lodstream link did not start (" + link_log.string() + ": " +
                last_line(link_log) + ")");

  const std::string stem = options_.package.stem().string();
  std::vector<std::string> args{"view"};
  if (policy == Policy::push)
    args.push_back("ws://" + address + "/" + stem);
  else
    args.push_back("http://" + address + "/" + stem + ".lods");
  if (policy == Policy::full) args.insert(args.end(), {"--order", "full"});
  if (policy == Policy::sse_pull) args.insert(args.end(), {"--order", "sse", "--window", "20"});
  if (policy == Policy::sse_pull_3) args.insert(args.end(), {"--order", "sse", "--window", "3"});
  args.insert(args.end(),
              {"--headless", "--path", options_.path_file.string(), "--out", dir.string(), "--pixel-error",
               number(options_.tau, ""), "--settle", number(options_.settle_s, ""), "--cuts-every",
               std::to_string(options_.cuts_every), "--json"});
  const fs::path view_log = dir / "view.log";
  const double server_cpu_before = server_->cpu_s();
  ChildProcess view(args, dir / "view.json", view_log);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  // The view ends by itself at the path's end plus the settle time; a minute more means it hangs.
  const double limit_s = options_.path_duration_s + options_.settle_s + 60.0;
  std::optional<int> status;
  while (!(status = view.poll())) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    std::fprintf(stderr, "\rbench stream --real: %s %-10s %5.1f s", label.c_str(), name.c_str(), elapsed);
    if (elapsed > limit_s) {
      view.stop();
      throw Error("bench stream --real: view (" + name + ") still running after " + number(limit_s, " s") +
                  "; stopped (" + view_log.string() + ")");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  link.stop();
  if (*status != 0)
    throw Error("bench stream --real: view (" + name + ") failed with status " + std::to_string(*status) +
                " (" + view_log.string() + ": " + last_line(view_log) + ")");

  RealRun run;
  run.server_cpu_s = server_->cpu_s() - server_cpu_before;
  run.client_cpu_s = view.cpu_s();
  run.frames = read_frames_csv(dir / "frames.csv");
  std::ifstream summary(dir / "view.json");
  const nlohmann::json j = nlohmann::json::parse(summary, nullptr, false);
  if (j.is_discarded() || !j.contains("converged"))
    throw Error((dir / "view.json").string() + ": not view's JSON summary");
  if (!run.frames.empty()) run.frames.back().converged = j["converged"].get<bool>();
  if (options_.cuts_every) {
    std::ifstream cuts(dir / "cuts.csv");
    std::string line;
    std::getline(cuts, line);  // the header
    for (size_t number = 2; std::getline(cuts, line); ++number) {
      // FRAME,OBJECT:NODE OBJECT:NODE … (an empty list: nothing drawn)
      std::istringstream in(line);
      size_t frame = 0;
      char comma = 0;
      if (!(in >> frame >> comma) || comma != ',' || frame >= run.frames.size())
        throw Error((dir / "cuts.csv").string() + ": line " + std::to_string(number) +
                    ": not FRAME,OBJECT:NODE…");
      std::vector<schedule::DrawnNode>& drawn = run.cuts[frame];
      schedule::DrawnNode d;
      char colon = 0;
      while (in >> d.object >> colon >> d.node) drawn.push_back(d);
    }
  }
  return run;
}

std::vector<FrameRow> read_frames_csv(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot read");
  std::string line;
  const std::string header =
      "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms";
  if (!std::getline(in, line) || line.rfind(header, 0) != 0)
    throw Error(file.string() + ": line 1: not the per-frame CSV header '" + header + "'");
  std::vector<FrameRow> frames;
  for (size_t number = 2; std::getline(in, line); ++number) {
    FrameRow f;
    unsigned long long bytes = 0, triangles = 0;
    unsigned nodes = 0;
    if (std::sscanf(line.c_str(), "%lf,%llu,%u,%llu,%lf,%lf,%lf,%lf", &f.t, &bytes, &nodes, &triangles,
                    &f.pixel_error_max, &f.pixel_error_mean, &f.benefit_ratio, &f.frame_ms) != 8)
      throw Error(file.string() + ": line " + std::to_string(number) + ": not 8 numbers");
    f.bytes = bytes;
    f.nodes = nodes;
    f.triangles = triangles;
    frames.push_back(f);
  }
  if (frames.empty()) throw Error(file.string() + ": no frames");
  return frames;
}

}  // namespace lodstream::cli
