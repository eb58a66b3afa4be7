// A small package for the net tests: raw-encoded nodes (no codec), distinct bytes, several pages.
#pragma once

#include <cstdint>
#include <filesystem>

#include "package/writer.hpp"

namespace lodstream::test {

// Writes `nodes` nodes (node i: 1000 + 13 i bytes derived from i and `salt`), each its own group, into
// 4 KB pages with 16 records per index page. Different salts give different content hashes.
package::WrittenPackage write_raw_package(const std::filesystem::path& file, uint32_t nodes, uint8_t salt);

}  // namespace lodstream::test
