#include "core/image.hpp"

#include <stb_image.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/error.hpp"

namespace lodstream {

namespace {

// Moves stb's RGBA result into an Image, or throws naming `name` with stb's reason.
Image take_stb_image(stbi_uc* data, int w, int h, const std::string& name) {
  if (!data) throw Error(name + ": cannot read image (" + stbi_failure_reason() + ")");
  Image image(w, h);
  std::memcpy(image.rgba.data(), data, image.rgba.size());
  stbi_image_free(data);
  return image;
}

}  // namespace

Image load_image(const std::filesystem::path& file) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(file.c_str(), &w, &h, &channels, 4);
  return take_stb_image(data, w, h, file.string());
}

Image decode_image(std::span<const uint8_t> bytes, const std::string& name) {
  if (bytes.size() > size_t(INT32_MAX))
    throw Error(name + ": image of " + std::to_string(bytes.size()) + " bytes is too large");
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, 4);
  return take_stb_image(data, w, h, name);
}

void save_png(const Image& image, const std::filesystem::path& file) {
  std::vector<uint8_t> png;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 4, image.rgba.data(), image.width * 4))
    throw Error(file.string() + ": cannot encode PNG");
  write_file_atomically(file, png.data(), png.size());
}

void write_file_atomically(const std::filesystem::path& file, const void* bytes, size_t size) {
  std::filesystem::path tmp = file;
  tmp += ".tmp" + std::to_string(getpid());
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw Error(file.string() + ": cannot write (" + std::strerror(errno) + ")");
  bool ok = std::fwrite(bytes, 1, size, f) == size;
  ok = (std::fclose(f) == 0) && ok;
  std::error_code ec;
  if (ok) std::filesystem::rename(tmp, file, ec);
  if (!ok || ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(file.string() + ": cannot write (" + std::strerror(errno) + ")");
  }
}

}  // namespace lodstream
