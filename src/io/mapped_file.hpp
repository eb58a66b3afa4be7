// A read-only memory map of a whole file, so readers parse bytes in place without copying them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace lodstream {

class MappedFile {
 public:
  // Maps `file`; throws lodstream::Error("<file>: cannot open: <reason>"). An empty file maps to size 0.
  explicit MappedFile(const std::filesystem::path& file);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const char* data() const { return data_; }
  // Drops the whole pages inside [begin, end) from this process's resident memory once a reader is done with
  // them (the page cache keeps them; reading them again maps them back in). Cost: one madvise call.
  void release(const char* begin, const char* end) const;
  size_t size() const { return size_; }

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace lodstream
