// The ddl operator's fallback never keeps a coding the decoder cannot factor (issue 21): on
// BrainStem the fitted weights rounded to zero on whole edge cuts, leaving pieces of a component
// without an anchor and LᵀL + anchors singular; the encoder kept that coding and wrote a stream no
// decoder accepts. Here a coding with the same defect (every edge of a vertex weighted 0) is
// offered first.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bitstream/syntax.h"
#include "decoder/segment_reconstruction.h"
#include "dmc/synth.h"
#include "dmc/topology.h"
#include "encoder/basis_writer.h"
#include "encoder/operator_choice.h"
#include "encoder/syntax_writer.h"
#include "fitting/segment_pca.h"

namespace dmc {
namespace {

class OperatorFallback : public ::testing::Test {
 protected:
  void SetUp() override {
    SynthOptions options;
    options.frames = 12;
    options.resolution = 300;
    StatusOr<MeshSequence> blob = Synthesize("blob", options);
    ASSERT_TRUE(blob.ok()) << blob.status().ToString();
    sequence_ = std::move(blob).value();
    topology_ = BuildTopology(sequence_.triangles(), sequence_.vertex_count());
    order_ = format::BreadthFirstOrder(topology_);
    const SegmentTrajectories trajectories = GatherTrajectories(sequence_, 0, 12);
    const SegmentPca pca = ComputeSegmentPca(trajectories);
    const double diagonal = ComputeBoundingBox(sequence_).diagonal();
    format::SegmentHeader& h = shared_.header;
    h.frame_count = 12;
    h.rank = 4;
    h.anchor_count = 1;
    h.mean_step = std::ldexp(diagonal, -18);
    h.residual_step = std::ldexp(diagonal, -10);
    h.anchor_step = h.residual_step;
    shared_.anchors = {0};
    syntax::WriteMean(pca.mean, h, &shared_.mean);
    syntax::WriteBasis(pca.eigenvectors.leftCols(4), h, &shared_.basis);
    const Eigen::MatrixXd projected =
        ProjectTrajectories(trajectories, shared_.mean, shared_.basis);
    coefficients_ =
        (shared_.basis.transpose() * shared_.basis).ldlt().solve(projected.transpose()).transpose();
    syntax::WriteAnchors(shared_.anchors, coefficients_, h, &shared_.anchor_values);
    measured_ = SampleMeasuredFrames(trajectories, sequence_.triangles(), 8);
  }

  // A coding of the segment with `id` (and, for the ddl, `weights`).
  SegmentCoding Coding(OperatorId id, std::vector<int64_t> weights = {}) const {
    SegmentSyntax target = shared_;
    target.header.operator_id = static_cast<uint8_t>(id);
    target.edge_weights = weights;
    SegmentCoding coding;
    coding.header = target.header;
    coding.edge_weights = std::move(weights);
    StatusOr<LaplaceOperator> laplace = RebuildSegmentOperator(topology_, target);
    EXPECT_TRUE(laplace.ok()) << laplace.status().ToString();
    const Eigen::MatrixXd delta = laplace->matrix * coefficients_;
    StatusOr<std::vector<uint8_t>> residuals =
        syntax::WriteResiduals(delta, topology_, order_, target.header, nullptr);
    EXPECT_TRUE(residuals.ok()) << residuals.status().ToString();
    coding.residual_payload = std::move(residuals).value();
    return coding;
  }

  // Tutte-like weights of 2^-8 units, with every edge of the last vertex (not an anchor) at 0:
  // that vertex is a piece of its own for the operator, free to move, so LᵀL is singular.
  std::vector<int64_t> CutWeights() const {
    std::vector<int64_t> weights(topology_.edges.size());
    const int cut = topology_.vertex_count - 1;
    for (size_t e = 0; e < weights.size(); ++e) {
      const int i = topology_.edges[e][0], j = topology_.edges[e][1];
      weights[e] = (i == cut || j == cut) ? 0 : 512 / (topology_.degree(i) + topology_.degree(j));
    }
    return weights;
  }

  MeshSequence sequence_;
  MeshTopology topology_;
  std::vector<int32_t> order_;
  SegmentSyntax shared_;
  Eigen::MatrixXd coefficients_;
  std::unique_ptr<MeasuredFrames> measured_;
};

TEST_F(OperatorFallback, ACodingWhoseNormalMatrixIsSingularIsNotChosen) {
  const SegmentCoding cut = Coding(OperatorId::kDdl, CutWeights());
  const Status decodes = CheckCodingDecodes(topology_, order_, shared_, cut);
  EXPECT_EQ(decodes.code(), ErrorCode::kNumericalFailure) << decodes.ToString();

  std::vector<SegmentCoding> codings;
  codings.push_back(cut);
  codings.push_back(Coding(OperatorId::kKirchhoff));
  codings.push_back(Coding(OperatorId::kTutte));
  const StatusOr<SegmentCoding> chosen = ChooseSegmentOperator(
      *measured_, topology_, order_, shared_, std::move(codings), OperatorChoiceOptions());
  ASSERT_TRUE(chosen.ok()) << chosen.status().ToString();
  EXPECT_NE(chosen->header.operator_id, static_cast<uint8_t>(OperatorId::kDdl));
  EXPECT_TRUE(std::isfinite(chosen->sted));
}

// Rate alone would rule the others out (they are only measured when none measured decodes).
TEST_F(OperatorFallback, TheCandidatesRateRuledOutAreTriedWhenNoneMeasuredDecodes) {
  std::vector<SegmentCoding> codings;
  codings.push_back(Coding(OperatorId::kDdl, CutWeights()));
  codings.push_back(Coding(OperatorId::kTutte));
  // Only codings within 0 bits of the smallest are measured: pad the tutte coding's payload
  // count (the choice reads only its residuals).
  codings.back().operator_payload.assign(codings.front().payload_bytes() + 100, 0);
  OperatorChoiceOptions choice;
  choice.prune_sted_ratio = 1.0;
  const StatusOr<SegmentCoding> chosen =
      ChooseSegmentOperator(*measured_, topology_, order_, shared_, std::move(codings), choice);
  ASSERT_TRUE(chosen.ok()) << chosen.status().ToString();
  EXPECT_EQ(chosen->header.operator_id, static_cast<uint8_t>(OperatorId::kTutte));
}

TEST_F(OperatorFallback, NoCandidateThatDecodesIsAnError) {
  std::vector<SegmentCoding> codings;
  codings.push_back(Coding(OperatorId::kDdl, CutWeights()));
  const StatusOr<SegmentCoding> chosen = ChooseSegmentOperator(
      *measured_, topology_, order_, shared_, std::move(codings), OperatorChoiceOptions());
  ASSERT_FALSE(chosen.ok());
  EXPECT_EQ(chosen.status().code(), ErrorCode::kNumericalFailure) << chosen.status().ToString();
  EXPECT_NE(chosen.status().message().find("no candidate operator decodes"), std::string::npos);
}

TEST_F(OperatorFallback, CombinatorialOperatorsFactorByConstruction) {
  for (const OperatorId id : {OperatorId::kKirchhoff, OperatorId::kTutte}) {
    EXPECT_TRUE(FactorsByConstruction(static_cast<uint8_t>(id)));
    EXPECT_TRUE(CheckCodingDecodes(topology_, order_, shared_, Coding(id)).ok());
  }
  EXPECT_FALSE(FactorsByConstruction(static_cast<uint8_t>(OperatorId::kDdl)));
}

}  // namespace
}  // namespace dmc
