// `lodstream import-worker FILE OUTFILE` (hidden): runs assimp on FILE in this separate process and writes
// the scene to OUTFILE for the parent (io/import_worker.hpp), so that an assimp crash cannot take the parent
// down.
#include <memory>

#include "command.hpp"
#include "io/import_worker.hpp"

namespace lodstream::cli {
namespace {

// This program implements the worker: import_model spawns it as /proc/self/exe.
const bool worker_program_set = [] {
  set_import_worker_program("/proc/self/exe");
  return true;
}();

const bool registered =
    register_command({"import-worker", "internal: read a model with assimp in a separate process",
                      [](CLI::App& sub) {
                        auto files = std::make_shared<std::pair<std::string, std::string>>();
                        sub.add_option("FILE", files->first, "model file")->required();
                        sub.add_option("OUTFILE", files->second, "where to write the scene")->required();
                        return [files] {
                          run_import_worker(files->first, files->second);
                          return 0;
                        };
                      },
                      true});

}  // namespace
}  // namespace lodstream::cli
