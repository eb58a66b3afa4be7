// `bench stream --real` (issue 6): the policies on real processes over loopback. One `lodstream serve` for
// the run (port 0), then per policy a fresh `lodstream link` in front of it with the run's bandwidth, RTT
// and jitter (port 0) and one headless `lodstream view` through it (a fresh client: empty cache), one policy
// after the other. Each view follows the camera path on the wall clock at 30 frames/s and writes its
// per-frame CSV (DESIGN.md's columns) and, every `cuts_every` frames and at the last one, the cut it drew
// (node ids: recording costs the client nothing, where drawing an image would stall its frame loop; the
// benchmark draws the recorded cuts afterwards).
//   full        view http://…/NAME.lods --order full        (every index page, then the finest pages in file
//                                                              order; nothing drawn until all arrived)
//   sse-pull    view http://…/NAME.lods --order sse --window 20   (20 requests outstanding, 20 connections)
//   sse-pull-3  view http://…/NAME.lods --order sse --window 3
//   push        view ws://…/NAME
//   oracle has no real counterpart (it needs the future path): run() refuses it.
// Every child process ends with this object, or with this process (child_process.hpp).
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "net/link_model.hpp"
#include "stream_sim.hpp"

namespace lodstream::cli {

struct RealOptions {
  std::filesystem::path package, path_file, out;  // out: the folder for each policy's view output and logs
  LinkSettings link;
  double tau = 1.0, settle_s = 10.0;
  double path_duration_s = 0.0;  // the camera path's length (a view that runs far longer is stopped)
  int cuts_every = 0;            // record the drawn cut every N frames (0: none)
};

// One policy's run: its frames (the view's CSV) and the cuts it recorded, by frame (row) index, and the CPU
// seconds (user + system) that the server spent during the run and that the view spent in all.
struct RealRun {
  std::vector<FrameRow> frames;
  std::map<size_t, std::vector<schedule::DrawnNode>> cuts;
  double server_cpu_s = 0.0, client_cpu_s = 0.0;
};

class RealStream {
 public:
  // Starts the server (its log: out/serve.log); throws lodstream::Error when it does not start.
  explicit RealStream(RealOptions options);
  // Runs `policy`'s client through a fresh link, printing a progress line to standard error while it runs
  // (`label` names the run); throws lodstream::Error when a process fails, naming its log.
  RealRun run(Policy policy, const std::string& label);

 private:
  RealOptions options_;
  std::unique_ptr<ChildProcess> server_;
  std::string server_address_;  // HOST:PORT
};

// The frames of a per-frame CSV (DESIGN.md's header first); throws lodstream::Error naming the file and line
// when it is malformed.
std::vector<FrameRow> read_frames_csv(const std::filesystem::path& file);

}  // namespace lodstream::cli
