// Tokenizer over the bytes of a text model file (PLY ascii body, OFF), with the line number for errors.
// Hand-written because the readers need in-place, allocation-free parsing of millions of numbers
// (std::from_chars does the conversions).
#pragma once

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace lodstream {

class TextCursor {
 public:
  // `comment` is the character that starts a comment running to the end of the line ('\0': none).
  TextCursor(const char* begin, const char* end, std::string file, char comment = '\0')
      : p_(begin), end_(end), file_(std::move(file)), comment_(comment) {}

  size_t line() const { return line_; }
  const char* position() const { return p_; }
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  const std::string& file() const { return file_; }

  // Skips blanks, line breaks and comments.
  void skip_space() {
    while (p_ < end_) {
      char c = *p_;
      if (c == '\n') {
        ++line_;
        ++p_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p_;
      } else if (comment_ != '\0' && c == comment_) {
        while (p_ < end_ && *p_ != '\n') ++p_;
      } else {
        break;
      }
    }
  }

  // Skips blanks and comments but stops at the end of the current line; true when the line has more tokens.
  bool more_on_line() {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r' || *p_ == '\f' || *p_ == '\v')) ++p_;
    if (p_ < end_ && comment_ != '\0' && *p_ == comment_)
      while (p_ < end_ && *p_ != '\n') ++p_;
    return p_ < end_ && *p_ != '\n';
  }

  // Moves past the end of the current line.
  void next_line() {
    while (p_ < end_ && *p_ != '\n') ++p_;
    if (p_ < end_) {
      ++p_;
      ++line_;
    }
  }

  // The next whitespace-separated token (empty at the end of the input).
  std::string_view token() {
    skip_space();
    const char* start = p_;
    while (p_ < end_ && !is_space(*p_) && !(comment_ != '\0' && *p_ == comment_)) ++p_;
    return {start, static_cast<size_t>(p_ - start)};
  }

  template <class T>
  T number(const char* what) {
    std::string_view t = token();
    T value{};
    auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (t.empty() || ec != std::errc() || ptr != t.data() + t.size())
      fail(std::string("expected ") + what +
           (t.empty() ? ", found end of file" : ", found '" + clip(t) + "'"));
    return value;
  }

  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(file_ + ":" + std::to_string(line_) + ": " + reason);
  }

 private:
  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }
  static std::string clip(std::string_view t) {
    std::string s(t.substr(0, 32));
    for (char& c : s)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    return s;
  }

  const char* p_;
  const char* end_;
  std::string file_;
  char comment_;
  size_t line_ = 1;
};

}  // namespace lodstream
