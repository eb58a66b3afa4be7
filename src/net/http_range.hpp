// HTTP byte ranges (RFC 9110 §14): parsing a Range header against a representation's length. Beast 1.74 has
// no Range support, so this is ours. Pure computation, no I/O.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace lodstream {

struct ByteRange {
  uint64_t first = 0;  // inclusive
  uint64_t last = 0;   // inclusive
  uint64_t size() const { return last - first + 1; }
};

struct RangeRequest {
  enum class Kind {
    kNone,         // no Range header, or one to ignore (not "bytes=", malformed): answer 200 with everything
    kSatisfiable,  // answer 206 with `ranges` (one: a single part; several: multipart/byteranges)
    kUnsatisfiable,  // answer 416 with "Content-Range: bytes */length"
  };
  Kind kind = Kind::kNone;
  std::vector<ByteRange> ranges;  // sorted by first byte, overlapping or adjacent ranges merged
};

// Parses `header` ("bytes=0-499", "bytes=500-", "bytes=-500", "bytes=0-0,10-20") for a representation of
// `length` bytes. Ranges past the end are clipped; ranges that start past the end are dropped; if none is
// left the request is unsatisfiable. More than `max_ranges` ranges (a denial-of-service vector) make the
// header ignored. Cost: O(n log n) in the number of ranges.
RangeRequest parse_range(std::string_view header, uint64_t length, size_t max_ranges = 64);

// "bytes FIRST-LAST/LENGTH", the Content-Range of one part.
std::string content_range(const ByteRange& range, uint64_t length);

}  // namespace lodstream
