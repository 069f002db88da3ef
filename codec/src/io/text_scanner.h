// Internal: strict, allocation-free scanning of text mesh files (lines, tokens, numbers).
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

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

enum class NumberParse { kOk, kNotANumber, kOutOfRange };

// Parses a whole token as a number, correctly rounded to T (from_chars: no locale, exact
// rounding, "nan"/"inf" accepted so that validation, not the parser, reports them with their
// frame and vertex). A leading '+' is accepted, trailing characters are not. kOutOfRange: a
// well-formed number beyond T's range (1e300 for a float, 2^63 for an int64_t). A real number too
// small for T is not out of range: it rounds to a zero of its sign, as strtof would give.
template <typename T>
NumberParse ParseNumberChecked(std::string_view token, T& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return NumberParse::kNotANumber;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  if (stop != end) return NumberParse::kNotANumber;
  if (error == std::errc()) return NumberParse::kOk;
  if (error != std::errc::result_out_of_range) return NumberParse::kNotANumber;
  if constexpr (std::is_floating_point_v<T>) {
    // from_chars reports underflow and overflow alike; a wider type tells them apart.
    long double wide = 0.0L;
    const auto [wide_stop, wide_error] = std::from_chars(token.data(), end, wide);
    if (wide_stop == end && wide_error == std::errc() && std::fabs(wide) < 1.0L) {
      value = std::signbit(wide) ? -T(0) : T(0);
      return NumberParse::kOk;
    }
  }
  return NumberParse::kOutOfRange;
}

template <typename T>
bool ParseNumber(std::string_view token, T& value) {
  return ParseNumberChecked(token, value) == NumberParse::kOk;
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

// What is wrong with coordinate `axis` (0, 1, 2 for x, y, z) of vertex `vertex` (counted from 0)
// whose token `token` did not parse (`result` not kOk), e.g. "vertex 12, coordinate y: '1e300' is
// out of float32 range (at most 3.4028235e+38 in magnitude)".
inline std::string CoordinateProblem(std::string_view token, NumberParse result, int64_t vertex,
                                     int axis) {
  return "vertex " + std::to_string(vertex) + ", coordinate " + "xyz"[axis] + ": " + Quote(token) +
         (result == NumberParse::kOutOfRange
              ? " is out of float32 range (at most 3.4028235e+38 in magnitude)"
              : " is not a number");
}

}  // namespace dmc::io_internal
