#include "package/byte_planes.hpp"

namespace lodstream::package {

void put_planes(std::vector<uint8_t>& out, const std::vector<uint64_t>& values, uint32_t components,
                uint32_t width) {
  const size_t count = values.size() / components;
  const size_t at = out.size();
  out.resize(at + values.size() * width);
  for (size_t i = 0; i < count; ++i)
    for (uint32_t a = 0; a < components; ++a)
      for (uint32_t b = 0; b < width; ++b)
        out[at + (b * components + a) * count + i] = uint8_t(values[components * i + a] >> (8 * b));
}

}  // namespace lodstream::package
