#include "command.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"

namespace lodstream::cli {

namespace {
std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}

bool parse_float(std::string_view s, float& out) {
  // std::from_chars for float is available in GCC 12's libstdc++.
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(out);
}
}  // namespace

bool register_command(Command command) {
  registry().push_back(std::move(command));
  return true;
}

const std::vector<Command>& registered_commands() {
  return registry();
}

void print_json(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

nlohmann::json bounds_json(const Bounds& b) {
  if (b.empty()) return {{"min", nullptr}, {"max", nullptr}};
  return {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
}

glm::vec3 parse_vec3(const std::string& text, const std::string& option) {
  glm::vec3 v;
  std::string_view rest = text;
  for (int i = 0; i < 3; ++i) {
    size_t comma = rest.find(',');
    bool last = i == 2;
    if (last != (comma == std::string_view::npos) || !parse_float(rest.substr(0, comma), v[i]))
      throw Error(option + " must be three finite numbers X,Y,Z, got '" + text + "'");
    if (!last) rest = rest.substr(comma + 1);
  }
  return v;
}

std::pair<int, int> parse_size(const std::string& text, const std::string& option) {
  int w = 0, h = 0;
  size_t x = text.find('x');
  auto parse = [](std::string_view s, int& out) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
  };
  if (x == std::string::npos || !parse(std::string_view(text).substr(0, x), w) ||
      !parse(std::string_view(text).substr(x + 1), h) || w < 1 || h < 1 || w > 16384 || h > 16384)
    throw Error(option + " must be WIDTHxHEIGHT with each side in 1..16384, got '" + text + "'");
  return {w, h};
}

StopSignals::StopSignals() {
  sigemptyset(&set_);
  sigaddset(&set_, SIGINT);
  sigaddset(&set_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set_, nullptr);
}

int StopSignals::wait() {
  int signal = 0;
  sigwait(&set_, &signal);
  return signal;
}

}  // namespace lodstream::cli
