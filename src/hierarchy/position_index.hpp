// Exact position identity ("weld by position"): dense ids for distinct positions, compared bit for bit (with
// -0 = +0). Hand-written open addressing because std::unordered_map costs about 3x more time and memory here
// and no Debian library offers a flat hash map. Cost: O(1) expected per call; 16 bytes per slot, at most 50 %
// load.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

namespace lodstream::hierarchy {

class PositionIndex {
 public:
  static constexpr uint32_t kMissing = UINT32_MAX;
  explicit PositionIndex(size_t expected = 16);
  // The id of `p`, adding it (next dense id) when new.
  uint32_t insert(const glm::vec3& p);
  // The id of `p`, or kMissing.
  uint32_t find(const glm::vec3& p) const;
  size_t size() const { return count_; }

 private:
  struct Slot {
    uint32_t x, y, z, id;
  };
  static Slot key(const glm::vec3& p, uint32_t id);
  size_t home(const Slot& s) const;
  void grow();

  std::vector<Slot> slots_;
  size_t count_ = 0;
};

// The id PositionIndex::insert would give each of `positions` in turn (equal positions, bit for bit with
// -0 = +0, share the id of the first; ids dense in order of first occurrence); `distinct` receives the
// number of ids. Each position's representative (core/representatives.hpp, on every core), then one in-order
// pass numbers the representatives. Cost: O(n), 4 bytes per position of scratch besides the result.
std::vector<uint32_t> weld_positions(std::span<const glm::vec3> positions, uint32_t& distinct);

}  // namespace lodstream::hierarchy
