#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "decoder/range_decoder.h"
#include "encoder/bit_cost.h"
#include "encoder/range_encoder.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

TEST(RangeCoder, RoundTripsMixedSyntax) {
  std::mt19937_64 rng(7);
  std::geometric_distribution<int> small(0.3);
  std::vector<int64_t> signed_values;
  std::vector<uint64_t> unsigned_values;
  std::vector<int> bits;
  for (int i = 0; i < 20000; ++i) {
    const int64_t magnitude = (i % 97 == 0) ? static_cast<int64_t>(rng() >> 30) : small(rng);
    signed_values.push_back((rng() & 1) ? magnitude : -magnitude);
    unsigned_values.push_back(static_cast<uint64_t>(small(rng)) * ((i % 501 == 0) ? 1000003 : 1));
    bits.push_back((rng() % 10) < 2);
  }
  signed_values.push_back(int64_t{1} << 61);
  signed_values.push_back(-(int64_t{1} << 61));
  unsigned_values.push_back(uint64_t{1} << 50);
  bits.push_back(1);
  bits.push_back(0);

  RangeEncoder encoder;
  IntegerContexts s_ctx, u_ctx;
  AdaptiveBit bit_ctx;
  for (size_t i = 0; i < signed_values.size(); ++i) {
    encoder.EncodeSigned(s_ctx, signed_values[i]);
    if (i < unsigned_values.size()) encoder.EncodeUnsigned(u_ctx, unsigned_values[i]);
    if (i < bits.size()) encoder.EncodeBit(bit_ctx, bits[i]);
    if (i % 3 == 0) encoder.EncodeBypassBits(i & 0x1f, 5);
  }
  const std::vector<uint8_t> bytes = encoder.Finish();

  RangeDecoder decoder;
  ASSERT_TRUE(decoder.Init(bytes).ok());
  IntegerContexts ds_ctx, du_ctx;
  AdaptiveBit dbit_ctx;
  for (size_t i = 0; i < signed_values.size(); ++i) {
    int64_t s;
    ASSERT_TRUE(decoder.DecodeSigned(ds_ctx, &s).ok());
    ASSERT_EQ(s, signed_values[i]) << "at " << i;
    if (i < unsigned_values.size()) {
      uint64_t u;
      ASSERT_TRUE(decoder.DecodeUnsigned(du_ctx, &u).ok());
      ASSERT_EQ(u, unsigned_values[i]) << "at " << i;
    }
    if (i < bits.size()) {
      ASSERT_EQ(decoder.DecodeBit(dbit_ctx), bits[i]) << "at " << i;
    }
    if (i % 3 == 0) {
      ASSERT_EQ(decoder.DecodeBypassBits(5), i & 0x1f);
    }
  }
  EXPECT_FALSE(decoder.overrun());
}

TEST(RangeCoder, SkewedBitsCompressNearEntropy) {
  std::mt19937 rng(3);
  RangeEncoder encoder;
  AdaptiveBit model;
  const int count = 100000;
  for (int i = 0; i < count; ++i) encoder.EncodeBit(model, (rng() % 100) < 5);
  const double bits_per_symbol = 8.0 * static_cast<double>(encoder.Finish().size()) / count;
  // H(0.05) = 0.286 bits; an adaptive model pays a little more.
  EXPECT_LT(bits_per_symbol, 0.31);
  EXPECT_GT(bits_per_symbol, 0.28);
}

TEST(RangeCoder, EveryTruncationIsReported) {
  RangeEncoder encoder;
  IntegerContexts ctx;
  for (int i = 0; i < 200; ++i) encoder.EncodeSigned(ctx, (i * 37) % 23 - 11);
  const std::vector<uint8_t> bytes = encoder.Finish();
  for (size_t length = 0; length < bytes.size(); ++length) {
    RangeDecoder decoder;
    const Status init = decoder.Init(std::span<const uint8_t>(bytes.data(), length));
    if (!init.ok()) {
      EXPECT_EQ(init.code(), ErrorCode::kTruncatedStream);
      continue;
    }
    IntegerContexts dctx;
    Status status;
    for (int i = 0; i < 200 && status.ok(); ++i) {
      int64_t value;
      status = decoder.DecodeSigned(dctx, &value);
    }
    if (status.ok()) status = decoder.CheckNotOverrun("test");
    EXPECT_FALSE(status.ok()) << "length " << length;
  }
}

