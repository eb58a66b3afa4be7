// `lodstream bench`: the parent of the benchmark subcommands registered through bench.hpp.
#include <memory>

#include "bench.hpp"

namespace lodstream::cli {
namespace {

std::vector<Command>& bench_commands() {
  static std::vector<Command> commands;
  return commands;
}

const bool registered =
    register_command({"bench", "benchmarks: lodstream side by side with the anchors it is measured against",
                      [](CLI::App& sub) {
                        sub.require_subcommand(1);
                        auto run = std::make_shared<std::function<int()>>();
                        for (const Command& command : bench_commands()) {
                          CLI::App* child = sub.add_subcommand(command.name, command.summary);
                          auto runner = command.setup(*child);
                          child->callback([run, runner] { *run = runner; });
                        }
                        return [run] { return *run ? (*run)() : 1; };
                      }});

}  // namespace

bool register_bench(Command command) {
  bench_commands().push_back(std::move(command));
  return true;
}

}  // namespace lodstream::cli
