#include "hierarchy/position_index.hpp"

#include <bit>
#include <cstring>

namespace lodstream::hierarchy {

PositionIndex::PositionIndex(size_t expected) {
  slots_.assign(std::bit_ceil(std::max<size_t>(16, expected * 2)), Slot{0, 0, 0, kMissing});
}

PositionIndex::Slot PositionIndex::key(const glm::vec3& p, uint32_t id) {
  Slot s;
  const float c[3] = {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};  // + 0 turns -0 into +0
  std::memcpy(&s.x, &c[0], 4), std::memcpy(&s.y, &c[1], 4), std::memcpy(&s.z, &c[2], 4);
  s.id = id;
  return s;
}

size_t PositionIndex::home(const Slot& s) const {
  uint64_t h = (uint64_t(s.x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(s.y) * 0xC2B2AE3D27D4EB4Full) ^
               (uint64_t(s.z) * 0x165667B19E3779F9ull);
  h ^= h >> 29;
  return size_t(h) & (slots_.size() - 1);
}

void PositionIndex::grow() {
  std::vector<Slot> old = std::move(slots_);
  slots_.assign(old.size() * 2, Slot{0, 0, 0, kMissing});
  for (const Slot& s : old) {
    if (s.id == kMissing) continue;
    size_t i = home(s);
    while (slots_[i].id != kMissing) i = (i + 1) & (slots_.size() - 1);
    slots_[i] = s;
  }
}

uint32_t PositionIndex::insert(const glm::vec3& p) {
  if ((count_ + 1) * 2 > slots_.size()) grow();
  Slot s = key(p, uint32_t(count_));
  size_t i = home(s);
  while (slots_[i].id != kMissing) {
    if (slots_[i].x == s.x && slots_[i].y == s.y && slots_[i].z == s.z) return slots_[i].id;
    i = (i + 1) & (slots_.size() - 1);
  }
  slots_[i] = s;
  return uint32_t(count_++);
}

uint32_t PositionIndex::find(const glm::vec3& p) const {
  Slot s = key(p, 0);
  size_t i = home(s);
  while (slots_[i].id != kMissing) {
    if (slots_[i].x == s.x && slots_[i].y == s.y && slots_[i].z == s.z) return slots_[i].id;
    i = (i + 1) & (slots_.size() - 1);
  }
  return kMissing;
}

}  // namespace lodstream::hierarchy
