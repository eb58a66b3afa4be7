#include "support/xvfb.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace lodstream::test {

Xvfb::Xvfb(int width, int height) {
  int fds[2];
  if (pipe(fds) != 0) return;
  const std::string fd = std::to_string(fds[1]);
  const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";
  const char* argv[] = {"Xvfb",         "-displayfd", fd.c_str(), "-screen", "0",
                        screen.c_str(), "-nolisten",  "tcp",      nullptr};
  if (posix_spawnp(&pid_, "Xvfb", nullptr, nullptr, const_cast<char**>(argv), environ) != 0) pid_ = -1;
  close(fds[1]);
  char c;
  while (pid_ > 0 && read(fds[0], &c, 1) == 1 && c != '\n') display_ += c;
  close(fds[0]);
}

Xvfb::~Xvfb() {
  if (pid_ > 0) {
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
  }
}

}  // namespace lodstream::test
