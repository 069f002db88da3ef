// The 3D+t spacetime Laplacian: moving-cell measures against hand values and fine references,
// the paper's identities (zero row sums, symmetry, ⋆0^{1/2}·1 in the null space, nonzero count),
// its α → ∞ and α → 0 limits, and the block-tridiagonal solver.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "dmc/operators.h"
#include "dmc/spacetime.h"
#include "test_support.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

std::vector<FramePositionsD> Frames(const MeshSequence& sequence) {
  std::vector<FramePositionsD> frames;
  for (int f = 0; f < sequence.frame_count(); ++f) frames.push_back(sequence.frame_d(f));
  return frames;
}

// The same frame repeated: a sequence without motion.
std::vector<FramePositionsD> StaticFrames(const MeshSequence& mesh, int count) {
  return std::vector<FramePositionsD>(count, mesh.frame_d(0));
}

// Composite Simpson with many panels: the fine reference for the quadratures.
template <typename Function>
double Simpson(Function f, double a, double b, int panels = 20000) {
  const double h = (b - a) / panels;
  double sum = f(a) + f(b);
  for (int p = 1; p < panels; ++p) sum += f(a + p * h) * (p % 2 == 1 ? 4.0 : 2.0);
  return sum * h / 3.0;
}

double MaxAbs(const SparseMatrixD& m) {
  double largest = 0.0;
  for (int c = 0; c < m.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(m, c); it; ++it) {
      largest = std::max(largest, std::abs(it.value()));
    }
  }
  return largest;
}

// Barycentric vertex areas Σ_f area_f / 3 of one frame.
Eigen::VectorXd BarycentricAreas(const Triangles& triangles, const FramePositionsD& p) {
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(p.rows());
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = p.row(triangles(t, 0)), b = p.row(triangles(t, 1)),
                          c = p.row(triangles(t, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    for (int s = 0; s < 3; ++s) areas[triangles(t, s)] += area / 3.0;
  }
  return areas;
}

TEST(GaussLegendre, WeightsSumToTwoAndHighDegreesAreExact) {
  for (int points : {1, 2, 5, 8}) {
    const GaussLegendreRule rule = MakeGaussLegendreRule(points);
    ASSERT_EQ(rule.nodes.size(), points);
    EXPECT_NEAR(rule.weights.sum(), 2.0, 1e-14);
    // ∫_{-1}^{1} x^(2n−2) = 2/(2n−1): the highest even degree the rule integrates exactly.
    const int degree = 2 * points - 2;
    double sum = 0.0;
    for (int q = 0; q < points; ++q) sum += rule.weights[q] * std::pow(rule.nodes[q], degree);
    EXPECT_NEAR(sum, 2.0 / (degree + 1), 1e-13) << points;
  }
  EXPECT_NEAR(MakeGaussLegendreRule(2).nodes.cwiseAbs().maxCoeff(), 1.0 / std::sqrt(3.0), 1e-15);
}

TEST(MovingLength, ClosedFormMatchesHandValues) {
  // A static segment: its length times the interval.
  EXPECT_NEAR(IntegrateMovingLength({3, 4, 0}, {0, 0, 0}, 0.0, 0.5), 2.5, 1e-14);
  // A segment shrinking through zero and growing again: ∫₀¹ |1 − 2β| = 1/2.
  EXPECT_NEAR(IntegrateMovingLength({1, 0, 0}, {-2, 0, 0}, 0.0, 1.0), 0.5, 1e-14);
  // ∫₀¹ sqrt(1 + β²) dβ = (sqrt 2 + asinh 1)/2.
  EXPECT_NEAR(IntegrateMovingLength({0, 1, 0}, {1, 0, 0}, 0.0, 1.0),
              0.5 * (std::sqrt(2.0) + std::asinh(1.0)), 1e-14);
}

TEST(MovingLength, ClosedFormMatchesAFineReferenceOnRandomMotions) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d a(normal(rng), normal(rng), normal(rng));
    // Changes from tiny (the quadrature fallback) to large.
    const double scale = std::pow(10.0, -6.0 + 7.0 * trial / 49.0);
    const Eigen::Vector3d b = scale * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const double exact = IntegrateMovingLength(a, b, 0.25, 0.75);
    const double reference = Simpson([&](double t) { return (a + t * b).norm(); }, 0.25, 0.75);
    EXPECT_NEAR(exact, reference, 1e-10 * reference) << "scale " << scale;
  }
}

