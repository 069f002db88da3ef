#include "encoder/segment_encoder.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <utility>

#include "decoder/segment_reconstruction.h"
#include "dmc/operators.h"
#include "encoder/anchors.h"
#include "encoder/basis_writer.h"
#include "encoder/codec_operators.h"
#include "encoder/operator_choice.h"
#include "encoder/step_shaping.h"
#include "encoder/stream_writer.h"
#include "encoder/syntax_writer.h"

namespace dmc {
namespace {

// The mean trajectory's step is diagonal · 2^-kMeanStepBits (stream_writer.h), or coarser, when the
// mean lies so far from the origin (beyond 2^33 diagonals) that its values would exceed the
// format's 2^52 steps: the step is then 2^-51 of the largest value, at most the residual step.
constexpr int kMeanMagnitudeBits = 51;

// Ranks are compared by bits · STED^kRankStedElasticity, lowest wins: a coding that lowers the
// product lies below a ladder whose bits fall as STED^-kRankStedElasticity. Where the ranks
// differ most (low STED, long captures) the ladders are steeper than they are on average (jump-full
// 1.15 × bpfv per unit of ln STED between 0.01 and 0.02, against about 0.8 over the short
// excerpts), and 0.8 chose too few components there: with the search's quarter threshold (and
// 2^-7 weights), 1.3 gave jump-full -20.9 % BD-rate (STED) against -13.6 % at 0.8 and -19.1 % at
// 1.1, the other sequences within 0.6 points (RD.md, "Rank search").
constexpr double kRankStedElasticity = 1.3;

}  // namespace

// One segment's state between its PCA and its chunks.
namespace {

// The stream is written in format version kVersionMinor: the basis in its syntax (spec §8.3).
bool BasisV11() { return format::kVersionMinor >= 1; }

// The basis chunk of syntax.header's rank: in the 1.1 syntax with `depths`, else 1.0's.
std::vector<uint8_t> CodeBasis(const Eigen::MatrixXd& basis, const std::vector<uint8_t>& depths,
                               SegmentSyntax& syntax) {
  if (BasisV11()) return syntax::WriteBasis(basis, syntax.header, depths, &syntax.basis);
  return syntax::WriteBasis(basis, syntax.header, &syntax.basis);
}

}  // namespace

struct SegmentEncoder::Segment {
  int vertex_count = 0;
  format::SegmentHeader header;  // everything but the rank (and the operator the choice makes)
  std::vector<int> ranks;        // the ranks to code, highest (the plain threshold's) first
  std::vector<int32_t> anchors;
  // 1.2: the anchors' step exponents and the vertices' step factors they imply (empty = 1).
  std::vector<int8_t> step_exponents;
  std::vector<double> step_factors;
  Eigen::MatrixXd mean_shape;  // V × 3: anchors, reference frames; released after the last use
  SegmentSyntax syntax;        // decoded mean, basis and anchors of the rank being coded
  std::vector<uint8_t> mean_payload;
  std::vector<uint8_t> top_basis_payload;
  std::vector<uint8_t> basis_depths;  // 1.1: the top rank's per-column bit depths
  Eigen::MatrixXd top_basis;          // the top rank's decoded basis
  Eigen::MatrixXd eigenvectors;  // the top rank's principal directions, for the lower ranks' bases
  Eigen::MatrixXd projected;     // V × rank, kept while a rank is still to be coded
  std::unique_ptr<MeasuredFrames> measured;  // the fallback's measurement frames
  bool fallback = false;
  // Without SearchPlan::refit_at_every_rank: the top rank's fitted DDL weights, for the others.
  std::vector<double> fitted_weights;
  // Without SearchPlan::operators_at_every_rank: the operator the top rank chose, and (without
  // refit_at_every_rank) the factorisation its measurement made, for the lower ranks'.
  std::optional<uint8_t> chosen_operator;
  MeasuredFactor factor;
};

// The segment coded at one rank: everything that depends on the rank, and bits ·
// STED^kRankStedElasticity when the fallback measured it.
struct SegmentEncoder::RankCoding {
  format::SegmentHeader header;
  std::vector<uint8_t> basis_payload, anchor_payload, operator_payload, residual_payload;
  double cost = std::numeric_limits<double>::quiet_NaN();
};

SegmentEncoder::SegmentEncoder(const MeshTopology& topology, const Triangles& triangles,
                               const std::vector<int32_t>& vertex_order,
                               const EncoderOptions& options, OperatorId operator_id,
                               double diagonal, double residual_step)
    : topology_(topology),
      triangles_(triangles),
      vertex_order_(vertex_order),
      options_(options),
      operator_id_(operator_id),
      diagonal_(diagonal),
      residual_step_(residual_step),
      weight_prediction_(options.uniform_weight_prediction
                             ? format::WeightPrediction::kUniform
                             : format::WeightPrediction::kReferenceProportional),
      plan_(PlanSearch(options, operator_id)) {}

format::SegmentHeader SegmentEncoder::BaseHeader(int first_frame, int frame_count) const {
  format::SegmentHeader h;
  h.first_frame = static_cast<uint32_t>(first_frame);
  h.frame_count = static_cast<uint32_t>(frame_count);
  h.operator_id = static_cast<uint8_t>(operator_id_);
  h.basis_bits = static_cast<uint8_t>(options_.basis_bits);
  h.weight_bits = static_cast<uint8_t>(SegmentWeightBits(options_, frame_count));
  h.weight_prediction = static_cast<uint8_t>(weight_prediction_);
  h.mean_step = std::ldexp(diagonal_, -kMeanStepBits);
  h.residual_step = residual_step_;
  h.anchor_step = residual_step_ * options_.anchor_step_ratio;
  h.anchor_weight = 1.0;
  return h;
}

// An automatic rank keeps component k while λ_k > threshold · V · Δ²; with rank search, also the
// distinct non-zero lower ranks of the larger thresholds (SearchPlan::rank_scales). Fewer
// components are often the better trade: on crane (16 frames) at 10 residual bits, rank 3
// instead of 4 gave 3 % fewer bits and a lower STED, since the fourth component's quantisation
// error outweighed what it captured (RD.md, "Rank search").
std::vector<int> SegmentEncoder::CandidateRanks(const Eigen::VectorXd& eigenvalues, int max_rank,
                                                int vertex_count) const {
  if (options_.rank != 0) return {std::min(options_.rank, max_rank)};
  std::vector<int> ranks;
  for (const double scale : plan_.rank_scales) {
    const double threshold =
        scale * options_.rank_threshold * vertex_count * residual_step_ * residual_step_;
    int rank = 0;
    while (rank < max_rank && eigenvalues[rank] > threshold) ++rank;
    if (ranks.empty() || (rank < ranks.back() && rank > 0)) ranks.push_back(rank);
  }
  return ranks;
}

// PCA, ranks, anchors, the coded mean and top-rank basis (the coefficients are computed against
// their decoded values) and the projection. A basis column is quantised on its own, so a lower
// rank's decoded basis is the first columns of the top rank's, and one projection serves every
// rank.
StatusOr<SegmentEncoder::Segment> SegmentEncoder::Prepare(SegmentTrajectories trajectories,
                                                          int first_frame) const {
  Segment segment;
  segment.vertex_count = static_cast<int>(trajectories.rows());
  const int frame_count = static_cast<int>(trajectories.cols() / 3);
  SegmentPca pca = ComputeSegmentPca(trajectories);
  const int max_rank = std::min<int>(3 * frame_count, std::max(segment.vertex_count - 1, 0));
  segment.ranks = CandidateRanks(pca.eigenvalues, max_rank, segment.vertex_count);
  const int top_rank = segment.ranks.front();
  segment.header = BaseHeader(first_frame, frame_count);

  segment.mean_shape = MeanShape(trajectories);
  if (top_rank > 0) {
    segment.anchors =
        ChooseAnchors(segment.mean_shape, topology_,
                      RequestedAnchorCount(options_, segment.vertex_count, frame_count));
  }
  if (segment.anchors.empty()) segment.anchors.push_back(0);
  if (top_rank > 0) {
    segment.step_exponents =
        ChooseStepExponents(segment.mean_shape, topology_, segment.anchors, options_.step_shaping);
    segment.step_factors =
        format::VertexStepFactors(topology_, segment.anchors, segment.step_exponents);
  } else {
    segment.step_exponents.assign(segment.anchors.size(), 0);
  }
  segment.header.anchor_count = static_cast<uint32_t>(segment.anchors.size());

  const double coarsened = std::ldexp(pca.mean.cwiseAbs().maxCoeff(), -kMeanMagnitudeBits);
  if (coarsened > segment.header.mean_step) {
    // Coarser than the residual step, the mean's error would outweigh the residuals' (and the
    // shape's offset be lost): a sequence so flat and so far from the origin is refused.
    if (coarsened > residual_step_) {
      return UnsupportedError(
          "the mean trajectory reaches " + syntax::ShortNumber(pca.mean.cwiseAbs().maxCoeff()) +
          ", so far from the origin for the bounding-box diagonal " +
          syntax::ShortNumber(diagonal_) + " that its quantisation step would be " +
          syntax::ShortNumber(coarsened) + ", coarser than the residual step " +
          syntax::ShortNumber(residual_step_) + ": translate the input nearer the origin");
    }
    segment.header.mean_step = coarsened;
  }
  DMC_RETURN_IF_ERROR(syntax::CheckStep(segment.header.mean_step, "the mean step",
                                        "rescale the input (smaller coordinates)"));
  DMC_RETURN_IF_ERROR(syntax::CheckQuantisedRange(pca.mean, segment.header.mean_step,
                                                  format::kMaxMeanMagnitude,
                                                  "a mean trajectory value", ""));
  SegmentSyntax& syntax = segment.syntax;
  syntax.header = segment.header;
  syntax.header.rank = static_cast<uint32_t>(top_rank);
  segment.mean_payload = syntax::WriteMean(pca.mean, segment.header, &syntax.mean);
  if (BasisV11()) {
    segment.basis_depths = syntax::ChooseBasisDepths(
        std::span<const double>(pca.eigenvalues.data(), pca.eigenvalues.size()), top_rank,
        segment.vertex_count, residual_step_, segment.header.basis_bits);
  }
  segment.top_basis_payload =
      CodeBasis(pca.eigenvectors.leftCols(top_rank), segment.basis_depths, syntax);
  if (segment.ranks.size() > 1) segment.eigenvectors = pca.eigenvectors.leftCols(top_rank);
  pca = SegmentPca();  // its 3F × 3F eigenvectors
  if (top_rank > 0) {
    segment.projected = ProjectTrajectories(trajectories, syntax.mean, syntax.basis);
  }
  segment.fallback = top_rank > 0 && plan_.fallback;
  if (segment.fallback) {
    segment.measured = SampleMeasuredFrames(trajectories, triangles_, plan_.measured_frames);
  }
  trajectories = SegmentTrajectories();
  segment.top_basis = syntax.basis;
  return segment;
}

StatusOr<SegmentResult> SegmentEncoder::Encode(SegmentTrajectories trajectories, int first_frame,
                                               ByteWriter& out) const {
  DMC_ASSIGN_OR_RETURN(Segment segment, Prepare(std::move(trajectories), first_frame));
  // One rank at a time, keeping only the cheapest coding: the top rank's when the costs are not
  // measured, the higher rank on ties.
  const std::vector<int>& ranks = segment.ranks;
  auto next_rank = [&](size_t c) { return c + 1 < ranks.size() ? ranks[c + 1] : 0; };
  DMC_ASSIGN_OR_RETURN(RankCoding best, CodeAtRank(segment, ranks[0], next_rank(0)));
  if (!plan_.operators_at_every_rank) segment.chosen_operator = best.header.operator_id;
  for (size_t c = 1; c < ranks.size(); ++c) {
    // A lower rank that cannot be coded is not chosen: the top rank's coding is complete.
    StatusOr<RankCoding> candidate = CodeAtRank(segment, ranks[c], next_rank(c));
    if (candidate.ok() && candidate->cost < best.cost) best = std::move(candidate).value();
  }
  DMC_RETURN_IF_ERROR(syntax::CheckSegmentHeader(best.header, segment.vertex_count));
  return AppendChunks(segment, best, out);
}

// The coefficients at `rank` against the decoded basis. Solved as r × V, then transposed once
// the projection is released (after the last rank; before it, cut to the next rank's columns):
// with one rank, two V × r buffers at a time, not three.
Eigen::MatrixXd SegmentEncoder::SolveCoefficients(Segment& segment, int rank, int next_rank) const {
  if (rank == 0) return Eigen::MatrixXd(segment.vertex_count, 0);
  const Eigen::MatrixXd gram = segment.syntax.basis.transpose() * segment.syntax.basis;
  Eigen::MatrixXd solved = gram.ldlt().solve(segment.projected.leftCols(rank).transpose());
  if (next_rank == 0) {
    segment.projected = Eigen::MatrixXd();
  } else {
    segment.projected.conservativeResize(Eigen::NoChange, next_rank);
  }
  return solved.transpose();
}

StatusOr<SegmentEncoder::RankCoding> SegmentEncoder::CodeAtRank(Segment& segment, int rank,
                                                                int next_rank) const {
  RankCoding coding;
  SegmentSyntax& syntax = segment.syntax;
  syntax.header = segment.header;
  syntax.header.rank = static_cast<uint32_t>(rank);
  if (rank == segment.ranks.front()) {
    coding.basis_payload = segment.top_basis_payload;
    syntax.basis = segment.top_basis;
  } else {
    coding.basis_payload =
        CodeBasis(segment.eigenvectors.leftCols(rank), segment.basis_depths, syntax);
  }
  Eigen::MatrixXd coefficients = SolveCoefficients(segment, rank, next_rank);
  // Anchors before the operator: the DDL trials reconstruct with them.
  for (const int32_t a : segment.anchors) {
    DMC_RETURN_IF_ERROR(syntax::CheckQuantisedRange(
        coefficients.row(a), syntax.header.anchor_step, syntax::kMaxSignedMagnitude,
        "the coefficient of anchor " + std::to_string(a), "use a larger anchor step ratio"));
  }
  coding.anchor_payload = syntax::WriteAnchors(segment.anchors, coefficients, syntax.header,
                                               &syntax.anchor_values, segment.step_exponents);
  syntax.anchors = segment.anchors;
  syntax.anchor_step_exponents = segment.step_exponents;
  if (rank > 0 && operator_id_ == OperatorId::kDdl) {
    DMC_RETURN_IF_ERROR(
        CodeDdl(segment, coefficients, next_rank, rank == segment.ranks.front(), coding));
  } else {
    DMC_RETURN_IF_ERROR(CodeFixedOperator(segment, rank, coefficients, coding));
  }
  return coding;
}

// Codes δ = L·C for the operator `target` names, quantised with its header's step and the
// segment's step factors. The dequantised deltas are not kept: nothing after the coding uses them
// but the fallback's measurement, which decodes them from the payload. `segment` and
// `coefficients` must outlive the writer.
WriteResidualsFn SegmentEncoder::ResidualWriter(const Segment& segment,
                                                const Eigen::MatrixXd& coefficients) const {
  const std::span<const double> step_factors = segment.step_factors;
  return [this, &coefficients,
          step_factors](const SegmentSyntax& target) -> StatusOr<std::vector<uint8_t>> {
    DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace, RebuildSegmentOperator(topology_, target));
    const Eigen::MatrixXd delta = laplace.matrix * coefficients;
    return syntax::WriteResiduals(delta, topology_, vertex_order_, target.header, nullptr,
                                  options_.residual_rdo_lambda, step_factors);
  };
}

