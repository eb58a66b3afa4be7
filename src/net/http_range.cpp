#include "net/http_range.hpp"

#include <algorithm>
#include <charconv>

namespace lodstream {

namespace {
std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool parse_u64(std::string_view s, uint64_t& out) {
  if (s.empty() || s.size() > 19) return false;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size();
}
}  // namespace

RangeRequest parse_range(std::string_view header, uint64_t length, size_t max_ranges) {
  RangeRequest none;
  header = trim(header);
  if (header.substr(0, 6) != "bytes=") return none;
  header.remove_prefix(6);
  std::vector<ByteRange> ranges;
  size_t specs = 0;
  while (!header.empty()) {
    size_t comma = header.find(',');
    std::string_view spec = trim(header.substr(0, comma));
    header = comma == std::string_view::npos ? std::string_view() : header.substr(comma + 1);
    if (spec.empty()) continue;  // "bytes=0-1,,2-3": empty list elements are allowed
    if (++specs > max_ranges) return none;
    size_t dash = spec.find('-');
    if (dash == std::string_view::npos) return none;
    std::string_view a = trim(spec.substr(0, dash)), b = trim(spec.substr(dash + 1));
    uint64_t first = 0, last = 0;
    if (a.empty()) {  // suffix: the last N bytes
      if (!parse_u64(b, last)) return none;
      if (last == 0 || length == 0) continue;
      ranges.push_back({length - std::min(last, length), length - 1});
    } else {
      if (!parse_u64(a, first)) return none;
      if (b.empty()) {
        last = UINT64_MAX;
      } else if (!parse_u64(b, last) || last < first) {
        return none;
      }
      if (first >= length) continue;
      ranges.push_back({first, std::min(last, length - 1)});
    }
  }
  if (specs == 0) return none;
  RangeRequest r;
  if (ranges.empty()) {
    r.kind = RangeRequest::Kind::kUnsatisfiable;
    return r;
  }
  std::sort(ranges.begin(), ranges.end(),
            [](const ByteRange& x, const ByteRange& y) { return x.first < y.first; });
  for (const auto& range : ranges) {
    if (!r.ranges.empty() && range.first <= r.ranges.back().last + 1)
      r.ranges.back().last = std::max(r.ranges.back().last, range.last);
    else
      r.ranges.push_back(range);
  }
  r.kind = RangeRequest::Kind::kSatisfiable;
  return r;
}

std::string content_range(const ByteRange& range, uint64_t length) {
  return "bytes " + std::to_string(range.first) + "-" + std::to_string(range.last) + "/" +
         std::to_string(length);
}

}  // namespace lodstream
