// A child process running this program (/proc/self/exe) with other arguments: how `bench stream` bakes a
// model and, with --real, runs `lodstream serve`, `lodstream link` and `lodstream view`. The child is bound
// to this process's life: the destructor stops it (SIGTERM, then SIGKILL after a grace period), and the
// kernel sends it SIGTERM if this process dies first (PR_SET_PDEATHSIG), so no exit path leaves one running.
#pragma once

#include <sys/resource.h>
#include <sys/types.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace lodstream::cli {

class ChildProcess {
 public:
  // Starts `lodstream ARGS…`. Its standard output goes to `stdout_file`; when that is empty, to a pipe that
  // read_line() reads; when it is "-", to this process's standard error (a report for the user, where this
  // process's standard output is --json's). Its standard error goes to `stderr_file`, or to this process's
  // when it is empty. Throws lodstream::Error when it cannot be started.
  ChildProcess(const std::vector<std::string>& args, const std::filesystem::path& stdout_file,
               const std::filesystem::path& stderr_file);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // The next line of its standard output (piped), without the newline; empty once `timeout_s` has passed
  // or the output has ended.
  std::string read_line(double timeout_s);
  // Its exit status (128 + the signal that ended it) once it has ended; nullopt while it runs. No waiting.
  std::optional<int> poll();
  // Waits for it to end; returns its exit status as poll() does.
  int wait();
  // Sends SIGTERM, waits up to `grace_s`, then SIGKILL; returns its exit status. Nothing when it has ended.
  int stop(double grace_s = 5.0);
  // The CPU time (user + system, all its threads) it has used so far, in seconds, from /proc while it runs
  // (clock-tick resolution) and from wait4's accounting once it has ended; NaN when it cannot be read.
  double cpu_s();

 private:
  void ended(int status, const rusage& usage);

  pid_t pid_ = -1;
  int out_ = -1;  // read end of the stdout pipe, or -1
  std::optional<int> status_;
  double cpu_s_ = NAN;
  std::string pending_;
};

}  // namespace lodstream::cli
