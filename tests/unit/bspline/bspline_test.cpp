// The restricted B-spline Laplace–Beltrami operator: exact identities of the elements and the
// integration, the nesting of the multigrid levels, the sphere spectrum against l(l+1) and its
// stability across tessellations (the paper's figure 3 and table 1), multigrid against a direct
// solve, and the per-vertex registry form.
#include "dmc/bspline.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dmc/operators.h"
#include "dmc/topology.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

struct Sphere {
  Triangles triangles;
  FramePositionsD positions;
};

Sphere UnitIcosphere(int level) {
  const MeshSequence sequence = testing::Icosphere(level);
  // Re-project in double precision: the float32 storage would put vertices 1e-8 off the sphere.
  FramePositionsD positions = sequence.frame_d(0);
  for (Eigen::Index v = 0; v < positions.rows(); ++v) positions.row(v).normalize();
  return {sequence.triangles(), positions};
}

BsplineOperator Build(const Sphere& sphere, int depth, int coarsest_depth,
                      BsplineIntegration integration = BsplineIntegration::kCubature,
                      int cubature_degree = 12) {
  BsplineOptions options;
  options.depth = depth;
  options.coarsest_depth = coarsest_depth;
  options.integration = integration;
  options.cubature_degree = cubature_degree;
  options.monte_carlo_samples = 200000;
  auto op = BuildBsplineOperator(sphere.triangles, sphere.positions, options);
  EXPECT_TRUE(op.ok()) << op.status().ToString();
  return std::move(op).value();
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

double MeshArea(const Sphere& sphere) {
  double area = 0.0;
  for (Eigen::Index t = 0; t < sphere.triangles.rows(); ++t) {
    const Eigen::Vector3d a = sphere.positions.row(sphere.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = sphere.positions.row(sphere.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = sphere.positions.row(sphere.triangles(t, 2)).transpose();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

TEST(BsplineOperator, ElementsSumToOneAndMatricesHaveTheirIdentities) {
  const Sphere sphere = UnitIcosphere(3);
  const BsplineOperator op = Build(sphere, 4, 4);
  const BsplineLevel& level = op.finest();
  const int n = level.dimension();
  ASSERT_GT(n, 0);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  // Partition of unity: constants are represented, so L·1 = 0 and 1ᵀD1 = area.
  EXPECT_LE((level.laplacian * ones).cwiseAbs().maxCoeff(), 1e-12 * MaxAbs(level.laplacian));
  EXPECT_NEAR(ones.dot(level.mass * ones), MeshArea(sphere), 1e-12 * MeshArea(sphere));
  EXPECT_NEAR(op.area, MeshArea(sphere), 1e-12);
  const Eigen::VectorXd at_vertices = op.evaluation * ones;
  EXPECT_LE((at_vertices.array() - 1.0).abs().maxCoeff(), 1e-12);
  // Exactly symmetric; D has a positive diagonal, L a negative one.
  EXPECT_EQ((SparseMatrixD(level.laplacian.transpose()) - level.laplacian).norm(), 0.0);
  EXPECT_EQ((SparseMatrixD(level.mass.transpose()) - level.mass).norm(), 0.0);
  EXPECT_GT(level.mass.diagonal().minCoeff(), 0.0);
  EXPECT_LT(level.laplacian.diagonal().maxCoeff(), 0.0);
  // Linear functions are in the space: the Dirichlet energy of x restricted to the sphere is
  // ∫|∇_M x|² = ∫(1 − n_x²) = (2/3)·area on the polyhedron only approximately, but the
  // coefficients of x are its B-spline coefficients: centres (node + ½)·h + origin.
  Eigen::VectorXd x_coefficients(n);
  const double h = op.frame.cube_size / (1 << level.depth);
  for (int i = 0; i < n; ++i)
    x_coefficients[i] = op.frame.origin.x() + (level.nodes[i].x() + 0.5) * h;
  EXPECT_LE((op.evaluation * x_coefficients - sphere.positions.col(0)).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(BsplineOperator, CoarseLevelsAreTheGalerkinProductsOfFineOnes) {
  const BsplineOperator op = Build(UnitIcosphere(2), 4, 2);
  ASSERT_EQ(op.levels.size(), 3u);
  for (size_t l = 0; l + 1 < op.levels.size(); ++l) {
    const SparseMatrixD& p = op.levels[l].prolongation;
    ASSERT_EQ(p.rows(), op.levels[l + 1].dimension());
    ASSERT_EQ(p.cols(), op.levels[l].dimension());
    const SparseMatrixD pt = p.transpose();
    const SparseMatrixD laplacian = pt * op.levels[l + 1].laplacian * p;
    const SparseMatrixD mass = pt * op.levels[l + 1].mass * p;
    EXPECT_LE(MaxAbs(laplacian - op.levels[l].laplacian), 1e-11 * MaxAbs(op.levels[l].laplacian))
        << "level " << l;
    EXPECT_LE(MaxAbs(mass - op.levels[l].mass), 1e-11 * MaxAbs(op.levels[l].mass)) << "level " << l;
    // The stencil ¼(1 3 3 1)³ sums to 8 per coarse node when no child is pruned.
    EXPECT_LE(pt.row(0).sum(), 8.0 + 1e-12);
  }
}

TEST(BsplineOperator, CubatureIsExactForTheElementDegree) {
  const Sphere sphere = UnitIcosphere(1);
  const BsplineOperator exact = Build(sphere, 3, 3);
  const BsplineOperator higher = Build(sphere, 3, 3, BsplineIntegration::kCubature, 20);
  const BsplineOperator low = Build(sphere, 3, 3, BsplineIntegration::kCubature, 3);
  const BsplineLevel& a = exact.finest();
  const BsplineLevel& b = higher.finest();
  ASSERT_EQ(a.dimension(), b.dimension());
  EXPECT_LE(MaxAbs(a.mass - b.mass), 1e-13 * MaxAbs(a.mass));
  EXPECT_LE(MaxAbs(a.laplacian - b.laplacian), 1e-13 * MaxAbs(a.laplacian));
  // A rule too weak for degree 12 visibly misses.
  EXPECT_GT(MaxAbs(a.mass - low.finest().mass), 1e-8 * MaxAbs(a.mass));
}

TEST(BsplineOperator, MonteCarloApproximatesTheExactIntegrals) {
  const Sphere sphere = UnitIcosphere(2);
  const BsplineOperator exact = Build(sphere, 3, 3);
  const BsplineOperator sampled = Build(sphere, 3, 3, BsplineIntegration::kMonteCarlo);
  const BsplineLevel& a = exact.finest();
  const BsplineLevel& b = sampled.finest();
  ASSERT_EQ(a.dimension(), b.dimension());
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(a.dimension());
  EXPECT_NEAR(ones.dot(b.mass * ones), MeshArea(sphere), 1e-9);  // weights sum to the area
  EXPECT_LE((b.laplacian * ones).cwiseAbs().maxCoeff(), 1e-12 * MaxAbs(b.laplacian));
  // 200k samples, a few thousand per element support: a few percent of noise overall.
  // Measured: 2.4% relative Frobenius difference for both matrices.
  EXPECT_LE((a.mass - b.mass).norm(), 0.05 * a.mass.norm());
  EXPECT_LE((a.laplacian - b.laplacian).norm(), 0.05 * a.laplacian.norm());
}

constexpr int kSpectrumDepth = 4;

std::vector<double> BsplineSphereSpectrum(int level, int* dimension) {
  const BsplineOperator op = Build(UnitIcosphere(level), kSpectrumDepth, kSpectrumDepth);
  *dimension = op.dimension();
  const auto spectrum = ComputeBsplineSpectrum(op, 16);
  EXPECT_TRUE(spectrum.ok()) << spectrum.status().ToString();
  if (!spectrum.ok()) return {};
  return {spectrum->eigenvalues.data(), spectrum->eigenvalues.data() + 16};
}

std::vector<double> CotanSphereSpectrum(int level) {
  const Sphere sphere = UnitIcosphere(level);
  const MeshTopology topology = BuildTopology(sphere.triangles, sphere.positions.rows());
  const auto op = BuildCotanSym(topology, sphere.positions);
  EXPECT_TRUE(op.ok());
  SparseMatrixD mass(op->mass.size(), op->mass.size());
  std::vector<Eigen::Triplet<double>> diagonal;
  for (Eigen::Index v = 0; v < op->mass.size(); ++v) diagonal.emplace_back(v, v, op->mass[v]);
  mass.setFromTriplets(diagonal.begin(), diagonal.end());
  const auto spectrum = ComputeGeneralizedSpectrum(-op->matrix, mass, 16);
  EXPECT_TRUE(spectrum.ok()) << spectrum.status().ToString();
  if (!spectrum.ok()) return {};
  return {spectrum->eigenvalues.data(), spectrum->eigenvalues.data() + 16};
}

// Eigenvalue k of the unit sphere: l(l+1) with multiplicity 2l+1.
double SphereEigenvalue(int k) {
  int l = 0;
  while ((l + 1) * (l + 1) <= k) ++l;
  return l * (l + 1.0);
}

// One icosphere tessellation per test (levels 2, 3, 4: 162, 642, 2562 vertices), so each runs
// alone. Measured at depth 4 (3528 elements at every level): the l = 3 group at 12.22 / 12.06 /
// 12.01, the cotangent one at 11.23 / 11.80 / 11.95 — the B-spline spectrum barely moves with the
// tessellation while the cotangent one only converges as the mesh is refined (figure 3).
class SphereSpectrum : public ::testing::TestWithParam<int> {};

TEST_P(SphereSpectrum, GroupsAtLTimesLPlusOneAndCloserThanCotan) {
  int dimension = 0;
  const std::vector<double> bspline = BsplineSphereSpectrum(GetParam(), &dimension);
  const std::vector<double> cotan = CotanSphereSpectrum(GetParam());
  ASSERT_EQ(bspline.size(), 16u);
  ASSERT_EQ(cotan.size(), 16u);
  EXPECT_NEAR(bspline[0], 0.0, 1e-6);  // the constants
  for (int k = 1; k < 16; ++k) {
    // Groups of 3, 5, 7 at l(l+1): ratios to the first group within a few percent, and the
    // values themselves within 2% on every tessellation.
    EXPECT_NEAR(bspline[k] / bspline[1], SphereEigenvalue(k) / 2.0,
                0.03 * SphereEigenvalue(k) / 2.0)
        << "k = " << k;
    EXPECT_NEAR(bspline[k], SphereEigenvalue(k), 0.02 * SphereEigenvalue(k)) << "k = " << k;
  }
  for (int k = 9; k < 16; ++k) {
    EXPECT_LT(std::abs(bspline[k] - SphereEigenvalue(k)),
              0.5 * std::abs(cotan[k] - SphereEigenvalue(k)))
        << "k = " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(IcosphereLevels, SphereSpectrum, ::testing::Values(2, 3, 4));

TEST(BsplineOperator, DimensionDoesNotFollowTheTessellation) {
  // Table 1: the element count depends on the surface, not on its 162 … 2562 vertices.
  std::vector<int> dimensions;
  for (int level : {2, 3, 4}) {
    dimensions.push_back(Build(UnitIcosphere(level), kSpectrumDepth, kSpectrumDepth).dimension());
  }
  const auto [low, high] = std::minmax_element(dimensions.begin(), dimensions.end());
  EXPECT_LE(*high - *low, 0.05 * *high);
  EXPECT_GT(*low, 1000);
}

TEST(BsplineMultigrid, CyclesConvergeToTheDirectSolution) {
  const Sphere sphere = UnitIcosphere(3);
  const BsplineOperator op = Build(sphere, 4, 2);
  ASSERT_EQ(op.levels.size(), 3u);
  // Screened Poisson fit of the coordinate field x: (K + D) η = ψ(∇x) + γ(x). Linear functions
  // lie in the element space, so the exact minimiser is x itself.
  const Eigen::MatrixXd x = sphere.positions.col(0);
  const auto values = IntegrateValueLoad(op, x);
  const auto gradients = IntegrateGradientLoad(op, x);
  ASSERT_TRUE(values.ok() && gradients.ok());
  const Eigen::VectorXd rhs = gradients->col(0) + values->col(0);
  auto multigrid = BsplineMultigrid::Create(op, 1.0, 1.0);
  ASSERT_TRUE(multigrid.ok()) << multigrid.status().ToString();

  const SparseMatrixD& a = multigrid->system(multigrid->level_count() - 1);
  SparseMatrixD shift(a.rows(), a.cols());
  shift.setIdentity();
  Eigen::SimplicialLDLT<SparseMatrixD> direct(a + 1e-13 * a.diagonal().mean() * shift);
  ASSERT_EQ(direct.info(), Eigen::Success);
  const Eigen::VectorXd exact = direct.solve(rhs);

  // Errors on the surface, in the L² norm of the restricted functions: √(eᵀDe) / √(xᵀDx).
  const SparseMatrixD& mass = op.finest().mass;
  const auto surface_error = [&](const Eigen::VectorXd& solution) {
    const Eigen::VectorXd e = solution - exact;
    return std::sqrt(e.dot(mass * e) / exact.dot(mass * exact));
  };
  for (MultigridCycle cycle : {MultigridCycle::kW, MultigridCycle::kV}) {
    MultigridOptions options;
    options.cycle = cycle;
    Eigen::VectorXd solution = Eigen::VectorXd::Zero(rhs.size());
    std::vector<double> errors{surface_error(solution)};
    std::vector<double> energies{std::sqrt((solution - exact).dot(a * (solution - exact)))};
    for (int c = 0; c < 40; ++c) {
      multigrid->Cycle(rhs, solution, options);
      errors.push_back(surface_error(solution));
      energies.push_back(std::sqrt((solution - exact).dot(a * (solution - exact))));
    }
    // Measured (W / V): surface error 1.6e-2 / 2.3e-2 after one cycle, 3.7e-4 / 4.6e-4 after 40.
    // A symmetric cycle is a contraction in the energy norm: the error never grows.
    for (size_t c = 1; c < energies.size(); ++c)
      EXPECT_LE(energies[c], energies[c - 1] * (1 + 1e-12));
    EXPECT_LT(errors[1], 0.1);
    EXPECT_LT(errors[40], 1e-3);
    EXPECT_LT(errors[40], 0.05 * errors[1]);
    // On the surface, the solution reproduces x (values at the vertices).
    EXPECT_LE((op.evaluation * solution - x.col(0)).cwiseAbs().maxCoeff(), 1e-2);
  }
  // Solve() stops at the requested residual.
  MultigridOptions options;
  options.relative_tolerance = 5e-3;  // the paper's Table 2 criterion
  Eigen::VectorXd solution = Eigen::VectorXd::Zero(rhs.size());
  const auto report = multigrid->Solve(rhs, solution, options);
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->converged);
  EXPECT_LE(report->final_residual, 5e-3 * rhs.norm());
  EXPECT_EQ(report->residual_history.size(), static_cast<size_t>(report->cycles));
  EXPECT_EQ(multigrid->Solve(rhs.head(3), solution).status().code(), ErrorCode::kMismatch);
}

TEST(BsplineVertexOperator, IsASymmetricLaplacianWithMass) {
  const Sphere sphere = UnitIcosphere(3);
  const MeshTopology topology = BuildTopology(sphere.triangles, sphere.positions.rows());
  const auto op = BuildBsplineVertexOperator(topology, sphere.positions, 4);
  ASSERT_TRUE(op.ok()) << op.status().ToString();
  const SparseMatrixD& l = op->matrix;
  ASSERT_EQ(l.rows(), sphere.positions.rows());
  EXPECT_EQ((SparseMatrixD(l.transpose()) - l).norm(), 0.0);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(l.rows());
  EXPECT_LE((l * ones).cwiseAbs().maxCoeff(), 1e-12 * MaxAbs(l));
  EXPECT_NEAR(op->mass.sum(), MeshArea(sphere), 1e-12 * MeshArea(sphere));
  // On the unit sphere Δx = −2x: m⁻¹ L_V x ≈ −2x (the lumped projection smooths a little).
  const Eigen::VectorXd x = sphere.positions.col(0);
  const Eigen::VectorXd laplacian = (l * x).cwiseQuotient(op->mass);
  const double ratio = laplacian.dot(x) / x.dot(x);
  // Measured: −1.967.
  EXPECT_NEAR(ratio, -2.0, 0.2);
  EXPECT_EQ(BuildBsplineVertexOperator(topology, sphere.positions.topRows(10), 4).status().code(),
            ErrorCode::kMismatch);
}

TEST(BsplineOperator, RejectsBadInput) {
  const Sphere sphere = UnitIcosphere(1);
  BsplineOptions options;
  options.depth = 0;
  EXPECT_EQ(BuildBsplineOperator(sphere.triangles, sphere.positions, options).status().code(),
            ErrorCode::kInvalidArgument);
  options.depth = 3;
  Triangles broken = sphere.triangles;
  broken(0, 0) = 1000;
  EXPECT_EQ(BuildBsplineOperator(broken, sphere.positions, options).status().code(),
            ErrorCode::kInvalidArgument);
  FramePositionsD flat = FramePositionsD::Zero(sphere.positions.rows(), 3);
  EXPECT_EQ(BuildBsplineOperator(sphere.triangles, flat, options).status().code(),
            ErrorCode::kInvalidArgument);
  const BsplineOperator op = Build(sphere, 3, 3);
  EXPECT_EQ(ComputeBsplineSpectrum(op, 0).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(BsplineMultigrid::Create(op, 0.0, 0.0).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
