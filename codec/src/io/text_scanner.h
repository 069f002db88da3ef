// Internal: strict, allocation-free scanning of text mesh files (lines, tokens, numbers).
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>

namespace dmc::io_internal {

// Iterates the lines of a text, accepting "\n" and "\r\n" endings.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  // Sets `line` to the next line without its terminator; false once the text is exhausted.
  bool Next(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    const char* begin = text_.data() + position_;
    const void* newline = std::memchr(begin, '\n', text_.size() - position_);
    size_t length = newline ? static_cast<size_t>(static_cast<const char*>(newline) - begin)
                            : text_.size() - position_;
    position_ += length + (newline ? 1 : 0);
    if (length > 0 && begin[length - 1] == '\r') --length;
    line = std::string_view(begin, length);
    ++line_number_;
    return true;
  }

  int line_number() const { return line_number_; }  // 1-based number of the last line returned
  size_t position() const { return position_; }     // byte offset of the next line

 private:
  std::string_view text_;
  size_t position_ = 0;
  int line_number_ = 0;
};

inline bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

// Splits a line into whitespace-separated tokens.
class TokenReader {
 public:
  explicit TokenReader(std::string_view line) : line_(line) {}

  // Sets `token` to the next token; false when none is left.
  bool Next(std::string_view& token) {
    while (position_ < line_.size() && IsBlank(line_[position_])) ++position_;
    if (position_ >= line_.size()) return false;
    const size_t start = position_;
    while (position_ < line_.size() && !IsBlank(line_[position_])) ++position_;
    token = line_.substr(start, position_ - start);
    return true;
  }
  // True when only blanks remain.
  bool AtEnd() {
    while (position_ < line_.size() && IsBlank(line_[position_])) ++position_;
    return position_ >= line_.size();
  }
  std::string_view Rest() const { return line_.substr(position_); }

 private:
  std::string_view line_;
  size_t position_ = 0;
};

// Parses a whole token as a number, correctly rounded to T (from_chars: no locale, exact
// rounding, "nan"/"inf" accepted so that validation, not the parser, reports them with their
// frame and vertex). A leading '+' is accepted, trailing characters are not.
template <typename T>
bool ParseNumber(std::string_view token, T& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  return error == std::errc() && stop == end;
}

// The line with leading blanks removed.
inline std::string_view TrimLeft(std::string_view line) {
  size_t i = 0;
  while (i < line.size() && IsBlank(line[i])) ++i;
  return line.substr(i);
}

// For error messages: a token quoted and cut to a readable length.
inline std::string Quote(std::string_view token) {
  constexpr size_t kMax = 40;
  std::string out = "'";
  out.append(token.substr(0, kMax));
  if (token.size() > kMax) out += "...";
  out += "'";
  return out;
}

}  // namespace dmc::io_internal
