// Packages baked by the program for the end-to-end tests, once per test process.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

#include "support/run.hpp"

namespace lodstream::test {

// `lodstream bake data/MODEL -o TEMP/FILE`; the package's path.
inline std::filesystem::path bake_data(const std::string& model, const std::string& file) {
  auto out = temp_dir() / file;
  auto r = run_lodstream({"bake", data_file(model).string(), "-o", out.string()});
  EXPECT_EQ(r.status, 0) << r.err;
  return out;
}

// refined_elephant baked once per test process.
inline const std::filesystem::path& elephant_package() {
  static const std::filesystem::path file = bake_data("refined_elephant.off", "elephant.lods");
  return file;
}

// data/motorBike.obj (67 objects) baked once per test process.
inline const std::filesystem::path& motorbike_package() {
  static const std::filesystem::path file = bake_data("motorBike.obj", "motorBike.lods");
  return file;
}

}  // namespace lodstream::test