TEST(MovingTriangle, ExactOnStaticAndUniformlyScaledTriangles) {
  const GaussLegendreRule rule = MakeGaussLegendreRule(3);
  Eigen::Matrix3d start;
  start << 0, 0, 0, 2, 0, 0, 0, 1, 0;  // area 1
  EXPECT_NEAR(IntegrateMovingTriangleArea(start, start, 0.0, 0.5, rule), 0.5, 1e-15);
  // Corners scaled by (1 + β): area (1 + β)², ∫₀¹ = 7/3.
  EXPECT_NEAR(IntegrateMovingTriangleArea(start, 2.0 * start, 0.0, 1.0, rule), 7.0 / 3.0, 1e-14);
}

TEST(MovingTriangle, GaussLegendreMatchesAFineReference) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  const GaussLegendreRule rule = MakeGaussLegendreRule(SpacetimeOptions{}.quadrature_points);
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::Matrix3d start, motion;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        start(r, c) = normal(rng);
        motion(r, c) = 0.2 * normal(rng);  // a frame-to-frame motion: the triangle does not flip
      }
    }
    const Eigen::Matrix3d end = start + motion;
    const auto area = [&](double beta) {
      const Eigen::Matrix3d at = start + beta * motion;
      return 0.5 * (at.row(1) - at.row(0)).cross(at.row(2) - at.row(0)).norm();
    };
    for (const auto& [b0, b1] : {std::pair{0.0, 0.5}, std::pair{0.5, 1.0}}) {
      const double reference = Simpson(area, b0, b1);
      EXPECT_NEAR(IntegrateMovingTriangleArea(start, end, b0, b1, rule), reference,
                  1e-9 * reference);
    }
  }
}

TEST(SpacetimeGeometry, StaticSequenceGivesPrismMeasures) {
  const MeshSequence mesh = testing::JitteredPlanarGrid(5, 0.3);
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  SpacetimeOptions options;
  options.alpha = 4.0;
  options.frame_times = {0.0, 0.5, 1.5};
  const auto g =
      ComputeSpacetimeGeometry(topology, mesh.triangles(), StaticFrames(mesh, 3), options);
  ASSERT_TRUE(g.ok()) << g.status().ToString();
  const Eigen::VectorXd areas = BarycentricAreas(mesh.triangles(), mesh.frame_d(0));
  const double sqrt_alpha = 2.0;
  // Temporal lengths sqrt(α)·Δt, quads |e|·sqrt(α)·Δt, cells A·sqrt(α)·Δt.
  EXPECT_NEAR(g->temporal_edge_length.col(0).maxCoeff(), sqrt_alpha * 0.5, 1e-15);
  EXPECT_NEAR(g->temporal_edge_length.col(1).minCoeff(), sqrt_alpha * 1.0, 1e-15);
  for (int e = 0; e < topology.edge_count(); ++e) {
    EXPECT_NEAR(g->temporal_quad_area(e, 1), g->spatial_edge_length(e, 0) * sqrt_alpha, 1e-14);
  }
  EXPECT_NEAR(g->temporal_cell_volume.col(0).sum(), 1.0 * sqrt_alpha * 0.5, 1e-13);
  // Vertex duals: A_i·sqrt(α)·(Δt_before + Δt_after)/2; temporal duals: A_i.
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_NEAR(g->vertex_dual_volume(v, 0), areas[v] * sqrt_alpha * 0.25, 1e-14);
    EXPECT_NEAR(g->vertex_dual_volume(v, 1), areas[v] * sqrt_alpha * 0.75, 1e-14);
    EXPECT_NEAR(g->vertex_dual_volume(v, 2), areas[v] * sqrt_alpha * 0.5, 1e-14);
    EXPECT_NEAR(g->temporal_edge_dual_area(v, 0), areas[v], 1e-14);
  }
  EXPECT_EQ(g->stats.empty_vertex_duals, 0);
}

