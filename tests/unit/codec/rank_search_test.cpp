// The automatic rank's search (EncoderOptions::rank_search): with the ddl operator's per-segment
// choice, each segment is also coded at the ranks of 1/4, 2 and 4 times the rank threshold, and
// the coding with the lowest bits · STED^1.3 is kept.
#include <gtest/gtest.h>

#include <cmath>

#include "dmc/encoder.h"
#include "dmc/synth.h"

namespace dmc {
namespace {

// One segment of 16 frames: the measured frames are all frames, so the report's STED is the one
// the search compared.
MeshSequence Blob() {
  SynthOptions options;
  options.frames = 16;
  options.resolution = 1500;
  return *Synthesize("blob", options);
}

double BitsTimesStedPower(const EncodeReport& report) {
  return static_cast<double>(report.bytes) * std::pow(report.distortion.sted, 1.3);
}

TEST(RankSearch, ChangesTheRankOnlyWhenThatCostsLess) {
  const MeshSequence original = Blob();
  int changed = 0;
  for (const int bits : {8, 10, 12}) {
    EncoderOptions options;
    options.residual_bits = bits;
    EncodeReport searched, plain;
    auto searched_bytes = Encode(original, options, &searched);
    ASSERT_TRUE(searched_bytes.ok()) << searched_bytes.status().ToString();
    options.rank_search = false;
    auto plain_bytes = Encode(original, options, &plain);
    ASSERT_TRUE(plain_bytes.ok()) << plain_bytes.status().ToString();
    if (searched.rank != plain.rank) ++changed;
    // The search compares payload bits without the stream's fixed parts (connectivity,
    // headers), and below its top rank it reuses the top rank's operator and weights, so the
    // whole stream's product may differ from its choice by a few percent.
    EXPECT_LE(BitsTimesStedPower(searched), 1.03 * BitsTimesStedPower(plain)) << "bits " << bits;
  }
  // On this animation another rank wins on at least one rung.
  EXPECT_GE(changed, 1);
}

TEST(RankSearch, IsOffForAFixedRankAndForOtherOperators) {
  const MeshSequence original = Blob();
  for (const char* name : {"ddl", "tutte"}) {
    EncoderOptions options;
    options.operator_name = name;
    options.residual_bits = 10;
    if (std::string(name) == "ddl") options.rank = 5;
    auto searched = Encode(original, options);
    options.rank_search = false;
    auto plain = Encode(original, options);
    ASSERT_TRUE(searched.ok() && plain.ok());
    EXPECT_EQ(*searched, *plain) << name;
  }
}

}  // namespace
}  // namespace dmc