// The DDL coding: the weights fitted to these coefficients, or below the top rank without
// SearchPlan::refit_at_every_rank the top rank's, coded (fitted or predicted, ChooseDdlWeights)
// with the residuals they imply.
StatusOr<SegmentCoding> SegmentEncoder::CodeDdlWeights(Segment& segment,
                                                       Eigen::MatrixXd& coefficients,
                                                       bool top) const {
  const WriteResidualsFn write_residuals = ResidualWriter(segment, coefficients);
  const format::SegmentHeader& header = segment.syntax.header;
  if (!top && !plan_.refit_at_every_rank) {
    return ChooseDdlWeights(segment.fitted_weights, topology_, options_, weight_prediction_, header,
                            write_residuals);
  }
  OperatorOptions operator_options;
  operator_options.ddl.mu = options_.ddl_mu;
  // The coefficients are lent to the fit's source, not copied (the fit's factorisation is the
  // encoder's peak), and taken back after it.
  OperatorSource source = SourceFromTrajectories(std::move(coefficients));
  StatusOr<LaplaceOperator> fit = FitDdlSymmetric(topology_, source, operator_options);
  coefficients = std::move(*source.trajectories);
  DMC_ASSIGN_OR_RETURN(const LaplaceOperator fitted, std::move(fit));
  if (top && !plan_.refit_at_every_rank && segment.ranks.size() > 1) {
    segment.fitted_weights = fitted.weights.values;
  }
  return ChooseDdlWeights(fitted.weights.values, topology_, options_, weight_prediction_, header,
                          write_residuals);
}

