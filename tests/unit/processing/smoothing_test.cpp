// Smoothing: hand-computed explicit steps, curvature flipping, Taubin's volume, implicit fairing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "processing/processing_util.h"
#include "processing_test_util.h"

namespace dmc {
namespace {

using testing::MustApply;
using testing::MustPrepare;

// PlanarGrid(7) with its centre vertex (3, 3) lifted to z = 1. Every interior vertex of this
// grid has degree 6, so one Tutte step moves the centre by λ·(0 − 1) and each of its six
// neighbours by λ·(1/6)·(1 − 0).
MeshSequence Bump() {
  MeshSequence grid = testing::PlanarGrid(7);
  grid.frame(0)(24, 2) = 1.0f;
  return grid;
}

double CentreDeltaZ(const MeshSequence& mesh, const FramePositionsD& positions) {
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const LaplaceOperator tutte = *BuildTutte(topology);
  return (tutte.matrix * Eigen::MatrixXd(positions))(24, 2);
}

TEST(SmoothExplicit, OneTutteStepMatchesTheHandComputedPositions) {
  const MeshSequence bump = Bump();
  const MeshTopology topology = BuildTopology(bump.triangles(), bump.vertex_count());
  for (double lambda : {0.5, 1.25}) {
    RunOptions options;
    options.operator_name = "tutte";
    options.parameters = {{"lambda", std::to_string(lambda)}, {"iterations", "1"}};
    const FrameOutput output =
        MustApply(MustPrepare("smooth-explicit", bump, options), bump.frame_d(0));
    EXPECT_NEAR(output.positions(24, 2), 1.0 - lambda, 1e-12);
    for (int k = topology.ring_offsets[24]; k < topology.ring_offsets[25]; ++k) {
      EXPECT_NEAR(output.positions(topology.ring_neighbors[k], 2), lambda / 6.0, 1e-12);
    }
    EXPECT_EQ(topology.degree(24), 6);
  }
}

TEST(SmoothExplicit, LambdaAboveOneFlipsCurvature) {
  // After one step the centre sits at 1 − λ and all six neighbours at λ/6, so its new δ_z is
  // λ/6 − (1 − λ): the peak becomes a pit once λ > 6/7 — in particular for every λ > 1, where
  // the centre overshoots the barycentre of its neighbours (thesis 3.2.2). (Up to λ = 2/ρ: this
  // grid's Tutte operator has spectral radius 1.537, so a λ above 1.301 is refused, below.)
  const MeshSequence bump = Bump();
  const double before = CentreDeltaZ(bump, bump.frame_d(0));
  ASSERT_LT(before, 0.0);  // a peak: δ points down
  for (double lambda : {0.5, 0.8, 1.1, 1.2, 1.3}) {
    RunOptions options;
    options.operator_name = "tutte";
    options.parameters = {{"lambda", std::to_string(lambda)}, {"iterations", "1"}};
    const FrameOutput output =
        MustApply(MustPrepare("smooth-explicit", bump, options), bump.frame_d(0));
    const double after = CentreDeltaZ(bump, output.positions);
    EXPECT_NEAR(after, lambda / 6.0 - (1.0 - lambda), 1e-12);
    if (lambda < 1.0) {
      EXPECT_LT(after, 0.0) << "lambda " << lambda << " keeps the peak";
    } else {
      EXPECT_GT(after, 0.0) << "lambda " << lambda << " turns the peak into a pit";
    }
  }
}

TEST(SmoothExplicit, NonUnitSumOperatorsUseTheScaledStep) {
  // Kirchhoff on this grid: the Gershgorin bound on its spectral radius is twice the largest
  // degree, so λ′ = λ / max degree.
  const MeshSequence bump = Bump();
  const MeshTopology topology = BuildTopology(bump.triangles(), bump.vertex_count());
  int max_degree = 0;
  for (int v = 0; v < topology.vertex_count; ++v)
    max_degree = std::max(max_degree, topology.degree(v));
  RunOptions options;
  options.operator_name = "kirchhoff";
  options.parameters = {{"lambda", "0.6"}, {"iterations", "1"}};
  const FrameOutput output =
      MustApply(MustPrepare("smooth-explicit", bump, options), bump.frame_d(0));
  EXPECT_NEAR(testing::MeasurementValue(output.measurements, "effective_lambda"), 0.6 / max_degree,
              1e-12);
  EXPECT_NEAR(output.positions(24, 2), 1.0 - 0.6 / max_degree * 6.0, 1e-12);
}

// Issue 27: with the mean |L_ii| as the scale, explicit and Taubin smoothing with cotan-sym and
// cotan-area diverged to inf/NaN at the default λ. The step is now scaled by the spectral-radius
// bound: at the defaults every operator contracts the highest frequency, stays finite and
// smooths, on an irregular mesh; a λ beyond the stable range is refused, naming the largest
// stable one.
TEST(SmoothExplicit, DefaultsAreStableForEveryOperatorAndUnstableLambdasAreRefused) {
  const MeshSequence grid = testing::JitteredPlanarGrid(16, 0.35);
  FramePositionsD input = grid.frame_d(0);
  for (int v = 0; v < grid.vertex_count(); ++v) input(v, 2) = 0.02 * std::sin(7.0 * v);
  MeshSequence noisy(grid.vertex_count(), grid.triangles(), 0);
  ASSERT_TRUE(noisy.AppendFrame(input.cast<float>()).ok());
  for (const char* op : {"tutte", "kirchhoff", "cotan", "cotan-sym", "cotan-area", "mean-value"}) {
    for (const char* method : {"smooth-explicit", "smooth-taubin"}) {
      RunOptions options;
      options.operator_name = op;
      options.parameters = {{"iterations", "50"}};
      const PreparedRun run = MustPrepare(method, noisy, options);
      const double step = [&] {
        const FrameOutput out = MustApply(run, noisy.frame_d(0));
        EXPECT_TRUE(out.positions.allFinite()) << op << " " << method;
        // The noise is damped: the operator's own roughness ‖L·z‖ falls (Taubin keeps the low
        // frequencies, and may lift its pass band a little, so |z| itself is not the measure).
        const SparseMatrixD& laplacian = run.laplace->matrix;
        const double factor = std::string(method) == "smooth-explicit" ? 0.5 : 1.0;
        EXPECT_LT((laplacian * out.positions.col(2)).norm(),
                  factor * (laplacian * noisy.frame_d(0).col(2)).norm())
            << op << " " << method;
        return testing::MeasurementValue(out.measurements, "effective_lambda");
      }();
      // λ′ · ρ ≤ 2 for the default λ = 0.5.
      const double radius = processing::SpectralRadiusEstimate(run.laplace->matrix);
      EXPECT_LE(step * radius, 1.0 + 1e-9) << op << " " << method;
    }
    RunOptions options;
    options.operator_name = op;
    options.parameters = {{"lambda", "1.9"}, {"iterations", "5"}};
    const auto refused = Prepare("smooth-explicit", noisy, options);
    ASSERT_FALSE(refused.ok()) << op << ": lambda 1.9 accepted";
    EXPECT_EQ(refused.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_THAT(refused.status().message(), ::testing::HasSubstr("diverges with this operator"));
    EXPECT_THAT(refused.status().message(), ::testing::HasSubstr("use lambda <= "));
  }
}

TEST(SmoothTaubin, KeepsVolumeWhereExplicitSmoothingShrinks) {
  const MeshSequence sphere = testing::NoisySphere(3, 1.0, 0.02);
  const FramePositionsD input = sphere.frame_d(0);
  const double volume = testing::SignedVolume(sphere.triangles(), input);
  for (const char* op : {"tutte", "cotan", "mean-value"}) {
    RunOptions options;
    options.operator_name = op;
    options.parameters = {{"lambda", "0.5"}, {"iterations", "20"}};
    const FrameOutput plain = MustApply(MustPrepare("smooth-explicit", sphere, options), input);
    const FrameOutput taubin = MustApply(MustPrepare("smooth-taubin", sphere, options), input);
    const double plain_ratio = testing::SignedVolume(sphere.triangles(), plain.positions) / volume;
    const double taubin_ratio =
        testing::SignedVolume(sphere.triangles(), taubin.positions) / volume;
    EXPECT_LT(plain_ratio, 0.9) << op;
    EXPECT_NEAR(taubin_ratio, 1.0, 0.03) << op;
    EXPECT_NEAR(testing::MeasurementValue(taubin.measurements, "volume_ratio"), taubin_ratio, 1e-9);
    // Both remove noise.
    EXPECT_LT(testing::RadialRoughness(taubin.positions), 0.5 * testing::RadialRoughness(input))
        << op;
    // μ from the pass band: k_PB = 1/λ + 1/μ = 0.1.
    const double mu = testing::MeasurementValue(taubin.measurements, "effective_mu");
    EXPECT_NEAR(1.0 / 0.5 + 1.0 / mu, 0.1, 1e-12) << op;
  }
}

TEST(SmoothTaubin, RejectsCoefficientsThatDoNotAttenuate) {
  const MeshSequence sphere = testing::Icosphere(1);
  RunOptions options;
  options.operator_name = "tutte";
  options.parameters = {{"lambda", "0.5"}, {"mu", "-0.4"}};  // needs μ < −λ
  EXPECT_EQ(Prepare("smooth-taubin", sphere, options).status().code(), ErrorCode::kInvalidArgument);
  options.parameters = {{"lambda", "0.5"}, {"pass-band", "3"}};  // beyond 1/λ
  EXPECT_EQ(Prepare("smooth-taubin", sphere, options).status().code(), ErrorCode::kInvalidArgument);
}

TEST(SmoothImplicit, ReducesTheNoiseEnergyMonotonically) {
  const MeshSequence sphere = testing::NoisySphere(3, 1.0, 0.03);
  for (const char* op : {"tutte", "kirchhoff", "cotan-sym", "cotan-area"}) {
    RunOptions options;
    options.operator_name = op;
    options.parameters = {{"lambda", "0.5"}, {"iterations", "1"}};
    const PreparedRun run = MustPrepare("smooth-implicit", sphere, options);
    const SparseMatrixD& laplacian = run.laplace->matrix;
    // Dirichlet-type energy ‖L x‖² of the one operator, after 0, 1, 2, ... steps.
    FramePositionsD x = sphere.frame_d(0);
    double energy = (laplacian * Eigen::MatrixXd(x)).squaredNorm();
    const double start_roughness = testing::RadialRoughness(x);
    for (int step = 1; step <= 4; ++step) {
      x = MustApply(run, x).positions;
      const double next = (laplacian * Eigen::MatrixXd(x)).squaredNorm();
      EXPECT_LT(next, energy) << op << " step " << step;
      energy = next;
    }
    EXPECT_LT(testing::RadialRoughness(x), 0.5 * start_roughness) << op;
  }
}

TEST(SmoothImplicit, OneStepSolvesTheImplicitSystem) {
  // (I − λL) x′ = x holds for the output, symmetric (Cholesky) and non-symmetric (LU) alike.
  const MeshSequence grid = testing::JitteredPlanarGrid(8, 0.3);
  FramePositionsD input = grid.frame_d(0);
  for (int v = 0; v < grid.vertex_count(); ++v) input(v, 2) = std::sin(7.0 * v);
  MeshSequence noisy(grid.vertex_count(), grid.triangles(), 0);
  ASSERT_TRUE(noisy.AppendFrame(input.cast<float>()).ok());
  for (const char* op : {"cotan", "kirchhoff"}) {
    RunOptions options;
    options.operator_name = op;
    options.parameters = {{"lambda", "2"}};
    const PreparedRun run = MustPrepare("smooth-implicit", noisy, options);
    const FramePositionsD x = noisy.frame_d(0);
    const FrameOutput output = MustApply(run, x);
    const double step = testing::MeasurementValue(output.measurements, "effective_lambda");
    const Eigen::MatrixXd residual =
        Eigen::MatrixXd(output.positions) -
        step * (run.laplace->matrix * Eigen::MatrixXd(output.positions)) - Eigen::MatrixXd(x);
    EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-9) << op;
  }
}

TEST(Smoothing, OneOperatorForTheWholeSequence) {
  // RunMethod on a sequence equals applying the one prepared method frame by frame.
  const MeshSequence animation = testing::Animate(testing::Icosphere(2), 4);
  RunOptions options;
  options.operator_name = "cotan";
  options.parameters = {{"iterations", "3"}};
  const auto result = RunMethod("smooth-explicit", animation, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->sequence.frame_count(), animation.frame_count());
  const PreparedRun run = MustPrepare("smooth-explicit", animation, options);
  for (int f = 0; f < animation.frame_count(); ++f) {
    const FrameOutput output = MustApply(run, animation.frame_d(f));
    EXPECT_LT((result->sequence.frame_d(f) - output.positions).cwiseAbs().maxCoeff(), 1e-6);
  }
  // A DDL operator fitted to all frames works the same way.
  options.operator_name = "ddl";
  const auto ddl = RunMethod("smooth-implicit", animation, options);
  ASSERT_TRUE(ddl.ok()) << ddl.status().ToString();
  EXPECT_EQ(ddl->sequence.frame_count(), animation.frame_count());
}

}  // namespace
}  // namespace dmc
