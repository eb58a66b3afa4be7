// An X server for window tests (GLFW under Xvfb, installed by scripts/setup): Xvfb picks a free display and
// writes its number to a pipe (-displayfd); the server is stopped when this object goes.
#pragma once

#include <sys/types.h>

#include <string>

namespace lodstream::test {

class Xvfb {
 public:
  // Starts `Xvfb -displayfd FD -screen 0 WIDTHxHEIGHTx24 -nolisten tcp` and waits for its display number.
  explicit Xvfb(int width = 320, int height = 240);
  ~Xvfb();  // SIGTERM, then waits for it
  Xvfb(const Xvfb&) = delete;
  Xvfb& operator=(const Xvfb&) = delete;
  // ":N", or empty when Xvfb could not start.
  std::string display() const { return display_.empty() ? "" : ":" + display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

}  // namespace lodstream::test
