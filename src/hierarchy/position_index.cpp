#include "hierarchy/position_index.hpp"

#include <algorithm>
#include <bit>

#include "core/representatives.hpp"

namespace lodstream::hierarchy {
namespace {

// A coordinate's bits with -0 folded into +0 (+ 0 turns -0 into +0), so equal values compare equal.
uint32_t coordinate_bits(float f) {
  return std::bit_cast<uint32_t>(f + 0.0f);
}

uint64_t hash_bits(uint32_t x, uint32_t y, uint32_t z) {
  uint64_t h = (uint64_t(x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(y) * 0xC2B2AE3D27D4EB4Full) ^
               (uint64_t(z) * 0x165667B19E3779F9ull);
  return h ^ (h >> 29);
}

uint64_t position_hash(const glm::vec3& p) {
  return hash_bits(coordinate_bits(p.x), coordinate_bits(p.y), coordinate_bits(p.z));
}

bool same_position(const glm::vec3& a, const glm::vec3& b) {
  return coordinate_bits(a.x) == coordinate_bits(b.x) && coordinate_bits(a.y) == coordinate_bits(b.y) &&
         coordinate_bits(a.z) == coordinate_bits(b.z);
}

}  // namespace

PositionIndex::PositionIndex(size_t expected) {
  slots_.assign(std::bit_ceil(std::max<size_t>(16, expected * 2)), Slot{0, 0, 0, kMissing});
}

PositionIndex::Slot PositionIndex::key(const glm::vec3& p, uint32_t id) {
  return Slot{coordinate_bits(p.x), coordinate_bits(p.y), coordinate_bits(p.z), id};
}

size_t PositionIndex::home(const Slot& s) const {
  return size_t(hash_bits(s.x, s.y, s.z)) & (slots_.size() - 1);
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

std::vector<uint32_t> weld_positions(std::span<const glm::vec3> positions, uint32_t& distinct) {
  std::vector<uint32_t> ids = representatives(
      positions.size(), [&](size_t v) { return position_hash(positions[v]); },
      [&](uint32_t a, uint32_t b) { return same_position(positions[a], positions[b]); });
  // Representatives come first (they are the smallest of their positions): number them in order.
  uint32_t next = 0;
  for (size_t v = 0; v < ids.size(); ++v) ids[v] = ids[v] == v ? next++ : ids[ids[v]];
  distinct = next;
  return ids;
}

}  // namespace lodstream::hierarchy
