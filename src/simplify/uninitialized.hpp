// An allocator that leaves value-initialized elements untouched. Internal to src/simplify.
#pragma once

#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace lodstream::simplify {

// std::allocator, except that value-initialization (vector(n), resize(n)) writes nothing: the first write
// of a large array is its first touch (page faults, about 4 s/GB with 4 KB pages on this machine), and an
// owner that fills it itself can then do that on every core instead of in one serial fill. For trivially
// destructible T only; the owner must write every element before reading it.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  static_assert(std::is_trivially_destructible_v<T>);
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}

  template <class U>
  void construct(U*) noexcept {}  // value-initialization: left to the owner
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// A vector whose resize(n) leaves the new elements for its owner to write.
template <class T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

}  // namespace lodstream::simplify