TEST(RangeCoder, RejectsNonZeroLeadByte) {
  const std::vector<uint8_t> bytes = {1, 0, 0, 0, 0};
  RangeDecoder decoder;
  EXPECT_EQ(decoder.Init(bytes).code(), ErrorCode::kCorruptStream);
}

TEST(ByteIo, VarintsRoundTripAndTruncationIsNamed) {
  ByteWriter writer;
  const std::vector<int64_t> values = {
      0, 1, -1, 63, -64, 1 << 20, -(int64_t{1} << 40), INT64_MAX, INT64_MIN};
  for (int64_t v : values) writer.PutVarS(v);
  writer.PutF64(3.25);
  writer.PutString("samba");
  ByteReader reader(writer.bytes());
  for (int64_t v : values) {
    int64_t got;
    ASSERT_TRUE(reader.GetVarS(&got, "v").ok());
    EXPECT_EQ(got, v);
  }
  double f;
  ASSERT_TRUE(reader.GetF64(&f, "f").ok());
  EXPECT_EQ(f, 3.25);
  std::string name;
  ASSERT_TRUE(reader.GetString(&name, 64, "name").ok());
  EXPECT_EQ(name, "samba");
  EXPECT_TRUE(reader.at_end());
  uint8_t byte;
  const Status status = reader.GetU8(&byte, "segment count");
  EXPECT_EQ(status.code(), ErrorCode::kTruncatedStream);
  EXPECT_NE(status.message().find("segment count"), std::string::npos);
}

// The encoder's rate estimate (encoder/bit_cost.h) is what the range coder spends: the summed
// costs of 50 000 values, each taken under the contexts' state just before coding it, match the
// payload's size (escapes included) within 0.5 %.
TEST(BitCost, SignedCostSumsToThePayloadSize) {
  std::mt19937_64 rng(11);
  std::geometric_distribution<int> small(0.35);
  RangeEncoder encoder;
  IntegerContexts contexts[2];
  double estimated_bits = 0.0;
  for (int i = 0; i < 50000; ++i) {
    const int64_t magnitude = (i % 211 == 0) ? static_cast<int64_t>(rng() >> 44) : small(rng);
    const int64_t value = (rng() & 1) ? magnitude : -magnitude;
    IntegerContexts& chosen = contexts[(i / 7) % 2];
    estimated_bits += SignedCost(chosen, value);
    encoder.EncodeSigned(chosen, value);
  }
  const double coded_bits = 8.0 * static_cast<double>(encoder.Finish().size());
  EXPECT_NEAR(estimated_bits / coded_bits, 1.0, 0.005) << estimated_bits << " vs " << coded_bits;
}

// RdoLevel: plain rounding at λ = 0 and for values that round to zero; otherwise the nearest
// level or the next toward zero, whichever has the lower squared error + λ · bits.
TEST(BitCost, RdoLevelChoosesBetweenTheNearestLevelAndTheNextTowardZero) {
  IntegerContexts contexts;
  RangeEncoder warm_up;
  for (int i = 0; i < 200; ++i) warm_up.EncodeSigned(contexts, i % 5 == 0 ? 1 : 0);
  for (const double steps : {-2.5, -1.4, -0.6, -0.2, 0.0, 0.3, 0.7, 1.45, 2.5, 3.2}) {
    EXPECT_EQ(RdoLevel(steps, contexts, 0.0), std::llround(steps)) << steps;
  }
  EXPECT_EQ(RdoLevel(0.4, contexts, 10.0), 0);
  // Zero is far cheaper than ±1 under these contexts: a large λ moves 0.7 to 0, a tiny one not.
  EXPECT_EQ(RdoLevel(0.7, contexts, 1.0), 0);
  EXPECT_EQ(RdoLevel(-0.7, contexts, 1.0), 0);
  EXPECT_EQ(RdoLevel(0.7, contexts, 1e-3), 1);
  // Never away from zero, never by more than one level.
  for (const double steps : {-5.3, -1.6, 1.6, 5.3}) {
    const int64_t level = RdoLevel(steps, contexts, 100.0);
    const int64_t nearest = std::llround(steps);
    EXPECT_TRUE(level == nearest || level == nearest - (nearest > 0 ? 1 : -1)) << steps;
  }
}

}  // namespace
}  // namespace dmc
