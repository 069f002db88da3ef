// The factor-once/solve-many SPD solver and the anchored normal-equation solver (both backends).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <cstring>
#include <thread>
#include <vector>

#include "dmc/operators.h"
#include "test_support.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;

class SolverBackends : public ::testing::TestWithParam<SolverBackend> {
 protected:
  void SetUp() override {
    if (!SolverBackendAvailable(GetParam())) {
      GTEST_SKIP() << SolverBackendName(GetParam()) << " is not in this build (DMC_WITH_CHOLMOD)";
    }
  }
  SolverOptions Options() const {
    SolverOptions options;
    options.backend = GetParam();
    return options;
  }
};

// A build without CHOLMOD (the default: it is GPL) says so instead of quietly using another
// backend; kAuto then factors with SimplicialLDLT.
TEST(SparseSpdSolver, AnAbsentBackendIsUnsupported) {
  const MeshSequence sphere = testing::Icosphere(2);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const auto tutte = BuildTutte(topo);
  ASSERT_TRUE(tutte.ok());
  const SparseMatrixD normal = BuildNormalMatrix(tutte->matrix, std::vector<int32_t>{0});
  EXPECT_TRUE(SolverBackendAvailable(SolverBackend::kAuto));
  EXPECT_TRUE(SolverBackendAvailable(SolverBackend::kSimplicialLdlt));
  EXPECT_EQ(SolverBackendAvailable(SolverBackend::kCholmod), DMC_WITH_CHOLMOD != 0);
  SolverOptions options;
  options.backend = SolverBackend::kCholmod;
  const auto cholmod = SparseSpdSolver::Factor(normal, options);
  if (DMC_WITH_CHOLMOD) {
    EXPECT_TRUE(cholmod.ok()) << cholmod.status().ToString();
  } else {
    ASSERT_FALSE(cholmod.ok());
    EXPECT_EQ(cholmod.status().code(), ErrorCode::kUnsupported);
    EXPECT_THAT(cholmod.status().message(), HasSubstr("DMC_WITH_CHOLMOD=OFF"));
  }
  options.backend = SolverBackend::kAuto;
  EXPECT_TRUE(SparseSpdSolver::Factor(normal, options).ok());
}

