// ReplaceInvalidUtf8: valid UTF-8 passes unchanged; every byte outside a well-formed sequence
// (stray continuation bytes, overlong forms, surrogates, code points past U+10FFFF, truncated
// sequences) becomes U+FFFD, and the result is always valid.
#include "io/utf8_text.h"

#include <gtest/gtest.h>

#include <string>

namespace dmc::io_internal {
namespace {

const std::string kReplacement = "\xEF\xBF\xBD";

TEST(ReplaceInvalidUtf8, KeepsValidText) {
  for (const std::string& text : {std::string(), std::string("crane-full"),
                                  std::string("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x90\x8E"),
                                  std::string("\xED\x9F\xBF\xEE\x80\x80\xF4\x8F\xBF\xBF")}) {
    EXPECT_EQ(ReplaceInvalidUtf8(text), text);
  }
}

TEST(ReplaceInvalidUtf8, ReplacesEachByteOutsideAWellFormedSequence) {
  EXPECT_EQ(ReplaceInvalidUtf8("a\xFF"
                               "b"),
            "a" + kReplacement + "b");
  EXPECT_EQ(ReplaceInvalidUtf8("\x80"), kReplacement);                     // stray continuation
  EXPECT_EQ(ReplaceInvalidUtf8("\xC0\xAF"), kReplacement + kReplacement);  // overlong '/'
  EXPECT_EQ(ReplaceInvalidUtf8("\xE0\x80\xAF"), kReplacement + kReplacement + kReplacement);
  EXPECT_EQ(ReplaceInvalidUtf8("\xED\xA0\x80"), kReplacement + kReplacement + kReplacement);
  EXPECT_EQ(ReplaceInvalidUtf8("\xF4\x90\x80\x80"),
            kReplacement + kReplacement + kReplacement + kReplacement);           // past U+10FFFF
  EXPECT_EQ(ReplaceInvalidUtf8("x\xE2\x82"), "x" + kReplacement + kReplacement);  // truncated
  // A valid sequence right after an invalid byte survives.
  EXPECT_EQ(ReplaceInvalidUtf8("\xC3\xC3\xA9"), kReplacement + "\xC3\xA9");
}

TEST(ReplaceInvalidUtf8, EveryByteValueGivesValidText) {
  for (int byte = 0; byte < 256; ++byte) {
    const std::string once = ReplaceInvalidUtf8(std::string(1, static_cast<char>(byte)) + "\xE2");
    EXPECT_EQ(ReplaceInvalidUtf8(once), once) << byte;  // valid: a second pass changes nothing
  }
}

}  // namespace
}  // namespace dmc::io_internal
