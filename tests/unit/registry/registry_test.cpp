// The operator registry: the table, lookups and their errors, sources, and every operator's
// identities in its own domain (per-vertex one-ring operators, the spacetime VF×VF operator, the
// B-spline element operator) on synthetic meshes and on the real sequences in ../shared/data.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "dmc/bspline.h"
#include "dmc/io.h"
#include "dmc/operators.h"
#include "dmc/pca.h"
#include "dmc/spacetime.h"
#include "test_support.h"
#include "unit/operators/operator_checks.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

OperatorOptions AnyDomain() {
  OperatorOptions options;
  options.allow_any_domain = true;
  return options;
}

double MaxAbs(const SparseMatrixD& matrix) {
  double largest = 0.0;
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      largest = std::max(largest, std::abs(it.value()));
    }
  }
  return largest;
}

// Exactly the per-vertex rows carry wire IDs: a decoder can rebuild only those.
TEST(OperatorRegistry, ListsEveryOperatorOnceWithItsWireIdAndDomain) {
  const std::vector<std::string> expected = {"kirchhoff", "tutte",      "cotan", "cotan-area",
                                             "cotan-sym", "mean-value", "ddl",   "ddl-asym",
                                             "spacetime", "bspline"};
  std::vector<std::string> names;
  std::set<int> ids;
  for (const OperatorInfo& info : OperatorRegistry()) {
    names.emplace_back(info.name);
    EXPECT_NE(info.factory, nullptr);
    EXPECT_FALSE(info.description.empty());
    EXPECT_NE(info.needs_geometry && info.needs_trajectories, true) << info.name;
    ASSERT_EQ(info.wire_id.has_value(), info.domain == OperatorDomain::kVertex) << info.name;
    if (!info.wire_id) continue;
    EXPECT_TRUE(ids.insert(static_cast<int>(*info.wire_id)).second) << "duplicate ID";
    EXPECT_EQ(OperatorIdName(*info.wire_id), info.name);  // decoder table agrees
    const auto by_id = FindOperator(*info.wire_id);
    ASSERT_TRUE(by_id.ok());
    EXPECT_EQ((*by_id)->name, info.name);
  }
  EXPECT_EQ(names, expected);
  EXPECT_EQ((*FindOperator("spacetime"))->domain, OperatorDomain::kSpacetime);
  EXPECT_EQ((*FindOperator("bspline"))->domain, OperatorDomain::kElement);
  EXPECT_EQ(OperatorDomainName(OperatorDomain::kVertex), "vertex");
  EXPECT_EQ(OperatorDomainName(OperatorDomain::kSpacetime), "spacetime");
  EXPECT_EQ(OperatorDomainName(OperatorDomain::kElement), "element");
}

TEST(OperatorRegistry, UnknownNamesAndIdsListWhatExists) {
  const auto name = FindOperator("laplace-beltrami");
  EXPECT_EQ(name.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(name.status().message(), HasSubstr("laplace-beltrami"));
  EXPECT_THAT(name.status().message(), HasSubstr("kirchhoff, tutte, cotan, cotan-area, cotan-sym, "
                                                 "mean-value, ddl, ddl-asym, spacetime, bspline"));
  const auto id = FindOperator(static_cast<OperatorId>(200));
  EXPECT_EQ(id.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(id.status().message(), HasSubstr("1 (kirchhoff)"));
  EXPECT_THAT(id.status().message(), HasSubstr("8 (ddl-asym)"));
  EXPECT_THAT(id.status().message(), Not(HasSubstr("spacetime")));  // no wire ID
}

// Callers written for V×V matrices (the processing methods, curvature, the Python binding) get a
// clear refusal instead of a matrix of another size unless they opt in.
TEST(OperatorRegistry, NonVertexDomainsNeedTheCallersConsent) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(1), 3);
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  const OperatorSource source = SourceFromSequence(seq);
  for (const char* name : {"spacetime", "bspline"}) {
    const auto refused = BuildOperator(name, topo, source);
    EXPECT_EQ(refused.status().code(), ErrorCode::kUnsupported) << name;
    EXPECT_THAT(refused.status().message(), HasSubstr(name));
    EXPECT_THAT(refused.status().message(), HasSubstr("per-vertex (V x V)"));
    const auto built = BuildOperator(name, topo, source, AnyDomain());
    ASSERT_TRUE(built.ok()) << name << ": " << built.status().ToString();
    EXPECT_EQ(built->name, name);
  }
}

