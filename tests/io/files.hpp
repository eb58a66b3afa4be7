// Helpers of the io tests: small model files written by the test itself.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "core/scene.hpp"
#include "io/import.hpp"
#include "support/run.hpp"

namespace lodstream::test {

inline std::filesystem::path write_file(const std::string& name, const std::string& bytes) {
  static const std::filesystem::path dir = temp_dir();
  auto path = dir / name;
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The message of the lodstream::Error that `read(file)` throws ("" and a test failure when none is thrown).
template <class Read>
std::string error_of(Read&& read, const std::filesystem::path& file) {
  try {
    read(file);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "reading " << file << " did not fail";
  return "";
}

// The message of the lodstream::Error that importing `file` throws.
inline std::string import_error(const std::filesystem::path& file, const ImportOptions& options = {}) {
  return error_of([&](const std::filesystem::path& f) { import_model(f, options); }, file);
}

}  // namespace lodstream::test
