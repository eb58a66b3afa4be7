// Subcommand registry of the `lodstream` program. Each cmd_<name>.cpp defines one subcommand and registers it
// with a namespace-scope `const bool registered = register_command({...});`, so main.cpp never lists them.
#pragma once

#include <signal.h>

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bounds.hpp"

namespace lodstream::cli {

struct Command {
  std::string name;
  std::string summary;  // one line, shown by `lodstream --help`
  // Adds the subcommand's options and flags to `sub`; returns what runs once the arguments are parsed.
  // The returned function returns the process exit status; it throws lodstream::Error on bad input.
  std::function<std::function<int()>(CLI::App& sub)> setup;
  bool hidden = false;  // internal subcommands (such as the import worker) are not listed in --help
};

bool register_command(Command command);
const std::vector<Command>& registered_commands();

// Prints `value` to standard output as exactly one JSON object on one line (the --json contract).
void print_json(const nlohmann::json& value);

// JSON of a box: {"min": [x,y,z], "max": [x,y,z]}.
nlohmann::json bounds_json(const Bounds& b);

// Parses "X,Y,Z" (a command-line vector); throws lodstream::Error naming `option` when malformed.
glm::vec3 parse_vec3(const std::string& text, const std::string& option);

// Parses "WxH" (an image size in pixels, each 1..16384); throws lodstream::Error naming `option`.
std::pair<int, int> parse_size(const std::string& text, const std::string& option);

// For long-running subcommands (serve, link): blocks SIGINT and SIGTERM in the calling thread and in every
// thread it starts afterwards (threads inherit the mask), so that wait() in the main thread receives them.
class StopSignals {
 public:
  StopSignals();
  // Blocks until SIGINT or SIGTERM arrives; returns the signal number.
  int wait();

 private:
  sigset_t set_;
};

}  // namespace lodstream::cli