TEST(OperatorRegistry, ReportsMissingInputs) {
  const MeshSequence grid = testing::PlanarGrid(4);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const OperatorSource coefficients = SourceFromTrajectories(Eigen::MatrixXd::Ones(16, 2));
  const auto cotan = BuildOperator("cotan", topo, coefficients);
  EXPECT_EQ(cotan.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(cotan.status().message(), HasSubstr("geometric"));
  OperatorSource frame_only;
  frame_only.reference_frame = grid.frame_d(0);
  EXPECT_EQ(BuildOperator("ddl", topo, frame_only).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(BuildOperator("tutte", topo, OperatorSource{}).ok());  // needs nothing
}

TEST(OperatorSources, LayOutTrajectoriesFrameAfterFrame) {
  const MeshSequence seq = testing::Animate(testing::Tetrahedron(), 3);
  const OperatorSource source = SourceFromSequence(seq);
  ASSERT_TRUE(source.trajectories && source.reference_frame);
  ASSERT_EQ(source.trajectories->rows(), 4);
  ASSERT_EQ(source.trajectories->cols(), 9);
  for (int f = 0; f < 3; ++f) {
    for (int v = 0; v < 4; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ((*source.trajectories)(v, 3 * f + axis), seq.frame(f)(v, axis));
      }
    }
  }
  EXPECT_TRUE(source.reference_frame->isApprox(MeanFrame(seq)));
  EXPECT_EQ(*SourceFromSequence(seq, 2).reference_frame, seq.frame_d(2));
  const OperatorSource single = SourceFromFrame(seq.frame_d(1));
  EXPECT_EQ(*single.trajectories, Eigen::MatrixXd(seq.frame_d(1)));
}

// The spacetime row: VF×VF, exactly symmetric, rows of W summing to zero, the nonzero count of
// the formula, one non-negative dual volume per row.
void ExpectSpacetimeIdentities(const LaplaceOperator& op, const MeshTopology& topo,
                               int frame_count) {
  SCOPED_TRACE("operator " + op.name);
  const Eigen::Index rows = static_cast<Eigen::Index>(topo.vertex_count) * frame_count;
  EXPECT_EQ(op.frame_count, frame_count);
  ASSERT_EQ(op.matrix.rows(), rows);
  ASSERT_EQ(op.matrix.cols(), rows);
  EXPECT_EQ(op.matrix.nonZeros(), SpacetimeNonzeroCount(topo, frame_count));
  EXPECT_EQ((SparseMatrixD(op.matrix.transpose()) - op.matrix).norm(), 0.0);
  EXPECT_LE((op.matrix * Eigen::VectorXd::Ones(rows)).cwiseAbs().maxCoeff(),
            1e-12 * MaxAbs(op.matrix));
  ASSERT_EQ(op.mass.size(), rows);
  EXPECT_GE(op.mass.minCoeff(), 0.0);
  EXPECT_LE(op.matrix.diagonal().maxCoeff(), 0.0);  // the sign convention
  EXPECT_TRUE(op.weights.values.empty());
  EXPECT_EQ(op.evaluation.size(), 0);
}

// The bspline row: N×N stiffness and mass, exactly symmetric, L·1 = 0, 1ᵀD1 = area, and a V×N
// evaluation matrix whose rows sum to one on every vertex in a triangle (partition of unity).
void ExpectElementIdentities(const LaplaceOperator& op, const MeshTopology& topo,
                             const FramePositionsD& positions) {
  SCOPED_TRACE("operator " + op.name);
  const Eigen::Index n = op.matrix.rows();
  ASSERT_GT(n, 0);
  ASSERT_EQ(op.matrix.cols(), n);
  ASSERT_EQ(op.mass_matrix.rows(), n);
  ASSERT_EQ(op.mass_matrix.cols(), n);
  ASSERT_EQ(op.evaluation.rows(), topo.vertex_count);
  ASSERT_EQ(op.evaluation.cols(), n);
  EXPECT_EQ(op.frame_count, 1);
  EXPECT_EQ((SparseMatrixD(op.matrix.transpose()) - op.matrix).norm(), 0.0);
  EXPECT_EQ((SparseMatrixD(op.mass_matrix.transpose()) - op.mass_matrix).norm(), 0.0);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  EXPECT_LE((op.matrix * ones).cwiseAbs().maxCoeff(), 1e-11 * MaxAbs(op.matrix));
  double area = 0.0;
  const Triangles triangles = TrianglesFromTopology(topo);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = positions.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d b = positions.row(triangles(t, 1)).transpose();
    const Eigen::Vector3d c = positions.row(triangles(t, 2)).transpose();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  EXPECT_NEAR(ones.dot(op.mass_matrix * ones), area, 1e-10 * area);
  const Eigen::VectorXd vertex_sums = op.evaluation * ones;
  for (int v = 0; v < topo.vertex_count; ++v) {
    EXPECT_NEAR(vertex_sums[v], topo.degree(v) > 0 ? 1.0 : 0.0, 1e-12) << "vertex " << v;
  }
  EXPECT_TRUE(op.weights.values.empty());
  EXPECT_EQ(op.mass.size(), 0);  // the mass is not diagonal
}

// `bspline_depth` 0 lets the row choose (about one voxel per mean edge: cheap on coarse meshes,
// seconds on real ones).
void ExpectEveryOperatorWorks(const MeshSequence& seq, const OperatorSource& source,
                              int bspline_depth = 0) {
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  OperatorOptions options = AnyDomain();
  options.bspline.depth = bspline_depth;
  for (const OperatorInfo& info : OperatorRegistry()) {
    const auto op = BuildOperator(info.name, topo, source, options);
    ASSERT_TRUE(op.ok()) << info.name << ": " << op.status().ToString();
    EXPECT_EQ(op->name, info.name);
    EXPECT_EQ(op->domain, info.domain) << info.name;
    EXPECT_EQ(op->symmetric, info.symmetric) << info.name;
    EXPECT_EQ(op->unit_sum, info.unit_sum) << info.name;
    switch (info.domain) {
      case OperatorDomain::kVertex:
        testing::ExpectOperatorIdentities(*op, topo);
        break;
      case OperatorDomain::kSpacetime:
        ExpectSpacetimeIdentities(*op, topo, seq.frame_count());
        break;
      case OperatorDomain::kElement:
        ExpectElementIdentities(*op, topo, *source.reference_frame);
        break;
    }
  }
}

TEST(OperatorRegistry, EveryOperatorPassesTheIdentitiesOnSyntheticSequences) {
  for (const MeshSequence& seq :
       {testing::Animate(testing::Icosphere(2), 5), testing::Animate(testing::Strip(10), 5),
        testing::Animate(testing::TwoTetrahedraAndIsolatedVertex(), 4),
        testing::Animate(testing::DefectiveGrid(), 4)}) {
    ExpectEveryOperatorWorks(seq, SourceFromSequence(seq));
  }
}

// The registry's spacetime row is the operator of dmc/spacetime.h: W and ⋆0 as built from the
// sequence (frame times from the frame rate), and M^{−1/2}·W·M^{−1/2} is the paper's Δ.
TEST(OperatorRegistry, SpacetimeRowIsTheSpacetimeLaplacian) {
  MeshSequence seq = testing::Animate(testing::Icosphere(2), 4);
  seq.frame_rate = 24.0;
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  OperatorOptions options = AnyDomain();
  options.spacetime.alpha = 0.5;
  options.spacetime.frame_rate = seq.frame_rate;
  const auto row = BuildOperator("spacetime", topo, SourceFromSequence(seq), options);
  ASSERT_TRUE(row.ok()) << row.status().ToString();
  SpacetimeOptions direct_options;
  direct_options.alpha = 0.5;
  const auto direct = BuildSpacetimeLaplacian(seq, direct_options);  // times k / 24 as well
  ASSERT_TRUE(direct.ok()) << direct.status().ToString();
  // Same measures, summed over triangles in another order (the row recovers them from the
  // topology): equal to rounding.
  EXPECT_LE(MaxAbs(row->matrix - direct->stiffness), 1e-12 * MaxAbs(direct->stiffness));
  EXPECT_LE((row->mass - direct->mass).cwiseAbs().maxCoeff(), 1e-12 * direct->mass.maxCoeff());
  const SparseMatrixD symmetrised = SymmetrisedSpacetimeLaplacian(row->matrix, row->mass);
  EXPECT_LE(MaxAbs(symmetrised - direct->matrix), 1e-12 * MaxAbs(direct->matrix));
  EXPECT_LE((symmetrised * row->mass.cwiseSqrt()).cwiseAbs().maxCoeff(),
            1e-12 * MaxAbs(symmetrised));
  // The frame rate matters: at time steps 1 instead of 1/24 the temporal couplings change.
  options.spacetime.frame_rate = 0.0;
  const auto unit_steps = BuildOperator("spacetime", topo, SourceFromSequence(seq), options);
  ASSERT_TRUE(unit_steps.ok());
  EXPECT_GT(MaxAbs(unit_steps->matrix - row->matrix), 1e-3 * MaxAbs(row->matrix));
}

TEST(OperatorRegistry, SpacetimeRowRejectsWhatIsNotASequence) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(1), 3);
  const MeshTopology topo = BuildTopology(seq.triangles(), seq.vertex_count());
  const auto single =
      BuildOperator("spacetime", topo, SourceFromFrame(seq.frame_d(0)), AnyDomain());
  EXPECT_EQ(single.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(single.status().message(), HasSubstr("at least 2 frames"));
  const auto ragged = BuildOperator(
      "spacetime", topo, SourceFromTrajectories(Eigen::MatrixXd::Ones(seq.vertex_count(), 7)),
      AnyDomain());
  EXPECT_EQ(ragged.status().code(), ErrorCode::kInvalidArgument);
  OperatorSource frame_only;
  frame_only.reference_frame = seq.frame_d(0);
  EXPECT_EQ(BuildOperator("spacetime", topo, frame_only, AnyDomain()).status().code(),
            ErrorCode::kInvalidArgument);
  OperatorOptions bad_alpha = AnyDomain();
  bad_alpha.spacetime.alpha = 0.0;
  EXPECT_EQ(BuildOperator("spacetime", topo, SourceFromSequence(seq), bad_alpha).status().code(),
            ErrorCode::kInvalidArgument);
}

