// `lodstream bench`: a parent subcommand whose children (bench simplify, bench stream, ...) live in their own
// cmd_bench_<name>.cpp and register themselves here the way subcommands register with command.hpp.
#pragma once

#include "command.hpp"

namespace lodstream::cli {

// Registers `lodstream bench <command.name>`; call from a namespace-scope initializer.
bool register_bench(Command command);

}  // namespace lodstream::cli
