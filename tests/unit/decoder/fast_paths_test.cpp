// The decoder's fast paths give bit for bit what the straightforward computations give (issue 7:
// a faster decoder must output the same frames): the normal matrix against Eigen's LᵀL + diagonal
// (pattern and every value), the parallel, column-blocked sparse solve against CHOLMOD solving the
// same blocks on one thread (and one solve of all columns to rounding), and the frame synthesis
// against the plain blockwise product + mean + conversion it replaced.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <hwy/targets.h>

#if DMC_WITH_CHOLMOD
#include <Eigen/CholmodSupport>
#endif
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "decoder/segment_reconstruction.h"
#include "decoder/synthesis_kernel.h"
#include "dmc/operators.h"
#include "dmc/simd.h"
#include "dmc/wire_ids.h"
#include "solvers/blas_threads.h"
#include "test_support.h"

namespace dmc {
namespace {

#if DMC_WITH_CHOLMOD
// Tutte normal matrix of a 40 × 40 grid with four anchors: 1600 unknowns, enough for CHOLMOD's
// supernodes and BLAS kernels to be involved.
SparseMatrixD GridNormalMatrix() {
  const MeshSequence grid = testing::PlanarGrid(40);
  const MeshTopology topology = BuildTopology(grid.triangles(), grid.vertex_count());
  const auto tutte = RebuildOperator(OperatorId::kTutte, topology, nullptr, nullptr);
  EXPECT_TRUE(tutte.ok());
  return BuildNormalMatrix(tutte->matrix, std::vector<int32_t>{0, 39, 800, 1599});
}
#endif

// The normal matrix as BuildNormalMatrix computed it before it was rewritten as one parallel pass.
SparseMatrixD ReferenceNormalMatrix(const SparseMatrixD& laplacian,
                                    std::span<const int32_t> anchors, double anchor_weight) {
  SparseMatrixD normal = SparseMatrixD(laplacian.transpose()) * laplacian;
  Eigen::VectorXd anchor_diagonal = Eigen::VectorXd::Zero(laplacian.cols());
  for (const int32_t a : anchors) anchor_diagonal[a] += anchor_weight * anchor_weight;
  SparseMatrixD diagonal(laplacian.cols(), laplacian.cols());
  diagonal.setIdentity();
  diagonal = anchor_diagonal.asDiagonal() * diagonal;
  normal += diagonal;
  normal.makeCompressed();
  return normal;
}

// Same pattern, and the same bits in every value (memcmp: +0 and -0 differ).
void ExpectIdenticalSparse(const SparseMatrixD& actual, const SparseMatrixD& expected) {
  ASSERT_TRUE(actual.isCompressed());
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  ASSERT_EQ(actual.nonZeros(), expected.nonZeros());
  const auto outer = static_cast<size_t>(actual.cols()) + 1;
  const auto count = static_cast<size_t>(actual.nonZeros());
  EXPECT_EQ(std::memcmp(actual.outerIndexPtr(), expected.outerIndexPtr(), outer * sizeof(int)), 0);
  EXPECT_EQ(std::memcmp(actual.innerIndexPtr(), expected.innerIndexPtr(), count * sizeof(int)), 0);
  EXPECT_EQ(std::memcmp(actual.valuePtr(), expected.valuePtr(), count * sizeof(double)), 0);
}

TEST(DecoderFastPaths, NormalMatrixEqualsEigenProductPlusDiagonal) {
  // 30 × 30 grid plus one isolated vertex (no triangle: an empty column of L, so LᵀL lacks its
  // diagonal entry), 901 vertices: two 512-column chunks.
  const MeshSequence grid = testing::PlanarGrid(30);
  const int v_count = grid.vertex_count() + 1;
  const MeshTopology topology = BuildTopology(grid.triangles(), v_count);
  std::vector<SparseMatrixD> laplacians;
  for (const OperatorId id : {OperatorId::kTutte, OperatorId::kKirchhoff}) {
    const auto op = RebuildOperator(id, topology, nullptr, nullptr);
    ASSERT_TRUE(op.ok()) << op.status().ToString();
    laplacians.push_back(op->matrix);
  }
  // DDL-style weights: varied signs and magnitudes, and exact zeros (products of ±0).
  OperatorWeights weights;
  weights.layout = WeightLayout::kPerEdge;
  for (int e = 0; e < topology.edge_count(); ++e) {
    weights.values.push_back(e % 7 == 0 ? 0.0 : (e % 3 == 0 ? -0.3 : 0.1) * (1 + e % 5));
  }
  const auto ddl = RebuildOperator(OperatorId::kDdl, topology, nullptr, &weights);
  ASSERT_TRUE(ddl.ok()) << ddl.status().ToString();
  laplacians.push_back(ddl->matrix);
  // Anchors: a repeated one, the isolated vertex, and one in each corner.
  const std::vector<int32_t> anchors = {0, 29, 29, 870, 899, 900};
  for (const SparseMatrixD& laplacian : laplacians) {
    for (const double weight : {1.0, 0.37}) {
      ExpectIdenticalSparse(BuildNormalMatrix(laplacian, anchors, weight),
                            ReferenceNormalMatrix(laplacian, anchors, weight));
    }
    ExpectIdenticalSparse(BuildNormalMatrix(laplacian, {}, 1.0),
                          ReferenceNormalMatrix(laplacian, {}, 1.0));
  }
}

#if DMC_WITH_CHOLMOD  // The SimplicialLDLT backend has its own test (solver_test.cpp).
TEST(DecoderFastPaths, BlockedParallelSolveEqualsOneCholmodSolve) {
  const SparseMatrixD normal = GridNormalMatrix();
  // 45 columns: two full 16-column blocks and a partial one, as a rank-45 segment has.
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(normal.rows(), 45);
  SolverOptions options;
  options.backend = SolverBackend::kCholmod;
  options.ordering = SolverOrdering::kAmd;
  const auto solver = SparseSpdSolver::Factor(normal, options);
  ASSERT_TRUE(solver.ok()) << solver.status().ToString();
  const auto blocked = solver->Solve(rhs);
  ASSERT_TRUE(blocked.ok()) << blocked.status().ToString();

  // The reference: the same factorisation settings, one solve of every column.
  ScopedSingleThreadedBlas single_threaded_blas;
  Eigen::CholmodSupernodalLLT<SparseMatrixD, Eigen::Lower> reference;
  reference.cholmod().nmethods = 1;
  reference.cholmod().method[0].ordering = CHOLMOD_AMD;
  reference.cholmod().postorder = 1;
  reference.compute(normal);
  ASSERT_EQ(reference.info(), Eigen::Success);
  // Block by block, bit for bit: the parallel blocks give what one thread solving the same
  // blocks gives, so the decoder's output does not depend on the thread count.
  Eigen::MatrixXd serial_blocks(rhs.rows(), rhs.cols());
  for (Eigen::Index first = 0; first < rhs.cols(); first += 16) {
    const Eigen::Index count = std::min<Eigen::Index>(16, rhs.cols() - first);
    serial_blocks.middleCols(first, count) = reference.solve(rhs.middleCols(first, count));
  }
  ASSERT_EQ(blocked->rows(), serial_blocks.rows());
  ASSERT_EQ(blocked->cols(), serial_blocks.cols());
  EXPECT_TRUE((blocked->array() == serial_blocks.array()).all())
      << "largest difference " << (*blocked - serial_blocks).cwiseAbs().maxCoeff();
  // Against one solve of all 45 columns, to rounding: the same on most BLAS kernels, but not on
  // every one (OpenBLAS 0.3.21 on an AVX-512 Xeon differs by up to 1.2e-11 of solutions of
  // about 9e3; sparse_spd_solver.cpp, kSolveBlockColumns).
  const Eigen::MatrixXd expected = reference.solve(rhs);
  EXPECT_LE((*blocked - expected).cwiseAbs().maxCoeff(), 1e-14 * expected.cwiseAbs().maxCoeff())
      << "largest " << expected.cwiseAbs().maxCoeff();
  // And it is a solution.
  EXPECT_LE((normal.selfadjointView<Eigen::Lower>() * *blocked - rhs).norm(), 1e-9 * rhs.norm());
}
#endif  // DMC_WITH_CHOLMOD

TEST(DecoderFastPaths, SynthesisEqualsBlockwiseProductPlusMean) {
  // 1000 vertices: three full 256-row blocks and a partial one; 7 frames, rank 5.
  constexpr int kVertices = 1000, kFrames = 7, kRank = 5;
  const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Random(kVertices, kRank);
  const Eigen::MatrixXd basis = Eigen::MatrixXd::Random(3 * kFrames, kRank);
  const Eigen::VectorXd mean = 10.0 * Eigen::VectorXd::Random(3 * kFrames);
  std::vector<float> frames(static_cast<size_t>(kVertices) * kFrames * 3);
  ASSERT_TRUE(SynthesizeFrames(mean, basis, coefficients, kFrames, frames.data()).ok());

  // What the decoder computed before: per 256-row block, the product, then the mean added in a
  // second pass, then the conversion.
  std::vector<float> expected(frames.size());
  for (int begin = 0; begin < kVertices; begin += 256) {
    const int rows = std::min(256, kVertices - begin);
    Eigen::MatrixXd trajectories(rows, 3 * kFrames);
    trajectories.noalias() = coefficients.middleRows(begin, rows) * basis.transpose();
    trajectories.rowwise() += mean.transpose();
    for (int f = 0; f < kFrames; ++f) {
      for (int v = 0; v < rows; ++v) {
        for (int axis = 0; axis < 3; ++axis) {
          expected[(static_cast<size_t>(f) * kVertices + begin + v) * 3 + axis] =
              static_cast<float>(trajectories(v, 3 * f + axis));
        }
      }
    }
  }
  EXPECT_EQ(frames, expected);
}

// Every SIMD variant of the kernel the CPU runs, against a sequential dot product, for every group
// size, widths around the strip lengths (padded to the stride) and ranks up to the target's 100:
// identical bits. (This file is compiled with -ffp-contract=off, tests/CMakeLists.txt, so the
// reference sums are one multiply and one add per term too.)
TEST(DecoderFastPaths, SynthesisKernelVariantsEqualSequentialDotProducts) {
  const std::vector<std::string> variants = SupportedSimdVariants();
  ASSERT_FALSE(variants.empty());
  EXPECT_EQ(variants.back(), "baseline");
  for (const std::string& variant : variants) {
    for (const int rank : {1, 2, 7, 60, 100}) {
      for (const std::ptrdiff_t width : {1, 3, 7, 8, 9, 16, 23, 33, 525}) {
        const std::ptrdiff_t stride = (width + kSynthesisStrideMultiple - 1) /
                                      kSynthesisStrideMultiple * kSynthesisStrideMultiple;
        const Eigen::MatrixXd basis = Eigen::MatrixXd::Random(stride, rank);
        const Eigen::MatrixXd coefficients = 100.0 * Eigen::MatrixXd::Random(rank, 4);
        for (int group = 1; group <= kSynthesisVertexGroup; ++group) {
          const double* rows[kSynthesisVertexGroup] = {};
          for (int i = 0; i < group; ++i) rows[i] = coefficients.col(i).data();
          std::vector<double> sums(static_cast<size_t>(group * stride), -1.0);
          ASSERT_TRUE(SumTrajectoryProductsWith(variant.c_str(), rows, group, basis.data(), rank,
                                                stride, sums.data()));
          std::vector<double> expected(sums.size());
          for (int i = 0; i < group; ++i) {
            for (std::ptrdiff_t j = 0; j < stride; ++j) {
              double sum = 0.0;
              for (int k = 0; k < rank; ++k) sum += coefficients(k, i) * basis(j, k);
              expected[static_cast<size_t>(i * stride + j)] = sum;
            }
          }
          EXPECT_EQ(std::memcmp(sums.data(), expected.data(), sums.size() * sizeof(double)), 0)
              << "variant " << variant << ", rank " << rank << ", width " << width << ", group "
              << group;
        }
      }
    }
  }
}

// Restores the fastest variant (and the real CPU's instruction sets) however a test ends.
class ScopedSimdVariantReset {
 public:
  ~ScopedSimdVariantReset() {
    hwy::SetSupportedTargetsForTest(0);
    EXPECT_TRUE(SetSimdVariant("auto").ok());
  }
};

// Forcing a variant: every supported one can be made active and synthesises the same frames; a
// misspelt name and an instruction set the CPU lacks are told apart; "auto" restores the fastest.
TEST(DecoderFastPaths, ForcedSimdVariantsSynthesiseIdenticalFrames) {
  const ScopedSimdVariantReset reset;
  constexpr int kVertices = 37, kFrames = 11, kRank = 9;
  const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Random(kVertices, kRank);
  const Eigen::MatrixXd basis = Eigen::MatrixXd::Random(3 * kFrames, kRank);
  const Eigen::VectorXd mean = Eigen::VectorXd::Random(3 * kFrames);
  const std::vector<std::string> variants = SupportedSimdVariants();
  std::vector<float> reference;
  for (const std::string& variant : variants) {
    ASSERT_TRUE(SetSimdVariant(variant).ok()) << variant;
    EXPECT_EQ(ActiveSimdVariant(), variant);
    std::vector<float> frames(static_cast<size_t>(kVertices) * kFrames * 3);
    ASSERT_TRUE(SynthesizeFrames(mean, basis, coefficients, kFrames, frames.data()).ok());
    if (reference.empty()) reference = frames;
    EXPECT_EQ(frames, reference) << variant;
  }
  for (const char* misspelt : {"avx3", "wasm", "AVX2", ""}) {
    const Status status = SetSimdVariant(misspelt);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument) << misspelt;
    EXPECT_NE(status.message().find("avx512, avx2"), std::string::npos) << status.message();
  }
  for (const char* name : {"avx512", "avx2", "sse4", "ssse3", "neon"}) {
    if (std::find(variants.begin(), variants.end(), name) != variants.end()) continue;
    const Status missing = SetSimdVariant(name);
    EXPECT_EQ(missing.code(), ErrorCode::kUnsupported) << name;
    EXPECT_NE(missing.message().find("available: "), std::string::npos) << missing.message();
  }
  ASSERT_TRUE(SetSimdVariant("auto").ok());
  EXPECT_EQ(ActiveSimdVariant(), variants.front());
}

#if HWY_ARCH_X86
// A CPU with SSE4 and no AVX (Highway's CPU detection mocked): the fastest variant is sse4, avx2
// and avx512 are refused as unavailable, and the variants that remain give the same bits.
TEST(DecoderFastPaths, SimdVariantsOfACpuWithoutAvx) {
  const ScopedSimdVariantReset reset;
  hwy::SetSupportedTargetsForTest(HWY_SSE4 | HWY_SSSE3 | HWY_EMU128 | HWY_SCALAR);
  ASSERT_TRUE(SetSimdVariant("auto").ok());
  EXPECT_EQ(ActiveSimdVariant(), "sse4");
  EXPECT_EQ(SupportedSimdVariants(), (std::vector<std::string>{"sse4", "ssse3", "baseline"}));
  for (const char* name : {"avx2", "avx512"}) {
    EXPECT_EQ(SetSimdVariant(name).code(), ErrorCode::kUnsupported) << name;
  }
  const Eigen::MatrixXd basis = Eigen::MatrixXd::Random(kSynthesisStrideMultiple * 3, 5);
  const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Random(5, 1);
  const double* rows[1] = {coefficients.data()};
  std::vector<double> sse4(basis.rows()), baseline(basis.rows());
  ASSERT_TRUE(
      SumTrajectoryProductsWith("sse4", rows, 1, basis.data(), 5, basis.rows(), sse4.data()));
  ASSERT_TRUE(SumTrajectoryProductsWith("baseline", rows, 1, basis.data(), 5, basis.rows(),
                                        baseline.data()));
  EXPECT_FALSE(
      SumTrajectoryProductsWith("avx2", rows, 1, basis.data(), 5, basis.rows(), sse4.data()));
  EXPECT_EQ(sse4, baseline);
}
#endif

// At the decode target's shape (rank 60, 175 frames, a partial last group and block) the frames
// are still those of the blockwise Eigen product the decoder used before the kernel.
TEST(DecoderFastPaths, SynthesisAtTheTargetShapeEqualsTheEigenProduct) {
  constexpr int kVertices = 515, kFrames = 175, kRank = 60;
  const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Random(kVertices, kRank);
  const Eigen::MatrixXd basis = 0.1 * Eigen::MatrixXd::Random(3 * kFrames, kRank);
  const Eigen::VectorXd mean = Eigen::VectorXd::Random(3 * kFrames);
  std::vector<float> frames(static_cast<size_t>(kVertices) * kFrames * 3);
  ASSERT_TRUE(SynthesizeFrames(mean, basis, coefficients, kFrames, frames.data()).ok());
  const Eigen::MatrixXd trajectories = coefficients * basis.transpose();
  size_t differing = 0;
  for (int f = 0; f < kFrames; ++f) {
    for (int v = 0; v < kVertices; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        const auto expected =
            static_cast<float>(trajectories(v, 3 * f + axis) + mean[3 * f + axis]);
        differing += frames[(static_cast<size_t>(f) * kVertices + v) * 3 + axis] != expected;
      }
    }
  }
  EXPECT_EQ(differing, 0u);
}