// The element space is the octree's, not the mesh's: at a fixed depth, two tessellations of the
// unit sphere (162 and 642 vertices) give the same N, and the first eigenvalues through
// LaplacianSpectrum (element mass D) are the sphere's 0, 2, 2, 2.
TEST(OperatorRegistry, BsplineRowDimensionDoesNotGrowWithTessellation) {
  OperatorOptions options = AnyDomain();
  options.bspline.depth = 3;
  std::vector<Eigen::Index> dimensions;
  for (int level : {2, 3}) {
    SCOPED_TRACE(level);
    const MeshSequence sphere = testing::Icosphere(level);
    FramePositionsD positions = sphere.frame_d(0);
    for (Eigen::Index v = 0; v < positions.rows(); ++v) positions.row(v).normalize();
    const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
    const auto op = BuildOperator("bspline", topo, SourceFromFrame(positions), options);
    ASSERT_TRUE(op.ok()) << op.status().ToString();
    ExpectElementIdentities(*op, topo, positions);
    dimensions.push_back(op->matrix.rows());
    if (level == 2) {
      const auto spectrum = LaplacianSpectrum(*op, 4);
      ASSERT_TRUE(spectrum.ok()) << spectrum.status().ToString();
      EXPECT_NEAR(spectrum->eigenvalues[0], 0.0, 1e-6);
      for (int k = 1; k < 4; ++k) EXPECT_NEAR(spectrum->eigenvalues[k], 2.0, 0.05) << k;
    }
  }
  EXPECT_EQ(dimensions[0], dimensions[1]);
}

