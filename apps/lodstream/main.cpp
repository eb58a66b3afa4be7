// lodstream: one program, many subcommands (DESIGN.md, "The command line"). Errors print one line,
// "lodstream: error: <reason>", on standard error and exit with status 1.
#include <cstdio>
#include <exception>
#include <functional>

#include "command.hpp"
#include "core/error.hpp"
#include "huge_pages.hpp"

int main(int argc, char** argv) {
  using namespace lodstream;
  cli::restart_with_huge_pages(argv);
  CLI::App app{"lodstream: stream large 3D scenes to clients that render them at a bounded frame time.",
               "lodstream"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lodstream 0.1.0");
  std::function<int()> run;
  for (const auto& command : cli::registered_commands()) {
    CLI::App* sub = app.add_subcommand(command.name, command.summary);
    if (command.hidden) sub->group("");
    auto runner = command.setup(*sub);
    sub->callback([&run, runner] { run = runner; });
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "lodstream: error: %s (see lodstream --help)\n", e.what());
    return 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "lodstream: error: %s\n", e.what());
    return 1;
  }
  try {
    return run ? run() : 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "lodstream: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lodstream: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lodstream: error: %s\n", e.what());
    return 1;
  }
}
