// Faulting in a large array's pages on every core before it is first written. A fresh page costs the thread
// that first touches it a page fault and the kernel's clearing of it (about 4 s/GB on the 2-core VM of
// BENCHMARKS.md): when that thread is the only one working (a std::vector's resize or fill, which writes
// every element on the calling thread), the other core waits. Here the pages are populated first, the
// address range split across the cores (madvise MADV_POPULATE_WRITE, Linux 5.14), and the serial write that
// follows finds them present. Where the kernel lacks it, nothing happens and the write faults as before.
// Measured (perf samples per thread of `lodstream info data/elephant_5m.ply`, 3 interleaved pairs, the
// import's arrays prefaulted): main thread minus worker 562 / 480 / 372 -> 213 / 203 / 182 ms of CPU, the
// total the same (1,586 -> 1,592 ms mean): about 0.14 s of the import's wall time no longer on one core.
#pragma once

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace lodstream {

// Arrays smaller than this are left to fault as they are written (two huge pages: less to split).
inline constexpr size_t kPrefaultMinBytes = size_t(4) << 20;

// Populates the pages of [data, data + bytes) on every core, in 2 MiB-aligned pieces (whole transparent huge
// pages). Cost: the kernel's page clearing, split across cores; nothing for pages already present.
inline void prefault(void* data, size_t bytes) {
  if (bytes < kPrefaultMinBytes) return;
#ifdef MADV_POPULATE_WRITE
  constexpr uintptr_t kPiece = uintptr_t(2) << 20;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data), end = begin + bytes;
  const uintptr_t first = begin & ~(kPiece - 1);  // pieces [first + k * kPiece, ...), clipped to the range
  const size_t pieces = (end - first + kPiece - 1) / kPiece;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pieces), [&](const tbb::blocked_range<size_t>& r) {
    // madvise wants a page-aligned start: the range's first page is rounded down within the array's own page.
    const uintptr_t page = 4096;
    const uintptr_t from = std::max(begin, first + r.begin() * kPiece) & ~(page - 1);
    const uintptr_t to = std::min(end, first + r.end() * kPiece);
    ::madvise(reinterpret_cast<void*>(from), to - from, MADV_POPULATE_WRITE);
  });
#endif
}

// v.reserve(n), then prefault of the reserved storage: the resize, assign or push_backs that follow write to
// present pages. For an empty `v` (otherwise its elements are moved to the new storage first).
template <class T>
void reserve_prefaulted(std::vector<T>& v, size_t n) {
  v.reserve(n);
  prefault(v.data(), n * sizeof(T));
}

// reserve_prefaulted, then v.resize(n, value): an array of n values, filled on this thread into present
// pages. For an empty `v`.
template <class T>
void resize_prefaulted(std::vector<T>& v, size_t n, const T& value = T()) {
  reserve_prefaulted(v, n);
  v.resize(n, value);
}

}  // namespace lodstream