// The DDL coding (CodeDdlWeights) and, with the fallback, the cheapest of it and the other
// candidate operators (ChooseSegmentOperator); below the top rank without
// SearchPlan::operators_at_every_rank, the top rank's operator alone, measured with the top
// rank's factorisation when it fits.
Status SegmentEncoder::CodeDdl(Segment& segment, Eigen::MatrixXd& coefficients, int next_rank,
                               bool top, RankCoding& coding) const {
  const SegmentSyntax& syntax = segment.syntax;
  const std::optional<uint8_t> only = top ? std::nullopt : segment.chosen_operator;
  std::vector<SegmentCoding> codings;
  if (!only || *only == static_cast<uint8_t>(OperatorId::kDdl)) {
    DMC_ASSIGN_OR_RETURN(SegmentCoding ddl, CodeDdlWeights(segment, coefficients, top));
    codings.push_back(std::move(ddl));
  }
  if (segment.fallback && (!only || *only != static_cast<uint8_t>(OperatorId::kDdl))) {
    for (SegmentCoding& candidate : CodeFallbackCandidates(
             syntax.header, topology_, segment.mean_shape,
             std::ldexp(diagonal_, -options_.reference_bits), ResidualWriter(segment, coefficients),
             only ? std::optional<OperatorId>(static_cast<OperatorId>(*only)) : std::nullopt)) {
      codings.push_back(std::move(candidate));
    }
  }
  if (codings.empty()) return InternalError("the top rank's operator has no coding at this rank");
  SegmentCoding chosen;
  if (segment.fallback) {
    coefficients = Eigen::MatrixXd();
    if (next_rank == 0) segment.mean_shape = Eigen::MatrixXd();
    // The measurement reads the syntax's mean, basis and anchors; rank search needs the STED.
    OperatorChoiceOptions choice;
    choice.prune_sted_ratio = plan_.prune_sted_ratio;
    choice.need_sted = segment.ranks.size() > 1;
    if (!top) choice.factor = &segment.factor;
    // Refitted weights differ per rank, so only the fallback's operators could reuse it: not
    // worth its memory beside the next fit.
    if (top && !plan_.operators_at_every_rank && !plan_.refit_at_every_rank && next_rank != 0) {
      choice.keep_factor = &segment.factor;
    }
    DMC_ASSIGN_OR_RETURN(chosen, ChooseSegmentOperator(*segment.measured, topology_, vertex_order_,
                                                       syntax, std::move(codings), choice));
    if (next_rank == 0) segment.factor = MeasuredFactor();
  } else {
    DMC_ASSIGN_OR_RETURN(chosen,
                         DecodableCoding(segment, std::move(codings.front()), coefficients));
  }
  coding.header = chosen.header;
  coding.operator_payload = std::move(chosen.operator_payload);
  coding.residual_payload = std::move(chosen.residual_payload);
  const size_t bytes = segment.mean_payload.size() + coding.basis_payload.size() +
                       coding.anchor_payload.size() + coding.operator_payload.size() +
                       coding.residual_payload.size();
  coding.cost = std::log(8.0 * static_cast<double>(bytes)) +
                kRankStedElasticity * std::log(std::max(chosen.sted, 1e-300));
  return Status::Ok();
}

