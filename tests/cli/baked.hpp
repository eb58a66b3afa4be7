// Packages baked by the program for the end-to-end tests, once per test process.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

#include "support/run.hpp"

namespace lodstream::test {

// refined_elephant baked once per test process.
inline const std::filesystem::path& elephant_package() {
  static const std::filesystem::path file = [] {
    auto out = temp_dir() / "elephant.lods";
    auto r = run_lodstream({"bake", data_file("refined_elephant.off").string(), "-o", out.string()});
    EXPECT_EQ(r.status, 0) << r.err;
    return out;
  }();
  return file;
}

}  // namespace lodstream::test
