#include "support/run.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

extern char** environ;

namespace lodstream::test {

namespace {
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
// Starts build/bin/lodstream with `args` and the given descriptor set-up; -1 (and a test failure) if it
// fails.
pid_t spawn(const std::vector<std::string>& args, const posix_spawn_file_actions_t& actions) {
  std::vector<std::string> argv_s{LODSTREAM_BINARY};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0) return pid;
  ADD_FAILURE() << "cannot start " << argv[0];
  return -1;
}
}  // namespace

nlohmann::json RunResult::json() const {
  try {
    return nlohmann::json::parse(out);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "stdout is not one JSON object: " << e.what() << "\nstdout: " << out
                  << "\nstderr: " << err;
    return {};
  }
}

RunResult run_lodstream(const std::vector<std::string>& args) {
  auto dir = temp_dir();
  auto out_path = dir / "stdout", err_path = dir / "stderr";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = spawn(args, actions);
  posix_spawn_file_actions_destroy(&actions);
  RunResult r;
  if (pid < 0) return r;
  int status = 0;
  waitpid(pid, &status, 0);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out_path);
  r.err = slurp(err_path);
  std::filesystem::remove_all(dir);
  return r;
}

BackgroundProcess::BackgroundProcess(const std::vector<std::string>& args) {
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) {
    ADD_FAILURE() << "pipe failed";
    return;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  pid_ = spawn(args, actions);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  out_ = pipe_fds[0];
}

BackgroundProcess::~BackgroundProcess() {
  stop();
}

std::string BackgroundProcess::read_line(double timeout_s) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    size_t newline = pending_.find('\n');
    if (newline != std::string::npos) {
      std::string line = pending_.substr(0, newline);
      pending_.erase(0, newline + 1);
      return line;
    }
    auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{out_, POLLIN, 0};
    if (left.count() <= 0 || poll(&p, 1, int(left.count())) <= 0) return {};
    char buf[4096];
    ssize_t n = read(out_, buf, sizeof buf);
    if (n <= 0) return {};
    pending_.append(buf, size_t(n));
  }
}

int BackgroundProcess::stop() {
  if (pid_ < 0) {
    if (out_ >= 0) close(out_), out_ = -1;
    return -1;
  }
  kill(pid_, SIGTERM);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  close(out_);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::filesystem::path data_file(const std::string& name) {
  auto p = std::filesystem::path(LODSTREAM_SOURCE_DIR) / "data" / name;
  if (!std::filesystem::exists(p))
    ADD_FAILURE() << p << " is missing: run scripts/fetch-data (make test does)";
  return p;
}

std::filesystem::path temp_dir() {
  static std::vector<std::filesystem::path> made;
  static const bool cleanup = [] {
    std::atexit([] {
      std::error_code ec;
      for (auto& d : made) std::filesystem::remove_all(d, ec);
    });
    return true;
  }();
  (void)cleanup;
  std::string tmpl = (std::filesystem::temp_directory_path() / "lodstream-test-XXXXXX").string();
  if (!mkdtemp(tmpl.data())) ADD_FAILURE() << "mkdtemp failed";
  made.emplace_back(tmpl);
  return tmpl;
}

}  // namespace lodstream::test
