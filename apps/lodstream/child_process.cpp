#include "child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/error.hpp"

namespace lodstream::cli {

namespace {

int exit_status(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int open_for_writing(const std::filesystem::path& file) {
  const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(file.string() + ": cannot create");
  return fd;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& args, const std::filesystem::path& stdout_file,
                           const std::filesystem::path& stderr_file) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<std::string> strings{self};
  strings.insert(strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);

  int out = -1, err = -1, pipe_fds[2] = {-1, -1};
  if (stdout_file.empty()) {
    if (pipe2(pipe_fds, O_CLOEXEC) != 0) throw Error("cannot create a pipe for " + args.at(0));
    out = pipe_fds[1];
  } else if (stdout_file == "-") {
    out = fcntl(2, F_DUPFD_CLOEXEC, 3);
    if (out < 0) throw Error("cannot duplicate standard error for " + args.at(0));
  } else {
    out = open_for_writing(stdout_file);
  }
  if (!stderr_file.empty()) err = open_for_writing(stderr_file);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ == 0) {
    // The child: only async-signal-safe calls until exec.
    if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != parent) _exit(127);
    dup2(out, 1);
    if (err >= 0) dup2(err, 2);
    execv(self.c_str(), argv.data());
    _exit(127);
  }
  close(out);
  if (err >= 0) close(err);
  if (pid_ < 0) {
    if (pipe_fds[0] >= 0) close(pipe_fds[0]);
    throw Error("cannot start " + self + " " + args.at(0));
  }
  out_ = pipe_fds[0];
}

ChildProcess::~ChildProcess() {
  stop();
  if (out_ >= 0) close(out_);
}

std::string ChildProcess::read_line(double timeout_s) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  for (;;) {
    if (const size_t newline = pending_.find('\n'); newline != std::string::npos) {
      std::string line = pending_.substr(0, newline);
      pending_.erase(0, newline + 1);
      return line;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd p{out_, POLLIN, 0};
    if (out_ < 0 || left <= 0 || ::poll(&p, 1, int(left)) <= 0) return {};
    char buf[4096];
    const ssize_t n = read(out_, buf, sizeof buf);
    if (n <= 0) return {};
    pending_.append(buf, size_t(n));
  }
}

std::optional<int> ChildProcess::poll() {
  if (!status_ && pid_ > 0) {
    int status = 0;
    rusage usage{};
    if (wait4(pid_, &status, WNOHANG, &usage) == pid_) ended(status, usage);
  }
  return status_;
}

int ChildProcess::wait() {
  if (!status_ && pid_ > 0) {
    int status = 0;
    rusage usage{};
    while (wait4(pid_, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    ended(status, usage);
  }
  return status_.value_or(-1);
}

void ChildProcess::ended(int status, const rusage& usage) {
  status_ = exit_status(status);
  auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  cpu_s_ = seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double ChildProcess::cpu_s() {
  if (pid_ <= 0 || poll()) return cpu_s_;
  // /proc/PID/stat: fields 14 and 15 (user and system time in clock ticks) after the parenthesized name.
  std::ifstream in("/proc/" + std::to_string(pid_) + "/stat");
  std::string line;
  if (!std::getline(in, line) || line.rfind(')') == std::string::npos) return NAN;
  std::istringstream fields(line.substr(line.rfind(')') + 2));
  std::string skip;
  for (int field = 3; field < 14; ++field) fields >> skip;
  double user = 0, system = 0;
  if (!(fields >> user >> system)) return NAN;
  return (user + system) / double(sysconf(_SC_CLK_TCK));
}

int ChildProcess::stop(double grace_s) {
  if (pid_ <= 0 || poll()) return status_.value_or(-1);
  kill(pid_, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  while (!poll() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (!poll()) kill(pid_, SIGKILL);
  return wait();
}

}  // namespace lodstream::cli
