// 8-bit RGBA images and PNG files (stb_image / stb_image_write from Debian's libstb).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace lodstream {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes, rows top to bottom

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(size_t(w) * size_t(h) * 4, 0) {}
  uint8_t* pixel(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
  const uint8_t* pixel(int x, int y) const { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
};

// Reads a PNG (or any format stb_image reads) as RGBA. Throws lodstream::Error naming the file and stb's
// reason.
Image load_image(const std::filesystem::path& file);
// Decodes an image file held in memory (PNG, JPEG, … as stb_image reads them) as RGBA. `name` names it in
// the error (for example "package.lods: blob 3"). Throws lodstream::Error with stb's reason.
Image decode_image(std::span<const uint8_t> bytes, const std::string& name);

// Writes a PNG: to a temporary file in the same folder, then renamed over `file`, so an interrupted write
// never leaves a broken image. Deterministic: the same pixels give the same bytes. Throws lodstream::Error on
// failure.
void save_png(const Image& image, const std::filesystem::path& file);

// Writes `bytes` to `file` through a temporary file in the same folder and a rename (atomic replace).
// Throws lodstream::Error naming the file on failure; the temporary file is removed.
void write_file_atomically(const std::filesystem::path& file, const void* bytes, size_t size);

}  // namespace lodstream
