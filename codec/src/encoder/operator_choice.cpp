#include "encoder/operator_choice.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "decoder/segment_reconstruction.h"
#include "decoder/syntax_reader.h"
#include "dmc/metrics.h"
#include "encoder/syntax_writer.h"

namespace dmc {
namespace {

// Rate–distortion slope used to compare codings at slightly different distortions: a coding
// whose STED is e^x times another's is worth kStedSlopeBits · x bits per frame and vertex. It is
// the slope of bpfv against ln STED measured on the encode ladders of samba, crane and
// horse-gallop between STED 0.02 and 0.05 (0.3–0.9; RD.md, "Operator fallback"). Candidates reach
// STEDs within about 20 % of each other (their steps are matched, below), so the choice is not
// sensitive to its exact value.
constexpr double kStedSlopeBits = 0.5;

// The measured frames' rows of a 3F-row trajectory quantity (the mean, the basis).
template <typename Matrix>
Matrix SampledFrameRows(const Matrix& rows, const std::vector<int>& frames) {
  Matrix sampled(3 * static_cast<Eigen::Index>(frames.size()), rows.cols());
  for (size_t k = 0; k < frames.size(); ++k) {
    sampled.middleRows(3 * static_cast<Eigen::Index>(k), 3) = rows.middleRows(3 * frames[k], 3);
  }
  return sampled;
}

// STED of the measured frames as the decoder rebuilds them from `syntax`, against the originals.
// The decoder's steps (FactorSegmentOperator, the solve, then the synthesis), each
// buffer released as soon as the next step no longer needs it: the deltas once solved, the
// operator once factored, and the decoded frames allocated only after the solve (the
// factorisation and the solve's right-hand sides are the peak). `factor` is used when it fits the
// coding, else the factorisation is made here and, with `keep`, handed back through it. An error
// is what the decoder would report on the coding (it must not be written); a coding the decoder
// rebuilds but whose STED is undefined gives NaN.
StatusOr<double> ReconstructedSted(const MeasuredFrames& measured, const MeshTopology& topology,
                                   SegmentSyntax& syntax, const Eigen::VectorXd& mean,
                                   const Eigen::MatrixXd& basis,
                                   const AnchoredLaplacianSolver* factor,
                                   std::optional<AnchoredLaplacianSolver>* keep) {
  std::optional<AnchoredLaplacianSolver> made;
  if (factor == nullptr) {
    DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace, RebuildSegmentOperator(topology, syntax));
    DMC_ASSIGN_OR_RETURN(made, FactorSegmentOperator(topology, laplace, syntax));
    factor = &*made;
  }
  DMC_ASSIGN_OR_RETURN(Eigen::MatrixXd coefficients,
                       factor->Solve(syntax.delta, syntax.anchor_values));
  if (made && keep != nullptr) *keep = std::move(made);
  made.reset();
  syntax.delta = Eigen::MatrixXd();
  const MeshSequence& original = measured.original;
  MeshSequence decoded(original.vertex_count(), original.triangles(), original.frame_count());
  DMC_RETURN_IF_ERROR(
      SynthesizeFrames(mean, basis, coefficients, decoded.frame_count(), decoded.data()));
  coefficients = Eigen::MatrixXd();
  if (!measured.meter) return std::numeric_limits<double>::quiet_NaN();
  const StatusOr<DistortionReport> report = measured.meter->Measure(decoded);
  return report.ok() ? report->sted : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

std::unique_ptr<MeasuredFrames> SampleMeasuredFrames(const SegmentTrajectories& trajectories,
                                                     const Triangles& triangles, int max_frames) {
  const int frame_count = static_cast<int>(trajectories.cols() / 3);
  auto measured = std::make_unique<MeasuredFrames>();
  const int stride = (frame_count + max_frames - 1) / max_frames;
  for (int f = 0; f < frame_count; f += stride) measured->frames.push_back(f);
  measured->original = MeshSequence(static_cast<int>(trajectories.rows()), triangles,
                                    static_cast<int>(measured->frames.size()));
  for (size_t k = 0; k < measured->frames.size(); ++k) {
    measured->original.frame(static_cast<int>(k)) =
        trajectories.middleCols(3 * measured->frames[k], 3);
  }
  StatusOr<DistortionMeter> meter = DistortionMeter::Create(measured->original);
  if (meter.ok()) measured->meter = std::move(meter).value();
  return measured;
}

StatusOr<SegmentCoding> ChooseDdlWeights(const std::vector<double>& fitted,
                                         const MeshTopology& topology,
                                         const EncoderOptions& options,
                                         format::WeightPrediction mode,
                                         const format::SegmentHeader& header,
                                         const WriteResidualsFn& write_residuals) {
  std::vector<double> dead_zones = {options.ddl_dead_zone};
  if (options.ddl_dead_zone == 0.0) dead_zones = {0.5, std::numeric_limits<double>::infinity()};
  std::optional<SegmentCoding> best;
  for (double dead_zone : dead_zones) {
    SegmentSyntax trial;
    trial.header = header;
    SegmentCoding coding;
    coding.header = header;
    coding.operator_payload = syntax::WriteDdlWeights(fitted, topology, header.weight_bits, mode,
                                                      &trial.edge_weights, dead_zone);
    DMC_RETURN_IF_ERROR(syntax::CheckDdlWeights(trial.edge_weights, header.weight_bits));
    DMC_ASSIGN_OR_RETURN(coding.residual_payload, write_residuals(trial));
    coding.edge_weights = std::move(trial.edge_weights);
    if (!best || coding.payload_bytes() < best->payload_bytes()) best = std::move(coding);
  }
  return std::move(*best);
}

std::vector<SegmentCoding> CodeFallbackCandidates(const format::SegmentHeader& ddl_header,
                                                  const MeshTopology& topology,
                                                  const Eigen::MatrixXd& mean_shape,
                                                  double reference_step,
                                                  const WriteResidualsFn& write_residuals,
                                                  std::optional<OperatorId> only) {
  std::vector<SegmentCoding> candidates;
  const double mean_degree =
      2.0 * static_cast<double>(topology.edges.size()) / topology.vertex_count;
  for (const auto& [id, step_scale] :
       {std::pair{OperatorId::kKirchhoff, mean_degree}, std::pair{OperatorId::kTutte, 1.0},
        std::pair{OperatorId::kMeanValue, 1.0}}) {
    if (only && id != *only) continue;
    SegmentSyntax target;
    target.header = ddl_header;
    target.header.operator_id = static_cast<uint8_t>(id);
    target.header.residual_step *= step_scale;
    // A candidate the format cannot carry here (its step, or the reference frame, out of range)
    // is left out.
    if (!syntax::CheckStep(target.header.residual_step, "", "").ok()) continue;
    SegmentCoding coding;
    if (id == OperatorId::kMeanValue) {
      const double step = ReferenceFrameStep(mean_shape, reference_step);
      if (!syntax::CheckStep(step, "", "").ok()) continue;
      coding.operator_payload =
          syntax::WriteReferenceFrame(mean_shape, topology, step, &target.reference_frame);
    }
    StatusOr<std::vector<uint8_t>> residuals = write_residuals(target);
    if (!residuals.ok()) continue;
    coding.header = target.header;
    coding.residual_payload = std::move(residuals).value();
    coding.reference_frame = std::move(target.reference_frame);
    candidates.push_back(std::move(coding));
  }
  return candidates;
}

double ReferenceFrameStep(const Eigen::MatrixXd& frame, double step) {
  // Coarse enough that every coordinate quantises to at most half the format's bound (exact: a
  // power-of-two division).
  const double largest = frame.size() == 0 ? 0.0 : frame.cwiseAbs().maxCoeff();
  return std::max(step, largest / static_cast<double>(format::kMaxReferenceMagnitude / 2));
}

bool FactorsByConstruction(uint8_t operator_id) {
  return operator_id == static_cast<uint8_t>(OperatorId::kKirchhoff) ||
         operator_id == static_cast<uint8_t>(OperatorId::kTutte);
}

StatusOr<SegmentCoding> ChooseSegmentOperator(const MeasuredFrames& measured,
                                              const MeshTopology& topology,
                                              const std::vector<int32_t>& vertex_order,
                                              const SegmentSyntax& shared,
                                              std::vector<SegmentCoding> codings,
                                              const OperatorChoiceOptions& choice) {
  if (codings.empty()) return InternalError("no coding of the segment to choose from");
  const int v_count = measured.original.vertex_count();
  const int frame_count = static_cast<int>(shared.header.frame_count);
  const double slope = kStedSlopeBits * v_count * frame_count;
  // The candidates worth measuring: rate alone rules out those that only a STED more than
  // prune_sted_ratio times lower could bring level with the smallest payload. The others are
  // kept, in order, for when none of those decodes.
  std::vector<size_t> measure, reserve;
  size_t smallest = 0;
  for (size_t c = 1; c < codings.size(); ++c) {
    if (codings[c].payload_bytes() < codings[smallest].payload_bytes()) smallest = c;
  }
  for (size_t c = 0; c < codings.size(); ++c) {
    const double excess = 8.0 * (static_cast<double>(codings[c].payload_bytes()) -
                                 static_cast<double>(codings[smallest].payload_bytes()));
    const bool worth = measured.meter && (choice.prune_sted_ratio <= 0.0 ||
                                          excess <= slope * std::log(choice.prune_sted_ratio));
    (worth ? measure : reserve).push_back(c);
  }
  // The smallest payload can come with a STED and KG far worse than the rate prune assumes:
  // BrainStem's fitted DDL weights at 2^-8 gave 0.292 bpfv at STED 0.051 and KG 27.8, and pruned
  // Tutte, which measures 0.370 bpfv at STED 0.037 and KG 2.8. So unless the smallest payload is
  // an operator whose normal matrix is well conditioned by construction (kirchhoff, tutte), the
  // smallest of those is measured too.
  if (measured.meter && !FactorsByConstruction(codings[smallest].header.operator_id)) {
    std::optional<size_t> safest;
    for (const size_t c : reserve) {
      if (FactorsByConstruction(codings[c].header.operator_id) &&
          (!safest || codings[c].payload_bytes() < codings[*safest].payload_bytes())) {
        safest = c;
      }
    }
    if (safest) {
      reserve.erase(std::find(reserve.begin(), reserve.end(), *safest));
      measure.insert(std::upper_bound(measure.begin(), measure.end(), *safest), *safest);
    }
  }
  if (measure.size() == 1 && !choice.need_sted &&
      FactorsByConstruction(codings[measure.front()].header.operator_id)) {
    return std::move(codings[measure.front()]);
  }
  const Eigen::VectorXd measured_mean = SampledFrameRows(shared.mean, measured.frames);
  const Eigen::MatrixXd measured_basis = SampledFrameRows(shared.basis, measured.frames);
  SegmentSyntax syntax;
  syntax.mean = shared.mean;
  syntax.basis = shared.basis;
  syntax.anchors = shared.anchors;
  syntax.anchor_step_exponents = shared.anchor_step_exponents;
  syntax.anchor_values = shared.anchor_values;
  // One candidate at a time (each measurement's solve, synthesis and metric run in parallel
  // within): only the best-so-far's factorisation is kept, so at most two exist at once. A
  // coding the decoder would reject (its normal matrix not positive definite, say) gives its
  // error; one it rebuilds without a STED, NaN.
  auto cost = [&](SegmentCoding& coding,
                  std::optional<AnchoredLaplacianSolver>* keep) -> StatusOr<double> {
    // The coding's operator inputs are lent to the syntax for the measurement.
    syntax.header = coding.header;
    std::swap(syntax.edge_weights, coding.edge_weights);
    std::swap(syntax.reference_frame, coding.reference_frame);
    const bool reuse = choice.factor != nullptr && choice.factor->Fits(coding);
    const Status read =
        syntax::ReadResiduals(coding.residual_payload, topology, vertex_order, syntax);
    const StatusOr<double> sted =
        read.ok() ? ReconstructedSted(measured, topology, syntax, measured_mean, measured_basis,
                                      reuse ? &*choice.factor->solver : nullptr, keep)
                  : StatusOr<double>(read);
    syntax.delta = Eigen::MatrixXd();
    std::swap(syntax.edge_weights, coding.edge_weights);
    std::swap(syntax.reference_frame, coding.reference_frame);
    if (!sted.ok()) return sted.status();
    if (!std::isfinite(*sted)) return std::numeric_limits<double>::quiet_NaN();
    coding.sted = *sted;
    return 8.0 * static_cast<double>(coding.payload_bytes()) +
           slope * std::log(std::max(*sted, 1e-300));
  };
  const bool keep = choice.keep_factor != nullptr;
  std::optional<AnchoredLaplacianSolver> best_factor, factor;
  std::optional<size_t> best;
  double best_cost = std::numeric_limits<double>::quiet_NaN();
  Status first_failure;
  // The cheapest measured coding that decodes; when the first that decodes has no STED, it alone
  // (nothing to compare with).
  for (const size_t c : measure) {
    StatusOr<double> candidate_cost = cost(codings[c], keep ? &factor : nullptr);
    if (!candidate_cost.ok()) {
      if (first_failure.ok()) first_failure = candidate_cost.status();
      factor.reset();
      continue;
    }
    if (!best) {
      best = c;
      best_cost = *candidate_cost;
      best_factor = std::move(factor);
      if (!std::isfinite(best_cost)) break;
    } else if (*candidate_cost < best_cost) {  // false for NaN
      best = c;
      best_cost = *candidate_cost;
      best_factor = std::move(factor);
    }
    factor.reset();
  }
  // None measured decodes: the first of the others that does.
  for (size_t r = 0; !best && r < reserve.size(); ++r) {
    SegmentCoding& coding = codings[reserve[r]];
    const StatusOr<double> decodes = FactorsByConstruction(coding.header.operator_id)
                                         ? StatusOr<double>(0.0)
                                         : cost(coding, keep ? &best_factor : nullptr);
    if (decodes.ok()) {
      best = reserve[r];
    } else {
      if (first_failure.ok()) first_failure = decodes.status();
      best_factor.reset();
    }
  }
  if (!best) {
    return first_failure.WithContext("segment at frame " +
                                     std::to_string(shared.header.first_frame) +
                                     ": no candidate operator decodes");
  }
  if (keep && best_factor) {
    choice.keep_factor->operator_id = codings[*best].header.operator_id;
    choice.keep_factor->edge_weights = codings[*best].edge_weights;
    choice.keep_factor->solver = std::move(best_factor);
  }
  return std::move(codings[*best]);
}

Status CheckCodingDecodes(const MeshTopology& topology, const std::vector<int32_t>& vertex_order,
                          const SegmentSyntax& shared, const SegmentCoding& coding) {
  if (coding.header.rank == 0 || FactorsByConstruction(coding.header.operator_id)) {
    return Status::Ok();
  }
  SegmentSyntax syntax;
  syntax.header = coding.header;
  syntax.edge_weights = coding.edge_weights;
  syntax.reference_frame = coding.reference_frame;
  syntax.anchors = shared.anchors;
  syntax.anchor_step_exponents = shared.anchor_step_exponents;
  syntax.anchor_values = shared.anchor_values;
  DMC_RETURN_IF_ERROR(
      syntax::ReadResiduals(coding.residual_payload, topology, vertex_order, syntax));
  DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace, RebuildSegmentOperator(topology, syntax));
  DMC_ASSIGN_OR_RETURN(const AnchoredLaplacianSolver solver,
                       FactorSegmentOperator(topology, laplace, syntax));
  return solver.Solve(syntax.delta, syntax.anchor_values).status();
}

}  // namespace dmc