// Real data: every operator's identities, and the DDL's residual against the others on the
// sequence's PCA coefficients (the codec's use).
TEST(OperatorRegistry, RealSequences) {
  DMC_REQUIRE_SHARED_DATA(cow, "cow");
  ReadOptions read_options;
  read_options.max_frames = 12;
  for (const char* name : {"cow", "chicken-crossing"}) {
    SCOPED_TRACE(name);
    const auto seq = ReadSequence(testing::SharedData(name), read_options);
    ASSERT_TRUE(seq.ok()) << seq.status().ToString();
    const auto pca = ComputeTrajectoryPca(*seq, 16);
    ASSERT_TRUE(pca.ok());
    OperatorSource source = SourceFromSequence(*seq);
    ExpectEveryOperatorWorks(*seq, source, /*bspline_depth=*/4);

    source.trajectories = pca->coefficients;
    const MeshTopology topo = BuildTopology(seq->triangles(), seq->vertex_count());
    const auto ddl = BuildOperator("ddl", topo, source);
    ASSERT_TRUE(ddl.ok());
    const double ddl_energy = (ddl->matrix * pca->coefficients).squaredNorm();
    // Measured on 12 frames at r = 16 (Σ‖δ‖²): cow DDL 0.70 vs cotan 0.99, mean-value 1.31,
    // Tutte 7.4; chicken 2.46 vs 3.61, 12.6, 26.8. Non-unit-sum operators compare through their
    // unit-sum row scalings (Kirchhoff → Tutte, cotan-sym and cotan-area → cotan).
    for (const char* other : {"tutte", "cotan", "mean-value"}) {
      const auto op = BuildOperator(other, topo, source);
      ASSERT_TRUE(op.ok());
      EXPECT_LT(ddl_energy, (op->matrix * pca->coefficients).squaredNorm()) << other;
    }
  }
}

}  // namespace
}  // namespace dmc
