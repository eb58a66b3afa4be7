// The import worker: assimp runs in a child process (`lodstream import-worker FILE OUTFILE`) so that a crash,
// a hang or memory corruption in assimp becomes an error message instead of taking lodstream down.
#pragma once

#include <filesystem>

#include "core/scene.hpp"
#include "io/import.hpp"

namespace lodstream {

// Parent side. Spawns the worker program with posix_spawn (never fork: the caller may have threads), waits up
// to options.worker_timeout_s, and decodes and checks the scene it wrote (scene_codec.hpp). The worker's
// warning lines are passed on to standard error. Throws lodstream::Error("<file>: import failed: <reason>")
// when the worker cannot start, crashes (the signal is named), times out (it is killed), exits non-zero (its
// error line is the reason) or writes garbage.
Scene import_in_worker(const std::filesystem::path& file, const ImportOptions& options);

// Child side, the body of the hidden `import-worker` subcommand: reads `file` with assimp and writes the
// encoded scene to `out` (through a temporary file and a rename). Throws lodstream::Error on failure.
void run_import_worker(const std::filesystem::path& file, const std::filesystem::path& out);

// A program that implements the `import-worker` subcommand calls this (once, at start-up) with the path that
// runs it, normally "/proc/self/exe"; import_in_worker then spawns that when ImportOptions::worker is empty.
void set_import_worker_program(const std::filesystem::path& program);

}  // namespace lodstream
