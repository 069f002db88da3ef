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

// Frames of a segment on which the fallback's candidates are measured: all up to this many, else
// every k-th. Decoding and measuring every frame of a long segment three times cost as much as the
// rest of the encode; the candidates are ranked the same way on the subsample (the temporal part
// of STED then compares frames k apart, for every candidate alike).
constexpr int kMeasuredFrames = 32;

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
// The decoder's steps, each buffer released as soon as the next step no longer needs it: the
// deltas once solved, the operator with its factorisation, and the decoded frames allocated only
// after the solve (the factorisation and the solve's right-hand sides are the peak).
StatusOr<double> ReconstructedSted(const DistortionMeter& meter, const MeshTopology& topology,
                                   SegmentSyntax& syntax, const Eigen::VectorXd& mean,
                                   const Eigen::MatrixXd& basis, const MeshSequence& original) {
  Eigen::MatrixXd coefficients;
  {
    DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace, RebuildSegmentOperator(topology, syntax));
    DMC_ASSIGN_OR_RETURN(coefficients, ReconstructCoefficients(topology, laplace, syntax));
  }
  syntax.delta = Eigen::MatrixXd();
  MeshSequence decoded(original.vertex_count(), original.triangles(), original.frame_count());
  DMC_RETURN_IF_ERROR(
      SynthesizeFrames(mean, basis, coefficients, decoded.frame_count(), decoded.data()));
  coefficients = Eigen::MatrixXd();
  DMC_ASSIGN_OR_RETURN(const DistortionReport report, meter.Measure(decoded));
  return report.sted;
}

}  // namespace

MeasuredFrames SampleMeasuredFrames(const SegmentTrajectories& trajectories,
                                    const Triangles& triangles) {
  const int frame_count = static_cast<int>(trajectories.cols() / 3);
  MeasuredFrames measured;
  const int stride = (frame_count + kMeasuredFrames - 1) / kMeasuredFrames;
  for (int f = 0; f < frame_count; f += stride) measured.frames.push_back(f);
  measured.original = MeshSequence(static_cast<int>(trajectories.rows()), triangles,
                                   static_cast<int>(measured.frames.size()));
  for (size_t k = 0; k < measured.frames.size(); ++k) {
    measured.original.frame(static_cast<int>(k)) =
        trajectories.middleCols(3 * measured.frames[k], 3);
  }
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
                                                  const WriteResidualsFn& write_residuals) {
  std::vector<SegmentCoding> candidates;
  const double mean_degree =
      2.0 * static_cast<double>(topology.edges.size()) / topology.vertex_count;
  for (const auto& [id, step_scale] :
       {std::pair{OperatorId::kKirchhoff, mean_degree}, std::pair{OperatorId::kTutte, 1.0},
        std::pair{OperatorId::kMeanValue, 1.0}}) {
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
                                    const std::vector<int32_t>& vertex_order, SegmentSyntax shared,
                                    std::vector<SegmentCoding> codings) {
  const int v_count = measured.original.vertex_count();
  const int frame_count = static_cast<int>(shared.header.frame_count);
  const Eigen::VectorXd measured_mean = SampledFrameRows(shared.mean, measured.frames);
  const Eigen::MatrixXd measured_basis = SampledFrameRows(shared.basis, measured.frames);
  StatusOr<DistortionMeter> meter = DistortionMeter::Create(measured.original);
  // No STED for this segment (e.g. an edge of length zero in every frame): keep the DDL.
  if (!meter.ok()) return std::move(codings.front());
  auto cost = [&](SegmentCoding& coding) {
    // The coding's operator inputs are lent to the syntax for the measurement.
    shared.header = coding.header;
    std::swap(shared.edge_weights, coding.edge_weights);
    std::swap(shared.reference_frame, coding.reference_frame);
    const Status read =
        syntax::ReadResiduals(coding.residual_payload, topology, vertex_order, shared);
    const StatusOr<double> sted = read.ok()
                                      ? ReconstructedSted(*meter, topology, shared, measured_mean,
                                                          measured_basis, measured.original)
                                      : StatusOr<double>(read);
    shared.delta = Eigen::MatrixXd();
    std::swap(shared.edge_weights, coding.edge_weights);
    std::swap(shared.reference_frame, coding.reference_frame);
    if (!sted.ok() || !std::isfinite(*sted)) return std::numeric_limits<double>::quiet_NaN();
    coding.sted = *sted;
    return 8.0 * static_cast<double>(coding.payload_bytes()) +
           kStedSlopeBits * v_count * frame_count * std::log(std::max(*sted, 1e-300));
  };
  size_t best = 0;
  double best_cost = cost(codings[0]);
  if (!std::isfinite(best_cost)) return std::move(codings[0]);
  for (size_t c = 1; c < codings.size(); ++c) {
    const double candidate_cost = cost(codings[c]);
    if (candidate_cost < best_cost) {  // false for NaN
      best_cost = candidate_cost;
      best = c;
    }
  }
  return std::move(codings[best]);
}

}  // namespace dmc