// Without the fallback's measurement nothing has decoded the ddl coding: checked here, and when
// the decoder would reject it (fitted weights that leave the normal matrix singular), the
// fallback's first candidate that decodes takes its place (kirchhoff's, whose normal matrix is
// positive definite by construction).
StatusOr<SegmentCoding> SegmentEncoder::DecodableCoding(const Segment& segment, SegmentCoding ddl,
                                                        const Eigen::MatrixXd& coefficients) const {
  const Status decodes = CheckCodingDecodes(topology_, vertex_order_, segment.syntax, ddl);
  if (decodes.ok()) return ddl;
  for (SegmentCoding& candidate :
       CodeFallbackCandidates(segment.syntax.header, topology_, segment.mean_shape,
                              std::ldexp(diagonal_, -options_.reference_bits),
                              ResidualWriter(segment, coefficients))) {
    if (CheckCodingDecodes(topology_, vertex_order_, segment.syntax, candidate).ok()) {
      return std::move(candidate);
    }
  }
  return decodes.WithContext("segment at frame " + std::to_string(segment.header.first_frame) +
                             ": no operator decodes");
}

// An operator without a fit: a geometric one from the coded mean shape, a combinatorial one from
// the connectivity alone, or at rank 0 the ddl's predicted weights (nothing to reconstruct).
Status SegmentEncoder::CodeFixedOperator(Segment& segment, int rank,
                                         const Eigen::MatrixXd& coefficients,
                                         RankCoding& coding) const {
  SegmentSyntax& syntax = segment.syntax;
  if (format::IsGeometricOperator(static_cast<uint8_t>(operator_id_))) {
    // The reference frame is the segment's mean shape, coded so both sides build the same
    // geometric operator from it.
    const double step =
        ReferenceFrameStep(segment.mean_shape, std::ldexp(diagonal_, -options_.reference_bits));
    DMC_RETURN_IF_ERROR(syntax::CheckStep(step, "the reference frame step",
                                          "rescale the input (smaller coordinates)"));
    coding.operator_payload =
        syntax::WriteReferenceFrame(segment.mean_shape, topology_, step, &syntax.reference_frame);
  } else if (operator_id_ == OperatorId::kDdl) {
    const std::vector<double> unused(topology_.edges.size(), 0.0);
    coding.operator_payload =
        syntax::WriteDdlWeights(unused, topology_, syntax.header.weight_bits, weight_prediction_,
                                &syntax.edge_weights, std::numeric_limits<double>::infinity());
    DMC_RETURN_IF_ERROR(syntax::CheckDdlWeights(syntax.edge_weights, syntax.header.weight_bits));
  }
  if (rank > 0) {
    DMC_ASSIGN_OR_RETURN(coding.residual_payload, ResidualWriter(segment, coefficients)(syntax));
  }
  coding.header = syntax.header;
  if (rank > 0 && !FactorsByConstruction(syntax.header.operator_id) && !options_.measure) {
    // A geometric operator from degenerate geometry can leave the normal matrix singular: refused
    // rather than written, since the operator was asked for. (A measured encode decodes every
    // segment anyway, and refuses alike.)
    SegmentCoding check;
    check.header = coding.header;
    check.residual_payload = coding.residual_payload;
    check.reference_frame = syntax.reference_frame;
    DMC_RETURN_IF_ERROR(CheckCodingDecodes(topology_, vertex_order_, syntax, check)
                            .WithContext("segment at frame " +
                                         std::to_string(syntax.header.first_frame) + ": the " +
                                         std::string(CodecOperatorName(operator_id_)) +
                                         " operator does not decode here (use another operator)"));
  }
  return Status::Ok();
}

SegmentResult SegmentEncoder::AppendChunks(const Segment& segment, const RankCoding& coding,
                                           ByteWriter& out) const {
  SegmentResult result;
  result.rank = static_cast<int>(coding.header.rank);
  result.anchors = static_cast<int>(segment.anchors.size());
  result.operator_id = static_cast<OperatorId>(coding.header.operator_id);
  result.residual_step = coding.header.residual_step;
  auto append = [&](format::ChunkType type, const std::vector<uint8_t>& payload, uint64_t* size) {
    const size_t before = out.size();
    syntax::AppendChunk(out, type, payload);
    *size += out.size() - before;
  };
  append(format::ChunkType::kSegmentHeader, syntax::WriteSegmentHeader(coding.header),
         &result.sizes.header);
  append(format::ChunkType::kMean, segment.mean_payload, &result.sizes.mean);
  append(format::ChunkType::kBasis, coding.basis_payload, &result.sizes.basis);
  append(format::ChunkType::kOperator, coding.operator_payload, &result.sizes.operator_info);
  append(format::ChunkType::kAnchors, coding.anchor_payload, &result.sizes.anchors);
  append(format::ChunkType::kResiduals, coding.residual_payload, &result.sizes.residuals);
  return result;
}

}  // namespace dmc