INSTANTIATE_TEST_SUITE_P(Backends, SolverBackends,
                         ::testing::Values(SolverBackend::kAuto, SolverBackend::kCholmod,
                                           SolverBackend::kSimplicialLdlt),
                         [](const auto& info) {
                           std::string name(SolverBackendName(info.param));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST_P(SolverBackends, SolvesManyRightHandSidesOfANormalMatrix) {
  const MeshSequence sphere = testing::Icosphere(3);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const auto tutte = BuildTutte(topo);
  ASSERT_TRUE(tutte.ok());
  const std::vector<int32_t> anchors = {0, 17, 300};
  const SparseMatrixD normal = BuildNormalMatrix(tutte->matrix, anchors);
  // N = LᵀL + Σ e_a e_aᵀ, checked entry-wise on the dense product.
  Eigen::MatrixXd dense_l(tutte->matrix);
  Eigen::MatrixXd expected = dense_l.transpose() * dense_l;
  for (const int a : anchors) expected(a, a) += 1.0;
  EXPECT_LE((Eigen::MatrixXd(normal) - expected).cwiseAbs().maxCoeff(), 1e-14);

  const auto solver = SparseSpdSolver::Factor(normal, Options());
  ASSERT_TRUE(solver.ok()) << solver.status().ToString();
  EXPECT_NE(solver->backend(), SolverBackend::kAuto);
  EXPECT_GT(solver->pivot_ratio(), 1e-10);
  const Eigen::MatrixXd x = Eigen::MatrixXd::NullaryExpr(
      topo.vertex_count, 5,
      [](Eigen::Index r, Eigen::Index c) { return std::cos(0.1 * r * (c + 1)); });
  const auto solved = solver->Solve(normal * x);
  ASSERT_TRUE(solved.ok()) << solved.status().ToString();
  EXPECT_LE((*solved - x).cwiseAbs().maxCoeff(), 1e-8);
}

// In place and sampled: SolveInPlace gives Solve's bits over several column blocks, and checking
// one residual column in 16 changes the check only, not the solution.
TEST_P(SolverBackends, SolveInPlaceAndSampledResidualCheckKeepTheBits) {
  const MeshSequence sphere = testing::Icosphere(3);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const auto tutte = BuildTutte(topo);
  ASSERT_TRUE(tutte.ok());
  const std::vector<int32_t> anchors = {0, 17, 300};
  const SparseMatrixD normal = BuildNormalMatrix(tutte->matrix, anchors);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::NullaryExpr(
      topo.vertex_count, 37,
      [](Eigen::Index r, Eigen::Index c) { return std::sin(0.05 * r * (c + 1)) + 0.01 * c; });
  const auto every_column = SparseSpdSolver::Factor(normal, Options());
  SolverOptions sampled_options = Options();
  sampled_options.residual_check_spacing = 16;
  const auto sampled = SparseSpdSolver::Factor(normal, sampled_options);
  ASSERT_TRUE(every_column.ok() && sampled.ok());
  const auto solved = every_column->Solve(rhs);
  ASSERT_TRUE(solved.ok()) << solved.status().ToString();
  Eigen::MatrixXd in_place = rhs;
  ASSERT_TRUE(sampled->SolveInPlace(in_place).ok());
  EXPECT_EQ(std::memcmp(in_place.data(), solved->data(), sizeof(double) * rhs.size()), 0);
  EXPECT_LE((normal * in_place - rhs).cwiseAbs().maxCoeff(), 1e-8);

  sampled_options.residual_check_spacing = 0;
  EXPECT_EQ(SparseSpdSolver::Factor(normal, sampled_options).status().code(),
            ErrorCode::kInvalidArgument);
}

// The simplicial backend solves all columns at once in its own loop; it must give the bits of
// Eigen's SimplicialLDLT::solve column by column, zeros in the right-hand side included (Eigen
// skips those in the forward substitution, which can only change the sign of a zero).
TEST(SparseSpdSolver, SimplicialSolveOfAllColumnsMatchesEigenBitForBit) {
  const MeshSequence sphere = testing::Icosphere(3);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const auto cotan = BuildCotanSym(topo, sphere.frame_d(0));
  ASSERT_TRUE(cotan.ok());
  const SparseMatrixD normal = BuildNormalMatrix(cotan->matrix, std::vector<int32_t>{0, 200});
  Eigen::MatrixXd rhs = Eigen::MatrixXd::NullaryExpr(
      topo.vertex_count, 9,
      [](Eigen::Index r, Eigen::Index c) { return std::sin(0.07 * r * (c + 1)) - 0.3 * c; });
  rhs.col(2).setZero();
  rhs.block(0, 4, topo.vertex_count / 2, 2).setZero();
  rhs(5, 7) = -0.0;
  SolverOptions options;
  options.backend = SolverBackend::kSimplicialLdlt;
  const auto solver = SparseSpdSolver::Factor(normal, options);
  ASSERT_TRUE(solver.ok()) << solver.status().ToString();
  const auto solved = solver->Solve(rhs);
  ASSERT_TRUE(solved.ok()) << solved.status().ToString();
  Eigen::SimplicialLDLT<SparseMatrixD, Eigen::Lower, Eigen::AMDOrdering<int>> eigen(normal);
  ASSERT_EQ(eigen.info(), Eigen::Success);
  for (Eigen::Index c = 0; c < rhs.cols(); ++c) {
    const Eigen::VectorXd expected = eigen.solve(rhs.col(c));
    EXPECT_EQ(std::memcmp(expected.data(), solved->col(c).data(), sizeof(double) * rhs.rows()), 0)
        << "column " << c;
  }
}

TEST_P(SolverBackends, RejectsASingularNormalMatrixInsteadOfReturningGarbage) {
  const MeshSequence sphere = testing::Icosphere(2);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const auto tutte = BuildTutte(topo);
  // No anchors: LᵀL has the constants in its null space.
  const auto solver = SparseSpdSolver::Factor(BuildNormalMatrix(tutte->matrix, {}), Options());
  ASSERT_FALSE(solver.ok());
  EXPECT_EQ(solver.status().code(), ErrorCode::kNumericalFailure);
}

TEST_P(SolverBackends, RejectsAnIndefiniteMatrix) {
  SparseMatrixD indefinite(2, 2);
  indefinite.insert(0, 0) = 1.0;
  indefinite.insert(1, 1) = -1.0;
  const auto solver = SparseSpdSolver::Factor(indefinite, Options());
  EXPECT_EQ(solver.status().code(), ErrorCode::kNumericalFailure);
}

TEST_P(SolverBackends, AnchoredSolverReproducesPositionsFromDifferentialCoordinates) {
  const MeshSequence mesh = testing::Animate(testing::JitteredPlanarGrid(15, 0.3), 2);
  const MeshTopology topo = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const FramePositionsD frame = mesh.frame_d(1);
  const Eigen::MatrixXd x = frame;
  for (const auto& op : {BuildTutte(topo), BuildCotan(topo, mesh.frame_d(0)),
                         BuildCotanSym(topo, mesh.frame_d(0)), BuildMeanValue(topo, frame)}) {
    ASSERT_TRUE(op.ok());
    std::vector<int32_t> anchors = {0, 37, 112, 200};
    const auto solver = AnchoredLaplacianSolver::Create(topo, op->matrix, anchors, 1.0, Options());
    ASSERT_TRUE(solver.ok()) << op->name << ": " << solver.status().ToString();
    Eigen::MatrixXd anchor_values(anchors.size(), 3);
    for (size_t k = 0; k < anchors.size(); ++k) anchor_values.row(k) = x.row(anchors[k]);
    const auto solved = solver->Solve(op->matrix * x, anchor_values);
    ASSERT_TRUE(solved.ok()) << solved.status().ToString();
    EXPECT_LE((*solved - x).cwiseAbs().maxCoeff(), 1e-9) << op->name;
  }
}

TEST(SparseSpdSolver, OrderingsGiveTheSameSolution) {
  const MeshSequence grid = testing::JitteredPlanarGrid(72, 0.3);  // 5184 vertices: METIS range
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const auto cotan = BuildCotanSym(topo, grid.frame_d(0));
  const SparseMatrixD normal = BuildNormalMatrix(cotan->matrix, std::vector<int32_t>{0, 4000});
  const Eigen::MatrixXd x = Eigen::MatrixXd(grid.frame_d(0));
  for (const auto ordering :
       {SolverOrdering::kAuto, SolverOrdering::kAmd, SolverOrdering::kMetis}) {
    SolverOptions options;
    options.ordering = ordering;
    const auto solver = SparseSpdSolver::Factor(normal, options);
    ASSERT_TRUE(solver.ok()) << solver.status().ToString();
    const auto solved = solver->Solve(normal * x);
    ASSERT_TRUE(solved.ok());
    EXPECT_LE((*solved - x).cwiseAbs().maxCoeff(), 1e-8);
  }
}

// Concurrent factorisations must not perturb each other: METIS draws from process-wide random
// state, and segments decoded in parallel must reproduce the encoder's measurement bit for bit.
TEST(SparseSpdSolver, ConcurrentNestedDissectionFactorisationsAreBitIdentical) {
  const MeshSequence grid = testing::JitteredPlanarGrid(40, 0.3);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const auto cotan = BuildCotanSym(topo, grid.frame_d(0));
  ASSERT_TRUE(cotan.ok());
  const SparseMatrixD normal = BuildNormalMatrix(cotan->matrix, std::vector<int32_t>{0, 900});
  const Eigen::MatrixXd rhs = normal * Eigen::MatrixXd(grid.frame_d(0));
  if (!SolverBackendAvailable(SolverBackend::kCholmod)) {
    GTEST_SKIP() << "METIS orderings are CHOLMOD's, not in this build (DMC_WITH_CHOLMOD)";
  }
  SolverOptions options;
  options.backend = SolverBackend::kCholmod;
  options.ordering = SolverOrdering::kMetis;
  auto solve_once = [&]() -> Eigen::MatrixXd {
    const auto solver = SparseSpdSolver::Factor(normal, options);
    if (!solver.ok()) return {};
    const auto solved = solver->Solve(rhs);
    return solved.ok() ? *solved : Eigen::MatrixXd();
  };
  const Eigen::MatrixXd reference = solve_once();
  ASSERT_GT(reference.size(), 0);
  constexpr int kThreads = 4, kRounds = 8;
  std::vector<Eigen::MatrixXd> results(kThreads * kRounds);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int round = 0; round < kRounds; ++round) results[t * kRounds + round] = solve_once();
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (const Eigen::MatrixXd& result : results) {
    ASSERT_EQ(result.size(), reference.size());
    EXPECT_TRUE(result == reference)
        << "max difference " << (result - reference).cwiseAbs().maxCoeff();
  }
}

TEST(AnchoredLaplacianSolver, RequiresAnAnchorInEveryComponent) {
  const MeshSequence mesh = testing::TwoTetrahedraAndIsolatedVertex();
  const MeshTopology topo = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const auto tutte = BuildTutte(topo);
  const auto missing = AnchoredLaplacianSolver::Create(topo, tutte->matrix, {0, 8});
  EXPECT_EQ(missing.status().code(), ErrorCode::kNumericalFailure);
  EXPECT_THAT(missing.status().message(), HasSubstr("no anchor"));
  const auto complete = AnchoredLaplacianSolver::Create(topo, tutte->matrix, {0, 5, 8});
  ASSERT_TRUE(complete.ok()) << complete.status().ToString();
  // The isolated vertex is fixed by its anchor alone.
  const Eigen::MatrixXd x = mesh.frame_d(0);
  Eigen::MatrixXd anchor_values(3, 3);
  anchor_values << x.row(0), x.row(5), x.row(8);
  const auto solved = complete->Solve(tutte->matrix * x, anchor_values);
  ASSERT_TRUE(solved.ok());
  EXPECT_LE((*solved - x).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(AnchoredLaplacianSolver, ValidatesShapes) {
  const MeshSequence grid = testing::PlanarGrid(4);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const auto tutte = BuildTutte(topo);
  EXPECT_EQ(AnchoredLaplacianSolver::Create(topo, tutte->matrix, {99}).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(AnchoredLaplacianSolver::Create(topo, tutte->matrix, {0}, 0.0).status().code(),
            ErrorCode::kInvalidArgument);
  const auto solver = AnchoredLaplacianSolver::Create(topo, tutte->matrix, {0});
  ASSERT_TRUE(solver.ok());
  EXPECT_EQ(solver->Solve(Eigen::MatrixXd::Zero(3, 3), Eigen::MatrixXd::Zero(1, 3)).status().code(),
            ErrorCode::kMismatch);
  EXPECT_EQ(
      solver->Solve(Eigen::MatrixXd::Zero(16, 3), Eigen::MatrixXd::Zero(2, 3)).status().code(),
      ErrorCode::kMismatch);
}

TEST(SparseSpdSolver, ValidatesInputs) {
  EXPECT_EQ(SparseSpdSolver::Factor(SparseMatrixD(2, 3)).status().code(),
            ErrorCode::kInvalidArgument);
  SparseMatrixD identity(3, 3);
  identity.setIdentity();
  const auto solver = SparseSpdSolver::Factor(identity);
  ASSERT_TRUE(solver.ok());
  EXPECT_EQ(solver->Solve(Eigen::MatrixXd::Ones(2, 1)).status().code(), ErrorCode::kMismatch);
  const auto solved = solver->Solve(Eigen::MatrixXd::Constant(3, 2, 4.0));
  ASSERT_TRUE(solved.ok());
  EXPECT_EQ(*solved, Eigen::MatrixXd::Constant(3, 2, 4.0));
}

}  // namespace
}  // namespace dmc