TEST(SpacetimeGeometry, DualVolumesTileThePrimalCellsUnderMotion) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(1), 4);
  const MeshTopology topology = BuildTopology(seq.triangles(), seq.vertex_count());
  const auto g = ComputeSpacetimeGeometry(topology, seq.triangles(), Frames(seq), {});
  ASSERT_TRUE(g.ok());
  // The barycentric duals of the vertices partition the temporal 3-cells; the temporal edge
  // duals partition each mid-interval mesh.
  EXPECT_NEAR(g->vertex_dual_volume.sum(), g->temporal_cell_volume.sum(),
              1e-12 * g->temporal_cell_volume.sum());
  for (int k = 0; k + 1 < seq.frame_count(); ++k) {
    const FramePositionsD middle = 0.5 * (seq.frame_d(k) + seq.frame_d(k + 1));
    EXPECT_NEAR(g->temporal_edge_dual_area.col(k).sum(),
                BarycentricAreas(seq.triangles(), middle).sum(), 1e-12);
  }
}

TEST(SpacetimeLaplacian, IdentitiesOnMovingMeshes) {
  for (const MeshSequence& seq :
       {testing::Animate(testing::Icosphere(1), 4), testing::Animate(testing::Strip(6), 3),
        testing::Animate(testing::TwoTetrahedraAndIsolatedVertex(), 3)}) {
    const MeshTopology topology = BuildTopology(seq.triangles(), seq.vertex_count());
    for (SpatialDual dual : {SpatialDual::kBarycentric, SpatialDual::kCircumcentric}) {
      SpacetimeOptions options;
      options.alpha = 0.7;
      options.spatial_dual = dual;
      const auto st = BuildSpacetimeLaplacian(seq, options);
      ASSERT_TRUE(st.ok()) << st.status().ToString();
      const Eigen::Index n = static_cast<Eigen::Index>(seq.vertex_count()) * seq.frame_count();
      ASSERT_EQ(st->matrix.rows(), n);
      // Preallocated storage holds exactly the formula's entries.
      EXPECT_EQ(st->matrix.nonZeros(), SpacetimeNonzeroCount(topology, seq.frame_count()));
      EXPECT_EQ(SpacetimeNonzeroCount(topology, seq.frame_count()),
                seq.frame_count() * (seq.vertex_count() + 2 * topology.edge_count()) +
                    2 * seq.vertex_count() * (seq.frame_count() - 1));
      const double scale = MaxAbs(st->matrix);
      // Symmetric, ⋆0^{1/2}·1 in the null space, Δu rows sum to zero.
      EXPECT_LE(MaxAbs(SparseMatrixD(st->matrix.transpose()) - st->matrix), 1e-14 * scale);
      const Eigen::VectorXd root_mass = st->mass.cwiseSqrt();
      EXPECT_LE((st->matrix * root_mass).cwiseAbs().maxCoeff(), 1e-12 * scale);
      const SparseMatrixD unsym = UnsymmetrisedSpacetimeLaplacian(*st);
      EXPECT_LE((unsym * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-12 * MaxAbs(unsym));
      EXPECT_GT(MaxAbs(SparseMatrixD(unsym.transpose()) - unsym), 1e-6 * MaxAbs(unsym));
      EXPECT_LE((st->stiffness * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(),
                1e-12 * MaxAbs(st->stiffness));
      // Blocks beyond neighbouring frames are empty; coupling blocks are diagonal.
      EXPECT_EQ(SpacetimeBlock(st->matrix, seq.vertex_count(), 0, 2).nonZeros(), 0);
      const SparseMatrixD coupling = SpacetimeBlock(st->matrix, seq.vertex_count(), 0, 1);
      EXPECT_EQ(coupling.nonZeros(), seq.vertex_count());
      for (int c = 0; c < coupling.outerSize(); ++c) {
        for (SparseMatrixD::InnerIterator it(coupling, c); it; ++it) EXPECT_EQ(it.row(), c);
      }
      EXPECT_TRUE(Eigen::MatrixXd(st->matrix).allFinite());
      if (dual == SpatialDual::kBarycentric) {
        // Positive weights: negative semidefinite (largest eigenvalue ~0).
        const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen{Eigen::MatrixXd(st->matrix)};
        EXPECT_LE(eigen.eigenvalues().maxCoeff(), 1e-12 * scale);
      }
    }
  }
}

TEST(SpacetimeLaplacian, IsolatedVertexHasZeroRows) {
  const MeshSequence seq = testing::Animate(testing::TwoTetrahedraAndIsolatedVertex(), 2);
  const auto st = BuildSpacetimeLaplacian(seq, {});
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->geometry.stats.empty_vertex_duals, 2);  // vertex 8 in both frames
  const Eigen::MatrixXd dense(st->matrix);
  EXPECT_EQ(dense.row(8).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(dense.row(9 + 8).cwiseAbs().maxCoeff(), 0.0);
}

// Property 4.5: as α → ∞ the coupling vanishes and each spatial block becomes the symmetrised
// per-frame DEC Laplacian ⋆0s^{−1/2}·(cotan-sym)·⋆0s^{−1/2} (circumcentric spatial duals).
TEST(SpacetimeLaplacian, LargeAlphaTendsToPerFrameCotangentLaplacians) {
  const MeshSequence mesh = testing::JitteredPlanarGrid(6, 0.3);
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const int v_count = mesh.vertex_count();
  const auto cotan_sym = BuildCotanSym(topology, mesh.frame_d(0));
  ASSERT_TRUE(cotan_sym.ok());
  const Eigen::VectorXd inverse_root =
      BarycentricAreas(mesh.triangles(), mesh.frame_d(0)).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd expected =
      inverse_root.asDiagonal() * Eigen::MatrixXd(cotan_sym->matrix) * inverse_root.asDiagonal();
  double previous_coupling = 1e300;
  for (double alpha : {1.0, 1e4, 1e8, 1e12}) {
    SpacetimeOptions options;
    options.alpha = alpha;
    options.spatial_dual = SpatialDual::kCircumcentric;
    const auto st =
        BuildSpacetimeLaplacian(topology, mesh.triangles(), StaticFrames(mesh, 3), options);
    ASSERT_TRUE(st.ok());
    const double coupling = MaxAbs(SpacetimeBlock(st->matrix, v_count, 0, 1));
    // D = −(A/√α)/sqrt(√α·A/2 · √α·A): the first frame's dual has half a step.
    EXPECT_NEAR(coupling, std::sqrt(2.0) / alpha, 1e-12 / alpha);
    EXPECT_LT(coupling, previous_coupling);
    previous_coupling = coupling;
    for (int k = 0; k < 3; ++k) {
      const Eigen::MatrixXd block(SpacetimeBlock(st->matrix, v_count, k, k));
      // Off the diagonal the blocks agree for every α without motion; the diagonal carries
      // the temporal weights, which vanish like 1/α.
      const double error = (block - expected).cwiseAbs().maxCoeff();
      EXPECT_LE(error, 2.0 / alpha + 1e-9 * expected.cwiseAbs().maxCoeff()) << alpha;
    }
  }
  // With motion the limit holds up to the size of the motion: frame k's block against frame
  // k's cotangent Laplacian.
  const MeshSequence moving = testing::Animate(mesh, 3, 0.02);
  SpacetimeOptions options;
  options.alpha = 1e10;
  options.spatial_dual = SpatialDual::kCircumcentric;
  const auto st = BuildSpacetimeLaplacian(moving, options);
  ASSERT_TRUE(st.ok());
  for (int k = 0; k < 3; ++k) {
    const auto frame_cotan = BuildCotanSym(topology, moving.frame_d(k));
    const Eigen::VectorXd root =
        BarycentricAreas(moving.triangles(), moving.frame_d(k)).cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd frame_expected =
        root.asDiagonal() * Eigen::MatrixXd(frame_cotan->matrix) * root.asDiagonal();
    const Eigen::MatrixXd block(SpacetimeBlock(st->matrix, v_count, k, k));
    EXPECT_LE((block - frame_expected).cwiseAbs().maxCoeff(),
              0.05 * frame_expected.cwiseAbs().maxCoeff());
  }
}

// Property 4.6: with motion small against the edges, the temporal coefficients dominate as α → 0.
TEST(SpacetimeLaplacian, SmallAlphaWithSmallMotionMakesTemporalCoefficientsDominate) {
  // A grid whose vertices move by ~1e-3 per frame, edges ~0.2 long.
  const MeshSequence base = testing::JitteredPlanarGrid(6, 0.3);
  MeshSequence seq(base.vertex_count(), base.triangles(), 4);
  for (int f = 0; f < 4; ++f) {
    seq.frame(f) = base.frame(0);
    for (int v = 0; v < base.vertex_count(); ++v) {
      seq.frame(f)(v, 2) = 1e-3f * static_cast<float>(f) * (1.0f + base.frame(0)(v, 0));
    }
  }
  const int v_count = seq.vertex_count();
  SpacetimeOptions options;
  options.alpha = 1e-8;
  const auto st = BuildSpacetimeLaplacian(seq, options);
  ASSERT_TRUE(st.ok());
  double smallest_temporal = 1e300, largest_spatial = 0.0;
  for (int k = 0; k + 1 < seq.frame_count(); ++k) {
    const Eigen::VectorXd d =
        Eigen::MatrixXd(SpacetimeBlock(st->matrix, v_count, k, k + 1)).diagonal();
    smallest_temporal = std::min(smallest_temporal, d.cwiseAbs().minCoeff());
    Eigen::MatrixXd spatial(SpacetimeBlock(st->matrix, v_count, k, k));
    spatial.diagonal().setZero();
    largest_spatial = std::max(largest_spatial, spatial.cwiseAbs().maxCoeff());
  }
  EXPECT_GT(smallest_temporal, 10.0 * largest_spatial);
  // And the other way round for large α.
  options.alpha = 1e6;
  const auto large = BuildSpacetimeLaplacian(seq, options);
  ASSERT_TRUE(large.ok());
  EXPECT_LT(MaxAbs(SpacetimeBlock(large->matrix, v_count, 0, 1)),
            1e-3 * MaxAbs(SpacetimeBlock(large->matrix, v_count, 0, 0)));
}

TEST(SpacetimeLaplacian, FrameTimesComeFromTheFrameRate) {
  MeshSequence seq = testing::Animate(testing::Icosphere(1), 3);
  const auto unit_steps = BuildSpacetimeLaplacian(seq, {});
  seq.frame_rate = 30.0;
  const auto per_second = BuildSpacetimeLaplacian(seq, {});
  ASSERT_TRUE(unit_steps.ok() && per_second.ok());
  EXPECT_NEAR(unit_steps->geometry.frame_times[2], 2.0, 0.0);
  EXPECT_NEAR(per_second->geometry.frame_times[2], 2.0 / 30.0, 1e-15);
  // Shorter steps: shorter temporal edges.
  EXPECT_LT(per_second->geometry.temporal_edge_length.maxCoeff(),
            unit_steps->geometry.temporal_edge_length.minCoeff());
}

TEST(SpacetimeLaplacian, RejectsBadInput) {
  const MeshSequence one = testing::Icosphere(1);
  EXPECT_EQ(BuildSpacetimeLaplacian(one, {}).status().code(), ErrorCode::kInvalidArgument);
  const MeshSequence two = testing::Animate(one, 2);
  SpacetimeOptions options;
  options.alpha = 0.0;
  EXPECT_EQ(BuildSpacetimeLaplacian(two, options).status().code(), ErrorCode::kInvalidArgument);
  options.alpha = 1.0;
  options.frame_times = {1.0, 1.0};
  EXPECT_EQ(BuildSpacetimeLaplacian(two, options).status().code(), ErrorCode::kInvalidArgument);
  options.frame_times = {0.0, 1.0, 2.0};
  EXPECT_EQ(BuildSpacetimeLaplacian(two, options).status().code(), ErrorCode::kInvalidArgument);
}

TEST(BlockTridiagonalSolver, MatchesADenseSolveAndSparseCholesky) {
  const MeshSequence seq = testing::Animate(testing::JitteredPlanarGrid(5, 0.3), 5);
  const int v_count = seq.vertex_count();
  const auto st = BuildSpacetimeLaplacian(seq, {});
  ASSERT_TRUE(st.ok());
  // −W plus soft anchors on frame 0: SPD, block tridiagonal with diagonal couplings.
  SparseMatrixD system = -st->stiffness;
  for (int v = 0; v < v_count; ++v) system.coeffRef(v, v) += 1.0;
  const auto block = BlockTridiagonalSolver::Factor(system, v_count);
  ASSERT_TRUE(block.ok()) << block.status().ToString();
  EXPECT_EQ(block->block_count(), seq.frame_count());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::MatrixXd rhs(system.rows(), 3);
  for (Eigen::Index r = 0; r < rhs.rows(); ++r) {
    for (int c = 0; c < 3; ++c) rhs(r, c) = unit(rng);
  }
  const auto x = block->Solve(rhs);
  ASSERT_TRUE(x.ok());
  const Eigen::MatrixXd dense = Eigen::MatrixXd(system).ldlt().solve(rhs);
  EXPECT_LE((*x - dense).cwiseAbs().maxCoeff(), 1e-9 * dense.cwiseAbs().maxCoeff());
  const auto cholesky = SparseSpdSolver::Factor(system);
  ASSERT_TRUE(cholesky.ok());
  EXPECT_LE((*cholesky->Solve(rhs) - *x).cwiseAbs().maxCoeff(), 1e-9 * dense.cwiseAbs().maxCoeff());
  EXPECT_EQ(block->Solve(rhs.topRows(3)).status().code(), ErrorCode::kMismatch);
}

TEST(BlockTridiagonalSolver, RejectsMatricesOutsideThePattern) {
  SparseMatrixD outside(6, 6);
  outside.setIdentity();
  outside.coeffRef(0, 5) = 0.1;  // couples frames 0 and 2
  EXPECT_EQ(BlockTridiagonalSolver::Factor(outside, 2).status().code(),
            ErrorCode::kInvalidArgument);
  SparseMatrixD off_diagonal_coupling(4, 4);
  off_diagonal_coupling.setIdentity();
  off_diagonal_coupling.coeffRef(0, 3) = 0.1;
  EXPECT_EQ(BlockTridiagonalSolver::Factor(off_diagonal_coupling, 2).status().code(),
            ErrorCode::kInvalidArgument);
  SparseMatrixD indefinite(2, 2);
  indefinite.setIdentity();
  indefinite.coeffRef(1, 1) = -1.0;
  EXPECT_EQ(BlockTridiagonalSolver::Factor(indefinite, 1).status().code(),
            ErrorCode::kNumericalFailure);
  EXPECT_EQ(BlockTridiagonalSolver::Factor(indefinite, 3).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