// The serial-OpenMP guard sets the calling thread's max-active-levels to 0 and restores it, and
// leaves other threads' alone (CHOLMOD's regions opened elsewhere keep their threads).
TEST(DecoderFastPaths, SerialOpenMpGuardIsPerThreadAndRestores) {
  using GetLevels = int (*)();
  const auto get = reinterpret_cast<GetLevels>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  if (get == nullptr) GTEST_SKIP() << "no OpenMP runtime in the process";
  const int before = get();
  int other_thread = -1;
  {
    ScopedSerialOpenMp guard;
    EXPECT_EQ(get(), 0);
    std::thread([&] { other_thread = get(); }).join();
  }
  EXPECT_EQ(get(), before);
  EXPECT_EQ(other_thread, before);  // a new thread starts from the initial value, untouched
}

TEST(DecoderFastPaths, SynthesisRejectsPositionsBeyondFloat) {
  const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Constant(300, 1, 1e300);
  const Eigen::MatrixXd basis = Eigen::MatrixXd::Ones(3, 1);
  const Eigen::VectorXd mean = Eigen::VectorXd::Zero(3);
  std::vector<float> frames(300 * 3);
  EXPECT_EQ(SynthesizeFrames(mean, basis, coefficients, 1, frames.data()).code(),
            ErrorCode::kCorruptStream);
}

}  // namespace
}  // namespace dmc
