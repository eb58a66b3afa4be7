#include "io/import_worker.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>

#include "core/error.hpp"
#include "core/image.hpp"
#include "io/assimp_reader.hpp"
#include "io/mapped_file.hpp"
#include "io/scene_codec.hpp"

extern char** environ;

namespace lodstream {

namespace {

std::filesystem::path& registered_program() {
  static std::filesystem::path program;
  return program;
}

std::filesystem::path worker_program(const ImportOptions& options) {
  if (!options.worker.empty()) return options.worker;
  if (!registered_program().empty()) return registered_program();
  // Other programs (tests, tools) use the `lodstream` built next to them.
  std::error_code ec;
  auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    auto sibling = self.parent_path() / "lodstream";
    if (std::filesystem::exists(sibling, ec)) return sibling;
  }
  return {};
}

// Removes a directory tree when it goes out of scope.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "lodstream-import-XXXXXX").string();
    if (!mkdtemp(tmpl.data()))
      throw Error(std::string("cannot create a temporary folder: ") + std::strerror(errno));
    path = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

// The reason in the worker's last "lodstream: error: " line, without the file name it starts with.
std::string error_reason(const std::string& err, const std::string& file) {
  const std::string tag = "lodstream: error: ";
  size_t at = err.rfind(tag);
  if (at == std::string::npos) return {};
  std::string line = err.substr(at + tag.size());
  line = line.substr(0, line.find('\n'));
  if (line.rfind(file + ": ", 0) == 0) line = line.substr(file.size() + 2);
  return line;
}

}  // namespace

void set_import_worker_program(const std::filesystem::path& program) {
  registered_program() = program;
}

Scene import_in_worker(const std::filesystem::path& path, const ImportOptions& options) {
  const std::string file = path.string();
  auto failed = [&file](const std::string& reason) { return Error(file + ": import failed: " + reason); };
  const std::filesystem::path program = worker_program(options);
  if (program.empty()) throw failed("no import worker program (the lodstream executable) to run assimp in");

  TempDir dir;
  const std::filesystem::path out = dir.path / "scene.bin";
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) throw failed(std::string("pipe: ") + std::strerror(errno));

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  // The child starts with no blocked signals and default SIGPIPE, whatever this process has set up.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

  std::string args[] = {program.string(), "import-worker", std::filesystem::absolute(path).string(),
                        out.string()};
  char* argv[] = {args[0].data(), args[1].data(), args[2].data(), args[3].data(), nullptr};
  pid_t pid = 0;
  int rc = posix_spawn(&pid, argv[0], &actions, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(pipe_fds[1]);
  if (rc != 0) {
    ::close(pipe_fds[0]);
    throw failed("cannot start " + program.string() + ": " + std::strerror(rc));
  }

  // Collect standard error until the worker closes it, then reap it; kill it at the deadline.
  using clock = std::chrono::steady_clock;
  const auto deadline = clock::now() + std::chrono::duration<double>(options.worker_timeout_s);
  std::string err;
  bool timed_out = false;
  char buffer[4096];
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd pfd{pipe_fds[0], POLLIN, 0};
    int ready = ::poll(&pfd, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    if (err.size() < (1 << 16)) err.append(buffer, static_cast<size_t>(n));
  }
  ::close(pipe_fds[0]);
  int status = 0;
  for (;;) {
    pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw failed(std::string("waitpid: ") + std::strerror(errno));
    if (timed_out || clock::now() >= deadline) {
      timed_out = true;
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  // Pass the worker's warnings on.
  for (size_t start = 0; start < err.size();) {
    size_t end = err.find('\n', start);
    if (end == std::string::npos) end = err.size();
    std::string line = err.substr(start, end - start);
    if (line.rfind("lodstream: warning: ", 0) == 0) std::fprintf(stderr, "%s\n", line.c_str());
    start = end + 1;
  }
  if (timed_out)
    throw failed("the importer did not finish within " + std::to_string(options.worker_timeout_s) + " s");
  if (WIFSIGNALED(status))
    throw failed("the importer crashed (signal " + std::to_string(WTERMSIG(status)) + ", " +
                 strsignal(WTERMSIG(status)) + ")");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string reason = error_reason(err, std::filesystem::absolute(path).string());
    throw failed(reason.empty() ? "the importer exited with status " + std::to_string(WEXITSTATUS(status))
                                : reason);
  }
  std::error_code ec;
  if (!std::filesystem::exists(out, ec)) throw failed("the importer wrote no scene");
  MappedFile map(out);
  return decode_scene(map.data(), map.size(), file + ": import failed");
}

void run_import_worker(const std::filesystem::path& file, const std::filesystem::path& out) {
  std::string bytes = encode_scene(read_with_assimp(file));
  write_file_atomically(out, bytes.data(), bytes.size());
}

}  // namespace lodstream
