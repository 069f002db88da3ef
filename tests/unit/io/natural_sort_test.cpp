#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "dmc/io.h"

namespace dmc {
namespace {

TEST(NaturalLessTest, DigitRunsCompareByValue) {
  EXPECT_TRUE(NaturalLess("2.obj", "10.obj"));
  EXPECT_FALSE(NaturalLess("10.obj", "2.obj"));
  EXPECT_TRUE(NaturalLess("frame9.obj", "frame10.obj"));
  EXPECT_TRUE(NaturalLess("x1y2", "x1y10"));
  EXPECT_TRUE(NaturalLess("mesh_0002.obj", "mesh_0010.obj"));
  EXPECT_TRUE(NaturalLess("99", "100"));
  // Values far beyond 64 bits still compare by length, then digits.
  EXPECT_TRUE(NaturalLess("f123456789012345678901", "f1234567890123456789010"));
}

TEST(NaturalLessTest, OtherCharactersCompareByByte) {
  EXPECT_TRUE(NaturalLess("a", "b"));
  EXPECT_TRUE(NaturalLess("a", "a1"));  // a prefix sorts first
  EXPECT_TRUE(NaturalLess("cat-01.obj", "cat-reference.obj"));
  EXPECT_TRUE(NaturalLess("B", "a"));  // case-sensitive, byte order
}

TEST(NaturalLessTest, IsAStrictTotalOrder) {
  EXPECT_FALSE(NaturalLess("abc10", "abc10"));
  // Equal in value, different in leading zeros: exactly one order holds, and it is stable.
  EXPECT_NE(NaturalLess("007", "7"), NaturalLess("7", "007"));
  EXPECT_TRUE(NaturalLess("007", "7"));
  EXPECT_TRUE(NaturalLess("7", "08"));
  EXPECT_TRUE(NaturalLess("007", "08"));
}

TEST(NaturalLessTest, SortsAShuffledFrameList) {
  const std::vector<std::string> expected = {"1.obj",  "2.obj",   "3.obj",  "9.obj",
                                             "10.obj", "11.obj",  "20.obj", "100.obj",
                                             "a2.obj", "a10.obj", "b.obj"};
  std::vector<std::string> names = expected;
  std::mt19937 random(7);
  for (int trial = 0; trial < 20; ++trial) {
    std::shuffle(names.begin(), names.end(), random);
    std::sort(names.begin(), names.end(), NaturalLess);
    EXPECT_EQ(names, expected);
  }
}

}  // namespace
}  // namespace dmc
