// The residual chunk (spec §8.6): the 1.1 context model round trips and differs from the 1.0 one,
// a 1.0 payload is coded and decoded exactly with the 1.0 buckets, truncated payloads are
// truncated-stream and out-of-range values corrupt-stream.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/syntax_reader.h"
#include "dmc/topology.h"
#include "encoder/range_encoder.h"
#include "encoder/syntax_writer.h"
#include "test_support.h"

namespace dmc {
namespace {

struct Fixture {
  MeshTopology topology;
  std::vector<int32_t> order;
  Eigen::MatrixXd delta;
};

// A 12 × 12 grid and residuals of a few steps that are busier in some regions and columns than in
// others (so the contexts matter), off the grid by up to 0.3 steps.
Fixture MakeFixture(int rank, double step) {
  const MeshSequence grid = testing::PlanarGrid(12);
  Fixture f{BuildTopology(grid.triangles(), grid.vertex_count()), {}, {}};
  f.order = format::BreadthFirstOrder(f.topology);
  f.delta.resize(grid.vertex_count(), rank);
  uint32_t state = 987654321u;
  for (int k = 0; k < rank; ++k) {
    for (int v = 0; v < grid.vertex_count(); ++v) {
      state = state * 1664525u + 1013904223u;
      const int spread = (v % 12 < 6 ? 1 : 9) + (rank - k);
      const int value = static_cast<int>((state >> 8) % (2 * spread + 1)) - spread;
      f.delta(v, k) = step * (value + 0.3 * ((v + k) % 3 - 1));
    }
  }
  return f;
}

format::SegmentHeader Header(int rank, double step, uint8_t minor) {
  format::SegmentHeader header;
  header.rank = static_cast<uint32_t>(rank);
  header.residual_step = step;
  header.version_minor = minor;
  return header;
}

Status Read(const std::vector<uint8_t>& payload, const Fixture& f,
            const format::SegmentHeader& header, Eigen::MatrixXd* delta) {
  SegmentSyntax syntax;
  syntax.header = header;
  const Status status = syntax::ReadResiduals(payload, f.topology, f.order, syntax);
  if (delta) *delta = syntax.delta;
  return status;
}

TEST(ResidualSyntax, Version11RoundTrips) {
  const int rank = 6;
  const Fixture f = MakeFixture(rank, 0.01);
  const format::SegmentHeader header = Header(rank, 0.01, 1);
  Eigen::MatrixXd written, read;
  const auto payload = syntax::WriteResiduals(f.delta, f.topology, f.order, header, &written);
  ASSERT_TRUE(payload.ok()) << payload.status().ToString();
  ASSERT_TRUE(Read(*payload, f, header, &read).ok());
  EXPECT_TRUE((read.array() == written.array()).all());
  EXPECT_EQ(written(0, 0), 0.01 * std::llround(f.delta(0, 0) / 0.01));
}

// The 1.0 syntax is the 1.0 buckets exactly: the writer's 1.0 payload equals one coded here
// directly with the 1.0 rule (earlier-neighbour bucket per column group), and it decodes back.
TEST(ResidualSyntax, Version10IsCodedAndDecodedWithThe10Buckets) {
  const int rank = 20;  // column groups 0 .. 16
  const Fixture f = MakeFixture(rank, 0.02);
  const format::SegmentHeader header = Header(rank, 0.02, 0);
  Eigen::MatrixXd written, read;
  const auto payload = syntax::WriteResiduals(f.delta, f.topology, f.order, header, &written);
  ASSERT_TRUE(payload.ok());

  const format::EarlierNeighbours earlier = format::ListEarlierNeighbours(f.topology, f.order);
  auto contexts = std::make_unique<format::ResidualContexts>();
  RangeEncoder encoder;
  std::vector<int64_t> q(f.order.size());
  for (int k = 0; k < rank; ++k) {
    for (size_t i = 0; i < f.order.size(); ++i) {
      const int bucket = earlier.Bucket(q, static_cast<int>(i));
      q[i] = std::llround(f.delta(f.order[i], k) / 0.02);
      encoder.EncodeSigned(contexts->sets[format::ResidualColumnGroup(k)][bucket], q[i]);
    }
  }
  EXPECT_EQ(*payload, encoder.Finish());

  ASSERT_TRUE(Read(*payload, f, header, &read).ok());
  EXPECT_TRUE((read.array() == written.array()).all());
  // The 1.1 model codes the same values differently; read as 1.1, the 1.0 payload does not give
  // them back.
  const auto payload11 =
      syntax::WriteResiduals(f.delta, f.topology, f.order, Header(rank, 0.02, 1), nullptr);
  ASSERT_TRUE(payload11.ok());
  EXPECT_NE(*payload11, *payload);
  Eigen::MatrixXd misread;
  const Status status = Read(*payload, f, Header(rank, 0.02, 1), &misread);
  EXPECT_FALSE(status.ok() && (misread.array() == written.array()).all());
}

TEST(ResidualSyntax, Context11FollowsTheSpec) {
  // No earlier neighbour, column 0: activity 0.
  EXPECT_EQ(format::ResidualContext11(0, 0, 0, 0, 0), 0);
  // Earlier neighbours all zero: octave 0, the all-zero flag.
  EXPECT_EQ(format::ResidualContext11(0, 0, 3, 0, 0), 1);
  // Column 0 (histories ignored), mean 1: activity floor(32 · 3 / 3) / 2 = 16, bit_width 5.
  EXPECT_EQ(format::ResidualContext11(0, 3, 3, 700, 700), 10);
  // Column 1: (floor(32 · 1 / 4) + 32 + 9) / 4 = 49 / 4 = 12, bit_width 4.
  EXPECT_EQ(format::ResidualContext11(1, 1, 4, 32, 9), 8);
  // Column 2, no earlier neighbour: (16 + 0) / 2 = 8, bit_width 4.
  EXPECT_EQ(format::ResidualContext11(2, 0, 0, 16, 0), 8);
  // Neighbours and histories zero: 0 and the flag.
  EXPECT_EQ(format::ResidualContext11(5, 0, 2, 0, 0), 1);
  // Large activity saturates at the last octave.
  const auto top = static_cast<uint32_t>(16 * format::kResidualActivityClamp);
  EXPECT_EQ(format::ResidualContext11(3, format::kResidualActivityClamp * 4, 4, top, top),
            2 * (format::kResidualActivityOctaves - 1));
}

TEST(ResidualSyntax, HistoriesFollowTheSpec) {
  uint32_t fast = 12345, slow = 678;
  format::UpdateResidualHistories(0, 3, fast, slow);  // column 0 starts them: 16 · 3
  EXPECT_EQ(fast, 48u);
  EXPECT_EQ(slow, 48u);
  format::UpdateResidualHistories(1, 1, fast, slow);
  EXPECT_EQ(fast, (48u + 16u) >> 1);                                 // 32
  EXPECT_EQ(slow, (3u * 48u + 16u) >> 2);                            // 40
  format::UpdateResidualHistories(2, int64_t{1} << 40, fast, slow);  // clamped to 2^16
  EXPECT_EQ(fast, (32u + (16u << 16)) >> 1);
  EXPECT_EQ(slow, (3u * 40u + (16u << 16)) >> 2);
}

TEST(ResidualSyntax, TruncatedPayloadIsTruncatedStream) {
  const int rank = 5;
  const Fixture f = MakeFixture(rank, 0.01);
  const format::SegmentHeader header = Header(rank, 0.01, 1);
  auto payload = syntax::WriteResiduals(f.delta, f.topology, f.order, header, nullptr);
  ASSERT_TRUE(payload.ok());
  ASSERT_GT(payload->size(), 64u);
  for (const size_t keep : {size_t{0}, size_t{5}, payload->size() / 2, payload->size() - 8}) {
    std::vector<uint8_t> cut(payload->begin(), payload->begin() + static_cast<long>(keep));
    EXPECT_EQ(Read(cut, f, header, nullptr).code(), ErrorCode::kTruncatedStream) << "kept " << keep;
  }
}

// A value beyond ±2^40 steps (codable by the exp-Golomb escape) is corrupt-stream, named.
TEST(ResidualSyntax, OutOfRangeValueIsCorruptStream) {
  const int rank = 3;
  const Fixture f = MakeFixture(rank, 0.01);
  const format::SegmentHeader header = Header(rank, 0.01, 1);
  format::ResidualContextSelector selector(f.topology, f.order, 1);
  RangeEncoder encoder;
  for (int k = 0; k < rank; ++k) {
    for (size_t i = 0; i < f.order.size(); ++i) {
      const int64_t q = (k == 1 && i == 7) ? format::kMaxResidualMagnitude + 1 : 1;
      encoder.EncodeSigned(selector.Select(k, static_cast<int>(i)), q);
      selector.Record(k, static_cast<int>(i), q);
    }
  }
  const Status status = Read(encoder.Finish(), f, header, nullptr);
  EXPECT_EQ(status.code(), ErrorCode::kCorruptStream);
  EXPECT_NE(status.ToString().find("residual out of range"), std::string::npos)
      << status.ToString();
}

// Select does not change the state: asking twice (an encoder weighing candidates) gives the same
// payload as asking once.
TEST(ResidualSyntax, SelectIsSideEffectFree) {
  const int rank = 4;
  const Fixture f = MakeFixture(rank, 0.01);
  const auto payload =
      syntax::WriteResiduals(f.delta, f.topology, f.order, Header(rank, 0.01, 1), nullptr);
  ASSERT_TRUE(payload.ok());
  format::ResidualContextSelector selector(f.topology, f.order, 1);
  RangeEncoder encoder;
  for (int k = 0; k < rank; ++k) {
    for (size_t i = 0; i < f.order.size(); ++i) {
      const int index = static_cast<int>(i);
      (void)selector.Select(k, index);
      const int64_t q = std::llround(f.delta(f.order[i], k) / 0.01);
      encoder.EncodeSigned(selector.Select(k, index), q);
      selector.Record(k, index, q);
    }
  }
  EXPECT_EQ(encoder.Finish(), *payload);
}

}  // namespace
}  // namespace dmc
