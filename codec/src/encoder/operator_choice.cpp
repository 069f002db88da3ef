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
// coding, else the factorisation is made here and, with `keep`, handed back through it.
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
  DMC_ASSIGN_OR_RETURN(const DistortionReport report, measured.meter->Measure(decoded));
  return report.sted;
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
    coding.operator_payload = syntax::WriteDdlWeights(fitted, topology, options.weight_bits, mode,
                                                      &trial.edge_weights, dead_zone);
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
    SegmentCoding coding;
    if (id == OperatorId::kMeanValue) {
      coding.operator_payload = syntax::WriteReferenceFrame(mean_shape, topology, reference_step,
                                                            &target.reference_frame);
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

SegmentCoding ChooseSegmentOperator(const MeasuredFrames& measured, const MeshTopology& topology,
                                    const std::vector<int32_t>& vertex_order,
                                    const SegmentSyntax& shared, std::vector<SegmentCoding> codings,
                                    const OperatorChoiceOptions& choice) {
  const int v_count = measured.original.vertex_count();
  const int frame_count = static_cast<int>(shared.header.frame_count);
  const double slope = kStedSlopeBits * v_count * frame_count;
  // No STED for this segment (e.g. an edge of length zero in every frame): keep the first.
  if (!measured.meter) return std::move(codings.front());
  // The candidates worth measuring: rate alone rules out those that only a STED more than
  // prune_sted_ratio times lower could bring level with the smallest payload.
  std::vector<size_t> measure;
  size_t smallest = 0;
  for (size_t c = 1; c < codings.size(); ++c) {
    if (codings[c].payload_bytes() < codings[smallest].payload_bytes()) smallest = c;
  }
  for (size_t c = 0; c < codings.size(); ++c) {
    const double excess = 8.0 * (static_cast<double>(codings[c].payload_bytes()) -
                                 static_cast<double>(codings[smallest].payload_bytes()));
    if (choice.prune_sted_ratio <= 0.0 || excess <= slope * std::log(choice.prune_sted_ratio)) {
      measure.push_back(c);
    }
  }
  if (measure.size() == 1 && !choice.need_sted) return std::move(codings[measure.front()]);
  const Eigen::VectorXd measured_mean = SampledFrameRows(shared.mean, measured.frames);
  const Eigen::MatrixXd measured_basis = SampledFrameRows(shared.basis, measured.frames);
  SegmentSyntax syntax;
  syntax.mean = shared.mean;
  syntax.basis = shared.basis;
  syntax.anchors = shared.anchors;
  syntax.anchor_values = shared.anchor_values;
  // One candidate at a time (each measurement's solve, synthesis and metric run in parallel
  // within): only the best-so-far's factorisation is kept, so at most two exist at once.
  auto cost = [&](SegmentCoding& coding, std::optional<AnchoredLaplacianSolver>* keep) {
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
    if (!sted.ok() || !std::isfinite(*sted)) return std::numeric_limits<double>::quiet_NaN();
    coding.sted = *sted;
    return 8.0 * static_cast<double>(coding.payload_bytes()) +
           slope * std::log(std::max(*sted, 1e-300));
  };
  const bool keep = choice.keep_factor != nullptr;
  std::optional<AnchoredLaplacianSolver> best_factor, factor;
  size_t best = measure.front();
  const double first_cost = cost(codings[best], keep ? &best_factor : nullptr);
  double best_cost = first_cost;
  for (size_t m = 1; m < measure.size() && std::isfinite(first_cost); ++m) {
    const double candidate_cost = cost(codings[measure[m]], keep ? &factor : nullptr);
    if (candidate_cost < best_cost) {  // false for NaN
      best_cost = candidate_cost;
      best = measure[m];
      best_factor = std::move(factor);
    }
    factor.reset();
  }
  if (keep && best_factor) {
    choice.keep_factor->operator_id = codings[best].header.operator_id;
    choice.keep_factor->edge_weights = codings[best].edge_weights;
    choice.keep_factor->solver = std::move(best_factor);
  }
  return std::move(codings[best]);
}

}  // namespace dmc
