// The basis chunk (spec §8.3): the 1.0 syntax and the 1.1 per-column bit depths round trip,
// decode to exactly what the writer reports, and reject corrupt depths and truncated payloads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "decoder/basis_reader.h"
#include "encoder/basis_writer.h"

namespace dmc {
namespace {

// A 3F × rank basis of smooth and noisy columns, entries in [-1, 1].
Eigen::MatrixXd TestBasis(int frames, int rank) {
  Eigen::MatrixXd basis(3 * frames, rank);
  uint32_t state = 12345;
  for (int k = 0; k < rank; ++k) {
    for (int r = 0; r < 3 * frames; ++r) {
      state = state * 1664525u + 1013904223u;
      const double noise = static_cast<double>(state >> 8) / double{1 << 24} - 0.5;
      basis(r, k) = 0.3 * std::sin(0.05 * (k + 1) * r + k) + 0.02 * k * noise;
    }
  }
  return basis;
}

format::SegmentHeader Header(int frames, int rank, int basis_bits) {
  format::SegmentHeader header;
  header.frame_count = static_cast<uint32_t>(frames);
  header.rank = static_cast<uint32_t>(rank);
  header.basis_bits = static_cast<uint8_t>(basis_bits);
  return header;
}

TEST(BasisSyntax, Version11RoundTripsPerColumnDepths) {
  const int frames = 30, rank = 7;
  const format::SegmentHeader header = Header(frames, rank, 14);
  const std::vector<uint8_t> depths = {14, 12, 12, 9, 5, 2, 3};
  Eigen::MatrixXd written;
  const std::vector<uint8_t> payload =
      syntax::WriteBasis(TestBasis(frames, rank), header, depths, &written);
  SegmentSyntax syntax;
  syntax.header = header;
  ASSERT_TRUE(syntax::ReadBasis(payload, syntax, 1).ok());
  EXPECT_EQ(syntax.basis, written);
  // Column k sits on the grid of its own depth.
  for (int k = 0; k < rank; ++k) {
    const double levels = std::exp2(depths[k] - 1) - 1;
    for (int r = 0; r < 3 * frames; ++r) {
      const double q = written(r, k) * levels;
      EXPECT_NEAR(q, std::round(q), 1e-9);
    }
  }
}

TEST(BasisSyntax, Version10StillDecodes) {
  const int frames = 20, rank = 5;
  const format::SegmentHeader header = Header(frames, rank, 10);
  Eigen::MatrixXd written;
  const std::vector<uint8_t> payload =
      syntax::WriteBasis(TestBasis(frames, rank), header, &written);
  SegmentSyntax syntax;
  syntax.header = header;
  ASSERT_TRUE(syntax::ReadBasis(payload, syntax, 0).ok());
  EXPECT_EQ(syntax.basis, written);
}

TEST(BasisSyntax, LowerRankIsTheFirstColumns) {
  const int frames = 16, rank = 6;
  const Eigen::MatrixXd basis = TestBasis(frames, rank);
  const std::vector<uint8_t> depths = {12, 11, 9, 7, 4, 2};
  Eigen::MatrixXd top, lower;
  (void)syntax::WriteBasis(basis, Header(frames, rank, 12), depths, &top);
  (void)syntax::WriteBasis(basis.leftCols(3), Header(frames, 3, 12), depths, &lower);
  EXPECT_EQ(lower, top.leftCols(3));
}

TEST(BasisSyntax, DepthOutsideRangeIsCorrupt) {
  const int frames = 12, rank = 3;
  for (const std::vector<uint8_t>& depths :
       {std::vector<uint8_t>{10, 11, 8}, std::vector<uint8_t>{10, 1, 8}}) {
    Eigen::MatrixXd written;
    const std::vector<uint8_t> payload =
        syntax::WriteBasis(TestBasis(frames, rank), Header(frames, rank, 10), depths, &written);
    SegmentSyntax syntax;
    syntax.header = Header(frames, rank, 10);
    EXPECT_EQ(syntax::ReadBasis(payload, syntax, 1).code(), ErrorCode::kCorruptStream);
  }
}

TEST(BasisSyntax, TruncatedPayloadIsTruncated) {
  const int frames = 40, rank = 6;
  const format::SegmentHeader header = Header(frames, rank, 12);
  const std::vector<uint8_t> depths = {12, 12, 10, 9, 8, 6};
  Eigen::MatrixXd written;
  std::vector<uint8_t> payload =
      syntax::WriteBasis(TestBasis(frames, rank), header, depths, &written);
  ASSERT_GT(payload.size(), 40u);
  payload.resize(payload.size() / 2);
  SegmentSyntax syntax;
  syntax.header = header;
  EXPECT_EQ(syntax::ReadBasis(payload, syntax, 1).code(), ErrorCode::kTruncatedStream);
}

TEST(BasisSyntax, DepthsFollowTheEigenvalues) {
  const double step = 0.001;
  const int vertices = 1000;
  // λ = V · (levels · Δ)² · share needs `levels` levels.
  const std::vector<double> eigenvalues = {
      vertices * std::pow(1000 * step, 2) * syntax::kBasisErrorShare,
      vertices * std::pow(20 * step, 2) * syntax::kBasisErrorShare, 0.0};
  const std::vector<uint8_t> depths = syntax::ChooseBasisDepths(eigenvalues, 3, vertices, step, 16);
  EXPECT_EQ(depths, (std::vector<uint8_t>{11, 6, 2}));  // 1023 >= 1000, 31 >= 20, the minimum
  EXPECT_EQ(syntax::ChooseBasisDepths(eigenvalues, 1, vertices, step, 9), std::vector<uint8_t>{9});
}

}  // namespace
}  // namespace dmc
