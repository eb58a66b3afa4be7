// Byte-range sources: the reader sees a package only through `read(offset, size)`, so the same reader works
// on a local file now and on HTTP Range requests later (one request per call).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace lodstream::package {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Total size in bytes.
  virtual uint64_t size() const = 0;
  // Fills `out` with the bytes at [offset, offset + out.size()). Throws lodstream::Error (naming the source)
  // when the range is not inside the source or the read fails; never returns a short read. Safe to call from
  // several threads at once.
  virtual void read(uint64_t offset, std::span<uint8_t> out) const = 0;
  // Names the source in error messages (a path or a URL).
  virtual const std::string& name() const = 0;
};

// A local file, read with pread (no shared file position, so reads may run concurrently). The size is taken
// at open; the file is expected not to change while open.
class FileSource final : public ByteSource {
 public:
  // Throws lodstream::Error naming `path` when it cannot be opened.
  explicit FileSource(const std::filesystem::path& path);
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;

  uint64_t size() const override { return size_; }
  void read(uint64_t offset, std::span<uint8_t> out) const override;
  const std::string& name() const override { return name_; }

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
  std::string name_;
};

}  // namespace lodstream::package
