#include "dmc/encoder.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/segment_reconstruction.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/io.h"
#include "dmc/operators.h"
#include "encoder/codec_operators.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/encoder_options.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"
#include "fitting/segment_pca.h"
#include "io/pc2_stream.h"
#include "metrics/streaming_distortion.h"

namespace dmc {
namespace {

// Defaults chosen by measurement (see the README's rate-distortion notes).
constexpr int kDefaultSegmentFrames = 256;
constexpr int kMeanStepBits = 18;         // mean trajectory step = diagonal · 2^-18
constexpr double kAnchorFraction = 0.01;  // automatic anchor count = 1 % of the vertices,
// at most 1000 (the 1 % rule at 100k vertices): farthest-point sampling costs O(V · anchors), so
// the cap keeps it linear in V beyond that.
constexpr int kMaxAutomaticAnchors = 1000;

// Farthest-point sampling on the segment's mean shape, then one anchor added to every component
// that has none (the normal matrix is singular otherwise). Ascending indices. Each round scans
// the vertices in fixed blocks in parallel; the farthest vertex (lowest index on ties) is the same
// for any thread count.
std::vector<int32_t> ChooseAnchors(const Eigen::MatrixXd& mean_shape, const MeshTopology& topology,
                                   int count) {
  const int v_count = topology.vertex_count;
  count = std::clamp(count, 1, v_count);
  std::vector<double> distance(v_count, std::numeric_limits<double>::infinity());
  std::vector<uint8_t> chosen(v_count, 0);
  std::vector<int32_t> anchors;
  constexpr int kBlock = 8192;
  const int blocks = (v_count + kBlock - 1) / kBlock;
  std::vector<std::pair<double, int>> block_best(blocks);
  int next = 0;
  for (int a = 0; a < count; ++a) {
    anchors.push_back(next);
    chosen[next] = 1;
    const Eigen::RowVector3d p = mean_shape.row(next);
    tbb::parallel_for(0, blocks, [&](int block) {
      std::pair<double, int> best{-1.0, -1};
      const int end = std::min(v_count, (block + 1) * kBlock);
      for (int v = block * kBlock; v < end; ++v) {
        distance[v] = std::min(distance[v], (mean_shape.row(v) - p).squaredNorm());
        if (!chosen[v] && distance[v] > best.first) best = {distance[v], v};
      }
      block_best[block] = best;
    });
    std::pair<double, int> farthest{-1.0, -1};
    for (const auto& best : block_best) {
      if (best.first > farthest.first) farthest = best;
    }
    if (farthest.second < 0) break;
    next = farthest.second;
  }
  std::vector<uint8_t> anchored(topology.component_count, 0);
  for (int32_t a : anchors) anchored[topology.component_of_vertex[a]] = 1;
  for (int v = 0; v < v_count; ++v) {
    const int c = topology.component_of_vertex[v];
    if (!anchored[c]) {
      anchored[c] = 1;
      anchors.push_back(v);
    }
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

// One way of coding a segment's operator and residuals, with what the decoder rebuilds the
// operator from besides the header. The dequantised residuals are not kept: the payload holds
// them, and the fallback decodes them again only while it measures this coding (a V×r matrix per
// coding would be the largest buffer of the encoder's peak).
struct SegmentCoding {
  format::SegmentHeader header;  // its operator and residual step
  std::vector<uint8_t> operator_payload;
  std::vector<uint8_t> residual_payload;
  std::vector<int64_t> edge_weights;  // ddl: the coded weights
  FramePositionsD reference_frame;    // geometric operators: the decoded reference frame
  // The fallback's measurement of it (STED of the sampled frames); NaN when not measured.
  double sted = std::numeric_limits<double>::quiet_NaN();

  size_t payload_bytes() const { return operator_payload.size() + residual_payload.size(); }
};

// Codes the residuals of the operator `target` names (its header, edge weights or reference
// frame) for the segment's coefficients: δ = L·C, quantised with target.header's step.
using WriteResidualsFn = std::function<StatusOr<std::vector<uint8_t>>(const SegmentSyntax&)>;

// Fitted DDL weights cost side information (about 10 bits per vertex per segment at 2^-7); on a
// short segment they may not pay for themselves. With options.ddl_dead_zone = 0 the encoder codes
// both the fitted weights (plain rounding) and the predicted weights alone (dead zone ∞: every
// residual 0, nearly free) with the residuals each implies, and keeps the smaller. At the same
// residual step the two reconstructions measured within 5 % STED of each other (samba 0.0233 vs
// 0.0245, crane 0.0371 vs 0.0369), so rate decides. (A Lagrangian cost with the coefficient error
// as distortion was tried and rejected: that error follows KG, not STED, and picked the predicted
// weights on samba, where the fitted ones win both rate and STED.) A fixed dead zone codes once.
// Only the smallest coding so far is kept (the first on ties).
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

// Rate–distortion slope used to compare codings at slightly different distortions: a coding
// whose STED is e^x times another's is worth kStedSlopeBits · x bits per frame and vertex. It is
// the slope of bpfv against ln STED measured on the encode ladders of samba, crane and
// horse-gallop between STED 0.02 and 0.05 (0.3–0.9; RD.md, session 4). Candidates reach STEDs
// within about 20 % of each other (their steps are matched, below), so the choice is not
// sensitive to its exact value.
constexpr double kStedSlopeBits = 0.5;

// Frames of a segment on which the fallback's candidates are measured: all up to this many, else
// every k-th. Decoding and measuring every frame of a long segment three times cost as much as the
// rest of the encode; the candidates are ranked the same way on the subsample (the temporal part
// of STED then compares frames k apart, for every candidate alike).
constexpr int kMeasuredFrames = 32;

// The fallback's measurement frames of a segment, taken before its trajectories are released.
struct MeasuredFrames {
  std::vector<int> frames;  // indices within the segment
  MeshSequence original;    // those frames of the input, in codec vertex order
};

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

// The fallback's other candidates for a segment whose ddl coding is done: kirchhoff, tutte and
// mean-value, in this order, each with its residuals coded (a candidate whose residuals cannot be
// coded, e.g. beyond the format's range at this step, is left out). Kirchhoff's rows sum to the
// vertex degree, not 1, so its δ are about mean degree times larger: its residual step is scaled
// by the mean degree to reach a comparable distortion. Mean-value's weights come from the
// segment's mean shape, coded as the reference frame at reference_step. Every candidate shares
// the ddl coding's mean, basis and anchors. This is the only step that needs the segment's
// coefficients: the caller releases them before the candidates are measured.
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

// The ddl operator's fallback. Fitted weights are side information (about 10 bits per vertex per
// segment) that only pays when the segment is long enough; the combinatorial operators need none
// and mean-value needs a coded reference frame. So the segment is also coded with the other
// candidates (CodeFallbackCandidates), each decoded as the decoder would and measured, and the
// coding with the lowest cost bits + kStedSlopeBits · V · F · ln STED is kept (the earlier on
// ties, so the DDL first). `shared` holds what every coding shares (mean, basis, anchors and
// their values); codings[0] is the DDL's. The residuals of one coding at a time are decoded from
// its payload, the decoder's own values, so only one candidate's deltas and factor exist at once.
// A coding that cannot be measured is not chosen; when the DDL's cannot, it is kept.
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

struct SegmentResult {
  format::ChunkSizes sizes;
  OperatorId operator_id = OperatorId::kDdl;  // what the segment was coded with
  int rank = 0;
  int anchors = 0;
};

// The automatic rank's candidates, as multiples of EncoderOptions::rank_threshold. Fewer
// components are often the better trade: on crane (16 frames) at 10 residual bits, rank 3
// instead of 4 gave 3 % fewer bits and a lower STED, since the fourth component's quantisation
// error outweighed what it captured. With EncoderOptions::rank_search the segment is coded at the
// rank of each threshold (distinct ranks only) and the cheapest coding is kept (RD.md,
// "Session 5").
constexpr double kRankThresholdScales[] = {1.0, 2.0, 4.0};
// Ranks are compared by bits · STED^kRankStedElasticity, lowest wins. The encode ladders of samba,
// crane and horse-gallop follow bits ∝ STED^-0.8 closely (the local slope of bpfv against ln STED
// is about 0.8 × bpfv, from 0.2 to 1.8 bpfv), so the product is constant along a ladder and a
// rank that lowers it lies below the ladder. The operator choice's fixed slope (kStedSlopeBits)
// under-weights STED at high rates: choosing ranks with it cost horse-gallop 2.9 % at STED 0.03.
constexpr double kRankStedElasticity = 0.8;

// Encodes one segment (its trajectories, in the codec's vertex order) into `out` in closed loop:
// every quantity after a quantiser uses the decoder's reconstruction of it. Each large buffer is
// released as soon as nothing after it needs it, so the segment's peak memory is the largest
// single step's, not the sum of the steps': the PCA's eigenvectors once the basis is coded, the
// trajectories once projected (the operator fit and the fallback's trials run without them), the
// fitted operator once its weights are coded, and the coefficients once every candidate's
// residuals are coded (the fallback measures the candidates from their payloads).
StatusOr<SegmentResult> EncodeSegment(SegmentTrajectories trajectories,
                                      const MeshTopology& topology, const Triangles& triangles,
                                      const std::vector<int32_t>& vertex_order,
                                      const EncoderOptions& options, OperatorId operator_id,
                                      double diagonal, double residual_step, int first_frame,
                                      ByteWriter& out) {
  const int v_count = static_cast<int>(trajectories.rows());
  const int frame_count = static_cast<int>(trajectories.cols() / 3);
  SegmentPca pca = ComputeSegmentPca(trajectories);
  format::SegmentHeader h;
  h.first_frame = static_cast<uint32_t>(first_frame);
  h.frame_count = static_cast<uint32_t>(frame_count);
  const int max_rank = std::min<int>(3 * frame_count, std::max(v_count - 1, 0));
  // The ranks to code the segment at, highest first (the plain threshold's): with an automatic
  // rank and the ddl operator's fallback, also the distinct lower ranks of the larger thresholds.
  const bool rank_search = options.rank == 0 && operator_id == OperatorId::kDdl &&
                           options.ddl_fallback && options.rank_search;
  std::vector<int> ranks;
  if (options.rank == 0) {
    for (const double scale : kRankThresholdScales) {
      const double threshold =
          scale * options.rank_threshold * v_count * residual_step * residual_step;
      int rank = 0;
      while (rank < max_rank && pca.eigenvalues[rank] > threshold) ++rank;
      if (ranks.empty() || (rank < ranks.back() && rank > 0)) ranks.push_back(rank);
      if (!rank_search) break;
    }
  } else {
    ranks.push_back(std::min(options.rank, max_rank));
  }
  const int top_rank = ranks.front();
  h.operator_id = static_cast<uint8_t>(operator_id);
  h.basis_bits = static_cast<uint8_t>(options.basis_bits);
  h.weight_bits = static_cast<uint8_t>(options.weight_bits);
  const auto mode = options.weight_prediction_uniform
                        ? format::WeightPrediction::kUniform
                        : format::WeightPrediction::kReferenceProportional;
  h.weight_prediction = static_cast<uint8_t>(mode);
  const int anchor_request =
      options.anchors >= 0 ? options.anchors
                           : std::clamp(static_cast<int>(std::lround(kAnchorFraction * v_count)), 1,
                                        kMaxAutomaticAnchors);
  h.mean_step = std::ldexp(diagonal, -kMeanStepBits);
  h.residual_step = residual_step;
  h.anchor_step = residual_step * options.anchor_step_ratio;
  h.anchor_weight = 1.0;

  std::vector<int32_t> anchors;
  Eigen::MatrixXd mean_shape = MeanShape(trajectories);
  if (top_rank > 0) anchors = ChooseAnchors(mean_shape, topology, anchor_request);
  if (anchors.empty()) anchors.push_back(0);
  h.anchor_count = static_cast<uint32_t>(anchors.size());

  // Mean and basis first: the coefficients are computed against their decoded values. A basis
  // column is quantised on its own, so a lower rank's decoded basis is the first columns of the
  // top rank's, and one projection serves every rank.
  SegmentSyntax syntax;
  syntax.header = h;
  syntax.header.rank = static_cast<uint32_t>(top_rank);
  const std::vector<uint8_t> mean_payload = syntax::WriteMean(pca.mean, h, &syntax.mean);
  std::vector<uint8_t> top_basis_payload =
      syntax::WriteBasis(pca.eigenvectors.leftCols(top_rank), syntax.header, &syntax.basis);
  Eigen::MatrixXd eigenvectors;  // kept only for the lower ranks' bases
  if (ranks.size() > 1) eigenvectors = pca.eigenvectors.leftCols(top_rank);
  pca = SegmentPca();         // its 3F × 3F eigenvectors
  Eigen::MatrixXd projected;  // V × top rank, kept only while a lower rank is still to be coded
  if (top_rank > 0) projected = ProjectTrajectories(trajectories, syntax.mean, syntax.basis);
  const bool fallback = top_rank > 0 && operator_id == OperatorId::kDdl && options.ddl_fallback;
  std::optional<MeasuredFrames> measured;
  if (fallback) measured = SampleMeasuredFrames(trajectories, triangles);
  trajectories = SegmentTrajectories();
  const Eigen::MatrixXd top_basis = syntax.basis;

  // The segment coded at one rank (the last use of the projection when next_rank is 0): everything
  // that depends on the rank, and bits · STED^kRankStedElasticity when the fallback measured it.
  struct RankCoding {
    format::SegmentHeader header;
    std::vector<uint8_t> basis_payload, anchor_payload, operator_payload, residual_payload;
    double cost = std::numeric_limits<double>::quiet_NaN();
  };
  auto code_at_rank = [&](int rank, int next_rank) -> StatusOr<RankCoding> {
    RankCoding coding;
    syntax.header = h;
    syntax.header.rank = static_cast<uint32_t>(rank);
    if (rank == top_rank) {
      coding.basis_payload = top_basis_payload;
      syntax.basis = top_basis;
    } else {
      coding.basis_payload =
          syntax::WriteBasis(eigenvectors.leftCols(rank), syntax.header, &syntax.basis);
    }
    Eigen::MatrixXd coefficients(v_count, 0);
    if (rank > 0) {
      // Solved as r × V, then transposed once the projection is released (after the last rank;
      // before it, cut to the next rank's columns): with one rank, two V × r buffers at a time,
      // not three (the same values as solving and transposing in one expression).
      const Eigen::MatrixXd gram = syntax.basis.transpose() * syntax.basis;
      Eigen::MatrixXd solved = gram.ldlt().solve(projected.leftCols(rank).transpose());
      if (next_rank == 0) {
        projected = Eigen::MatrixXd();
      } else {
        projected.conservativeResize(Eigen::NoChange, next_rank);
      }
      coefficients = solved.transpose();
    }
    // Anchors before the operator: the DDL trials below reconstruct with them.
    coding.anchor_payload =
        syntax::WriteAnchors(anchors, coefficients, syntax.header, &syntax.anchor_values);
    syntax.anchors = anchors;
    // The dequantised deltas are not kept (nullptr): nothing after the coding uses them but the
    // fallback's measurement, which decodes them from the payload.
    const WriteResidualsFn write_residuals =
        [&](const SegmentSyntax& target) -> StatusOr<std::vector<uint8_t>> {
      DMC_ASSIGN_OR_RETURN(const LaplaceOperator laplace, RebuildSegmentOperator(topology, target));
      const Eigen::MatrixXd delta = laplace.matrix * coefficients;
      return syntax::WriteResiduals(delta, topology, vertex_order, target.header, nullptr);
    };
    format::SegmentHeader& header = syntax.header;
    if (rank > 0 && operator_id == OperatorId::kDdl) {
      SegmentCoding ddl;
      {
        OperatorOptions operator_options;
        operator_options.ddl.mu = options.ddl_regularization;
        // The coefficients are lent to the fit's source, not copied (the fit's factorisation is
        // the encoder's peak), and taken back after it.
        OperatorSource source = SourceFromTrajectories(std::move(coefficients));
        StatusOr<LaplaceOperator> fit = FitDdlSymmetric(topology, source, operator_options);
        coefficients = std::move(*source.trajectories);
        DMC_ASSIGN_OR_RETURN(const LaplaceOperator fitted, std::move(fit));
        DMC_ASSIGN_OR_RETURN(ddl, ChooseDdlWeights(fitted.weights.values, topology, options, mode,
                                                   header, write_residuals));
      }
      if (fallback) {
        std::vector<SegmentCoding> codings;
        codings.push_back(std::move(ddl));
        for (SegmentCoding& candidate : CodeFallbackCandidates(
                 header, topology, mean_shape, std::ldexp(diagonal, -options.reference_bits),
                 write_residuals)) {
          codings.push_back(std::move(candidate));
        }
        coefficients = Eigen::MatrixXd();
        if (next_rank == 0) mean_shape = Eigen::MatrixXd();
        // The measurement takes the syntax (mean, basis, anchors) and gives nothing back.
        SegmentSyntax shared;
        shared.header = syntax.header;
        shared.mean = syntax.mean;
        shared.basis = syntax.basis;
        shared.anchors = syntax.anchors;
        shared.anchor_values = syntax.anchor_values;
        ddl = ChooseSegmentOperator(*measured, topology, vertex_order, std::move(shared),
                                    std::move(codings));
      }
      coding.header = ddl.header;
      coding.operator_payload = std::move(ddl.operator_payload);
      coding.residual_payload = std::move(ddl.residual_payload);
      const size_t bytes = mean_payload.size() + coding.basis_payload.size() +
                           coding.anchor_payload.size() + coding.operator_payload.size() +
                           coding.residual_payload.size();
      coding.cost = std::log(8.0 * static_cast<double>(bytes)) +
                    kRankStedElasticity * std::log(std::max(ddl.sted, 1e-300));
    } else {
      if (format::IsGeometricOperator(static_cast<uint8_t>(operator_id))) {
        // The reference frame is the segment's mean shape, coded so both sides build the same
        // geometric operator from it.
        coding.operator_payload = syntax::WriteReferenceFrame(
            mean_shape, topology, std::ldexp(diagonal, -options.reference_bits),
            &syntax.reference_frame);
      } else if (operator_id == OperatorId::kDdl) {
        // Rank 0: nothing to reconstruct; send the predicted weights (all residuals zero).
        const std::vector<double> unused(topology.edges.size(), 0.0);
        coding.operator_payload =
            syntax::WriteDdlWeights(unused, topology, options.weight_bits, mode,
                                    &syntax.edge_weights, std::numeric_limits<double>::infinity());
      }
      if (rank > 0) {
        DMC_ASSIGN_OR_RETURN(coding.residual_payload, write_residuals(syntax));
      }
      coding.header = header;
    }
    return coding;
  };

  // One rank at a time, keeping only the cheapest coding: the top rank's when the costs are not
  // measured, the higher rank on ties.
  auto next_rank = [&](size_t c) { return c + 1 < ranks.size() ? ranks[c + 1] : 0; };
  DMC_ASSIGN_OR_RETURN(RankCoding best, code_at_rank(top_rank, next_rank(0)));
  for (size_t c = 1; c < ranks.size(); ++c) {
    // A lower rank that cannot be coded is not chosen: the top rank's coding is complete.
    StatusOr<RankCoding> candidate = code_at_rank(ranks[c], next_rank(c));
    if (candidate.ok() && candidate->cost < best.cost) best = std::move(candidate).value();
  }
  h = best.header;

  SegmentResult result;
  result.rank = static_cast<int>(h.rank);
  result.anchors = static_cast<int>(anchors.size());
  result.operator_id = static_cast<OperatorId>(h.operator_id);
  auto append = [&](format::ChunkType type, const std::vector<uint8_t>& payload, uint64_t* size) {
    const size_t before = out.size();
    syntax::AppendChunk(out, type, payload);
    *size += out.size() - before;
  };
  append(format::ChunkType::kSegmentHeader, syntax::WriteSegmentHeader(h), &result.sizes.header);
  append(format::ChunkType::kMean, mean_payload, &result.sizes.mean);
  append(format::ChunkType::kBasis, best.basis_payload, &result.sizes.basis);
  append(format::ChunkType::kOperator, best.operator_payload, &result.sizes.operator_info);
  append(format::ChunkType::kAnchors, best.anchor_payload, &result.sizes.anchors);
  append(format::ChunkType::kResiduals, best.residual_payload, &result.sizes.residuals);
  return result;
}

// What every encode of a sequence derives from its shape, options and bounding box.
struct StreamPlan {
  OperatorId operator_id = OperatorId::kDdl;
  double diagonal = 0.0;
  double residual_step = 0.0;
  int frames = 0;
  // Equal-sized segments (differing by at most one frame): segment s holds frames
  // [segment_first[s], segment_first[s + 1]).
  std::vector<int> segment_first;
  int segments() const { return static_cast<int>(segment_first.size()) - 1; }
  int segment_frames(int s) const { return segment_first[s + 1] - segment_first[s]; }
};

StatusOr<StreamPlan> PlanStream(int frames, double diagonal, const EncoderOptions& options) {
  StreamPlan plan;
  DMC_ASSIGN_OR_RETURN(plan.operator_id, CodecOperatorId(options.operator_name));
  plan.diagonal = diagonal;
  plan.residual_step = options.residual_step > 0.0 ? options.residual_step
                                                   : std::ldexp(diagonal, -options.residual_bits);
  plan.frames = frames;
  const int segment_limit =
      options.segment_frames > 0 ? options.segment_frames : kDefaultSegmentFrames;
  const int segments = (frames + segment_limit - 1) / segment_limit;
  plan.segment_first.assign(segments + 1, 0);
  for (int s = 0; s < segments; ++s) {
    plan.segment_first[s + 1] =
        plan.segment_first[s] + frames / segments + (s < frames % segments ? 1 : 0);
  }
  return plan;
}

// Magic, version, the sequence header chunk and the connectivity chunk.
std::vector<uint8_t> StreamPrefix(int vertex_count, int triangle_count, const std::string& name,
                                  double frame_rate, const StreamPlan& plan,
                                  const ConnectivityCode& connectivity,
                                  format::ChunkSizes& totals) {
  ByteWriter out;
  for (uint8_t byte : format::kMagic) out.PutU8(byte);
  out.PutU8(format::kVersionMajor);
  out.PutU8(format::kVersionMinor);
  out.PutU8(0);  // reserved
  format::SequenceHeader header;
  header.vertex_count = static_cast<uint32_t>(vertex_count);
  header.triangle_count = static_cast<uint32_t>(triangle_count);
  header.frame_count = static_cast<uint32_t>(plan.frames);
  header.segment_count = static_cast<uint32_t>(plan.segments());
  header.frame_rate = frame_rate;
  header.name = name;
  if (!connectivity.vertex_order.empty()) header.flags |= format::kFlagReordered;
  syntax::AppendChunk(out, format::ChunkType::kSequenceHeader, syntax::WriteSequenceHeader(header));
  totals.header += out.size();  // includes magic and version
  const size_t before = out.size();
  syntax::AppendChunk(out, format::ChunkType::kConnectivity, connectivity.payload);
  totals.connectivity += out.size() - before;
  return out.Take();
}

// The end chunk: it counts the chunks before it (sequence header, connectivity, 6 per segment).
std::vector<uint8_t> StreamEnd(const StreamPlan& plan, format::ChunkSizes& totals) {
  ByteWriter count;
  count.PutVarU(static_cast<uint64_t>(2 + 6 * plan.segments()));
  ByteWriter out;
  syntax::AppendChunk(out, format::ChunkType::kEnd, count.bytes());
  totals.header += out.size();
  return out.Take();
}

// Adds segment `index` (segments in order) to the totals and the report: its sizes, its operator,
// and the rank and anchors rate control chose when it is the first.
void RecordSegment(const SegmentResult& segment, int index, format::ChunkSizes& totals,
                   EncodeReport* report) {
  if (report) {
    if (index == 0) {
      report->rank = segment.rank;
      report->anchors = segment.anchors;
      report->segment_operators.clear();
    }
    report->segment_operators.emplace_back(CodecOperatorName(segment.operator_id));
  }
  totals.header += segment.sizes.header;
  totals.mean += segment.sizes.mean;
  totals.basis += segment.sizes.basis;
  totals.operator_info += segment.sizes.operator_info;
  totals.anchors += segment.sizes.anchors;
  totals.residuals += segment.sizes.residuals;
}

// The report's rate fields (rank and anchors are the first segment's, set as it is added).
void FillRateReport(const StreamPlan& plan, int vertex_count, uint64_t bytes,
                    const format::ChunkSizes& totals, EncodeReport& report) {
  report.bytes = bytes;
  report.frames = plan.frames;
  report.vertices = vertex_count;
  report.bpfv =
      8.0 * static_cast<double>(bytes) / (static_cast<double>(plan.frames) * vertex_count);
  report.header_bytes = totals.header;
  report.connectivity_bytes = totals.connectivity;
  report.mean_bytes = totals.mean;
  report.basis_bytes = totals.basis;
  report.operator_bytes = totals.operator_info;
  report.anchor_bytes = totals.anchors;
  report.residual_bytes = totals.residuals;
  report.residual_step = plan.residual_step;
  report.residual_bits_equivalent =
      static_cast<int>(std::lround(std::log2(plan.diagonal / plan.residual_step)));
  report.segments = plan.segments();
}

StatusOr<std::vector<uint8_t>> EncodeOnce(const MeshSequence& sequence,
                                          const ConnectivityCode& connectivity,
                                          const MeshTopology& topology,
                                          const EncoderOptions& options, double diagonal,
                                          EncodeReport* report) {
  DMC_ASSIGN_OR_RETURN(const StreamPlan plan,
                       PlanStream(sequence.frame_count(), diagonal, options));
  format::ChunkSizes totals;
  ByteWriter out;
  out.PutBytes(StreamPrefix(sequence.vertex_count(), sequence.triangle_count(), sequence.name,
                            sequence.frame_rate, plan, connectivity, totals));

  const std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  // Segments encoded in parallel into their own buffers and concatenated in order: the bytes do
  // not depend on the thread count.
  const int segments = plan.segments();
  std::vector<ByteWriter> segment_bytes(segments);
  std::vector<StatusOr<SegmentResult>> segment_results(segments, InternalError("not encoded"));
  tbb::parallel_for(0, segments, [&](int s) {
    SegmentTrajectories trajectories = GatherTrajectories(
        sequence, plan.segment_first[s], plan.segment_frames(s), connectivity.vertex_order);
    segment_results[s] = EncodeSegment(std::move(trajectories), topology, connectivity.triangles,
                                       vertex_order, options, plan.operator_id, diagonal,
                                       plan.residual_step, plan.segment_first[s], segment_bytes[s]);
  });
  for (int s = 0; s < segments; ++s) {
    DMC_ASSIGN_OR_RETURN(SegmentResult segment, std::move(segment_results[s]));
    out.PutBytes(segment_bytes[s].bytes());
    RecordSegment(segment, s, totals, report);
  }
  out.PutBytes(StreamEnd(plan, totals));
  if (report) FillRateReport(plan, sequence.vertex_count(), out.size(), totals, *report);
  return out.Take();
}

// Decodes `bytes` with the real decoder and measures it against the input. A reordered stream is
// first mapped back to input vertex labels (output vertex i is input vertex relabel[i]).
Status Measure(const MeshSequence& sequence, const std::vector<uint8_t>& bytes,
               const std::vector<int32_t>& relabel, EncodeReport* report) {
  DMC_ASSIGN_OR_RETURN(MeshSequence decoded, Decode(bytes));
  if (!relabel.empty()) {
    MeshSequence restored(decoded.vertex_count(), decoded.triangles(), decoded.frame_count());
    for (Eigen::Index t = 0; t < restored.triangle_count(); ++t) {
      for (int k = 0; k < 3; ++k) {
        restored.mutable_triangles()(t, k) = relabel[decoded.triangles()(t, k)];
      }
    }
    for (int f = 0; f < decoded.frame_count(); ++f) {
      for (int v = 0; v < decoded.vertex_count(); ++v) {
        restored.frame(f).row(relabel[v]) = decoded.frame(f).row(v);
      }
    }
    decoded = std::move(restored);
  }
  DMC_ASSIGN_OR_RETURN(report->distortion, MeasureDistortion(sequence, decoded));
  report->measured = true;
  return Status::Ok();
}

Status CheckFormatLimits(int vertex_count, int frame_count) {
  if (static_cast<uint64_t>(frame_count) > format::kMaxFrames ||
      static_cast<uint64_t>(vertex_count) > format::kMaxVertices) {
    return UnsupportedError("sequence exceeds the format's limits");
  }
  return Status::Ok();
}

bool HasRateTarget(const EncoderOptions& options) {
  return options.target_bpfv > 0.0 || options.target_sted > 0.0;
}

bool MeetsRateTarget(const EncoderOptions& options, const EncodeReport& report) {
  return options.target_bpfv > 0.0 ? report.bpfv <= options.target_bpfv
                                   : report.distortion.sted <= options.target_sted;
}

// Rate control: bisection on the residual step, 2^-1 … 2^-24 of the diagonal, in 12 halvings of
// the interval in bits (rank follows the step automatically). Rate falls and distortion rises
// monotonically with the step. `trial` encodes with the options it is given (the targets cleared,
// residual_step set) and says whether the result meets the target. The search moves toward the
// finest step that meets a rate target and the coarsest that meets a distortion target, so the
// last trial that met it is the choice: `trial` keeps it. kInvalidArgument when none met it. The
// in-memory and the streaming encoder share it, so they choose the same step.
Status SearchResidualStep(const EncoderOptions& options, double diagonal,
                          const std::function<StatusOr<bool>(const EncoderOptions&)>& trial) {
  const bool prefer_finer = options.target_bpfv > 0.0;
  EncoderOptions trial_options = options;
  trial_options.target_bpfv = trial_options.target_sted = 0.0;
  double low = 1.0, high = 24.0;  // residual bits
  bool found = false;
  for (int iteration = 0; iteration < 12; ++iteration) {
    const double bits = 0.5 * (low + high);
    trial_options.residual_step = diagonal * std::pow(2.0, -bits);
    DMC_ASSIGN_OR_RETURN(const bool meets, trial(trial_options));
    found = found || meets;
    // Meeting a rate target: finer steps are better while they fit; meeting a distortion
    // target: coarser steps are better while they meet it.
    if (meets == prefer_finer) {
      low = bits;
    } else {
      high = bits;
    }
  }
  if (!found) {
    return InvalidArgumentError(prefer_finer ? "no parameters reach the target rate"
                                             : "no parameters reach the target distortion");
  }
  return Status::Ok();
}

// ---- Streaming ---------------------------------------------------------------------------------

// Frames per read of the scan, segment and measure passes: blocks of about 1 MiB (at least one
// frame). Larger blocks read no faster from a PC2 cache, and the block is held beside the
// segment's trajectories, so it counts toward the encoder's peak memory.
int FramesPerRead(int vertex_count, int frame_count) {
  constexpr size_t kReadBytes = size_t{1} << 20;
  const size_t frame_bytes = static_cast<size_t>(vertex_count) * 3 * sizeof(float);
  return static_cast<int>(
      std::clamp<size_t>(kReadBytes / frame_bytes, 1, static_cast<size_t>(frame_count)));
}

// Reads every frame of the source once, in blocks: checks finiteness, returns the bounding box,
// and gives each frame to `meter` (when not null) in order. `progress(frames done)` per block.
StatusOr<BoundingBox> ScanSource(FrameSource& source, StreamingDistortion* meter,
                                 const std::function<void(int)>& progress) {
  const int v_count = source.vertex_count(), frames = source.frame_count();
  const size_t per_frame = static_cast<size_t>(v_count) * 3;
  BoundingBox box;
  box.min.setConstant(std::numeric_limits<double>::infinity());
  box.max.setConstant(-std::numeric_limits<double>::infinity());
  const int frames_per_read = FramesPerRead(v_count, frames);
  std::vector<float> block(per_frame * static_cast<size_t>(frames_per_read));
  for (int done = 0; done < frames; done += frames_per_read) {
    const int count = std::min(frames_per_read, frames - done);
    DMC_RETURN_IF_ERROR(source.ReadFrames(done, count, block.data()));
    DMC_RETURN_IF_ERROR(CheckFiniteFrames(block.data(), done, count, v_count));
    for (int f = 0; f < count; ++f) {
      const float* data = block.data() + per_frame * static_cast<size_t>(f);
      const Eigen::Map<const FramePositions> positions(data, v_count, 3);
      box.min = box.min.cwiseMin(positions.colwise().minCoeff().cast<double>().transpose());
      box.max = box.max.cwiseMax(positions.colwise().maxCoeff().cast<double>().transpose());
      if (meter) meter->AddOriginalFrame(data);
    }
    progress(done + count);
  }
  return box;
}

// One segment travelling through the streaming encoder's pipeline.
struct SegmentWork {
  int index = 0;
  Status read = Status::Ok();
  SegmentTrajectories trajectories;
  ByteWriter bytes;
  StatusOr<SegmentResult> result = InternalError("not encoded");
};

// Reads frames [first, first + count) of the source, in blocks, into a segment's trajectories.
// The read block lives only as long as the read: kept across segments it would sit beside the
// encode stage's buffers at their peak.
Status ReadSegmentTrajectories(FrameSource& source, int first, int count,
                               const std::vector<int32_t>& relabel,
                               SegmentTrajectories& trajectories) {
  const int v_count = source.vertex_count();
  const size_t per_frame = static_cast<size_t>(v_count) * 3;
  const int frames_per_read = FramesPerRead(v_count, count);
  trajectories.resize(v_count, 3 * static_cast<Eigen::Index>(count));
  std::vector<float> block(per_frame * static_cast<size_t>(frames_per_read));
  for (int done = 0; done < count; done += frames_per_read) {
    const int frames = std::min(frames_per_read, count - done);
    DMC_RETURN_IF_ERROR(source.ReadFrames(first + done, frames, block.data()));
    for (int f = 0; f < frames; ++f) {
      StoreFrame(block.data() + per_frame * static_cast<size_t>(f), done + f, relabel,
                 trajectories);
    }
  }
  return Status::Ok();
}

}  // namespace

StatusOr<std::vector<uint8_t>> Encode(const MeshSequence& sequence, const EncoderOptions& options,
                                      EncodeReport* report) {
  const auto start = std::chrono::steady_clock::now();
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_RETURN_IF_ERROR(ValidateOptions(options));
  DMC_RETURN_IF_ERROR(CheckFormatLimits(sequence.vertex_count(), sequence.frame_count()));
  // Connectivity first: the rest of the stream uses the decoder's vertex labels and topology.
  DMC_ASSIGN_OR_RETURN(
      const ConnectivityCode connectivity,
      EncodeConnectivity(sequence.triangles(), sequence.vertex_count(), options.allow_reorder));
  const MeshTopology topology = BuildTopology(connectivity.triangles, sequence.vertex_count());
  const double diagonal = std::max(ComputeBoundingBox(sequence).diagonal(), 1e-12);
  EncodeReport local;
  EncodeReport& out = report ? *report : local;
  out = EncodeReport();

  std::vector<uint8_t> bytes;
  if (HasRateTarget(options)) {
    std::vector<uint8_t> best;
    EncodeReport best_report;
    DMC_RETURN_IF_ERROR(SearchResidualStep(
        options, diagonal, [&](const EncoderOptions& trial_options) -> StatusOr<bool> {
          EncodeReport trial;
          DMC_ASSIGN_OR_RETURN(
              std::vector<uint8_t> candidate,
              EncodeOnce(sequence, connectivity, topology, trial_options, diagonal, &trial));
          if (options.target_sted > 0.0) {
            DMC_RETURN_IF_ERROR(Measure(sequence, candidate, connectivity.vertex_order, &trial));
          }
          const bool meets = MeetsRateTarget(options, trial);
          if (meets) {
            best = std::move(candidate);
            best_report = trial;
          }
          return meets;
        }));
    bytes = std::move(best);
    out = best_report;
  } else {
    DMC_ASSIGN_OR_RETURN(bytes,
                         EncodeOnce(sequence, connectivity, topology, options, diagonal, &out));
  }
  if (options.measure && !out.measured)
    DMC_RETURN_IF_ERROR(Measure(sequence, bytes, connectivity.vertex_order, &out));
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bytes;
}

Status EncodeToFile(const MeshSequence& sequence, const std::filesystem::path& output,
                    const EncoderOptions& options, EncodeReport* report) {
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, Encode(sequence, options, report));
  return WriteFileAtomically(output, bytes);
}

Status SequenceFrameSource::ReadFrames(int first, int count, float* out) {
  if (first < 0 || count < 0 || first > sequence_.frame_count() - count) {
    return InvalidArgumentError("frames [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") are outside the sequence's " +
                                std::to_string(sequence_.frame_count()) + " frames");
  }
  if (count > 0) {
    const size_t per_frame = static_cast<size_t>(sequence_.vertex_count()) * 3;
    std::copy_n(sequence_.frame(first).data(), per_frame * static_cast<size_t>(count), out);
  }
  return Status::Ok();
}

std::string_view EncodeStageName(EncodeStage stage) {
  switch (stage) {
    case EncodeStage::kScan:
      return "scanning";
    case EncodeStage::kEncode:
      return "encoding";
    case EncodeStage::kMeasure:
      return "measuring";
  }
  return "?";
}

namespace {

// Rate control while streaming, for a source with vertices and frames within the format's limits:
// each trial of SearchResidualStep is a whole streaming encode into
// a scratch file beside the output (measured only for a distortion target), so memory stays one
// segment's while the source is read about 14 times; the chosen step is then encoded to `output`
// with the caller's options. The bytes are those of Encode() with the same target.
Status EncodeStreamingWithRateSearch(FrameSource& source, const std::filesystem::path& output,
                                     const EncoderOptions& options, EncodeReport* report,
                                     const StreamingEncodeOptions& streaming,
                                     std::chrono::steady_clock::time_point start) {
  DMC_ASSIGN_OR_RETURN(const BoundingBox box, ScanSource(source, nullptr, [&](int done) {
                         if (streaming.progress) {
                           streaming.progress(EncodeStage::kScan, done, source.frame_count());
                         }
                       }));
  const double diagonal = std::max(box.diagonal(), 1e-12);
  // A hidden name beside the output: ".<name>.rate-trial".
  std::filesystem::path scratch_name = ".";
  scratch_name += output.filename();
  scratch_name += ".rate-trial";
  const std::filesystem::path scratch = output.parent_path() / scratch_name;
  double chosen_step = 0.0;
  const Status searched = SearchResidualStep(
      options, diagonal, [&](const EncoderOptions& trial_options) -> StatusOr<bool> {
        EncoderOptions trial = trial_options;
        trial.measure = options.target_sted > 0.0;
        EncodeReport trial_report;
        DMC_RETURN_IF_ERROR(EncodeStreaming(source, scratch, trial, &trial_report, streaming));
        const bool meets = MeetsRateTarget(options, trial_report);
        if (meets) chosen_step = trial.residual_step;
        return meets;
      });
  std::error_code ignored;
  std::filesystem::remove(scratch, ignored);
  DMC_RETURN_IF_ERROR(searched);
  EncoderOptions final_options = options;
  final_options.target_bpfv = final_options.target_sted = 0.0;
  final_options.residual_step = chosen_step;
  DMC_RETURN_IF_ERROR(EncodeStreaming(source, output, final_options, report, streaming));
  if (report) {
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return Status::Ok();
}

}  // namespace

Status EncodeStreaming(FrameSource& source, const std::filesystem::path& output,
                       const EncoderOptions& options, EncodeReport* report,
                       const StreamingEncodeOptions& streaming) {
  const auto start = std::chrono::steady_clock::now();
  DMC_RETURN_IF_ERROR(ValidateOptions(options));
  if (streaming.segments_in_flight < 1) {
    return InvalidArgumentError("segments in flight must be >= 1");
  }
  const int v_count = source.vertex_count();
  const int frames = source.frame_count();
  const Triangles& triangles = source.triangles();
  auto progress = [&](EncodeStage stage, int done) {
    if (streaming.progress) streaming.progress(stage, done, frames);
  };

  // The checks ValidateSequence makes, on frame 0 here (counts, triangle indices) and on every
  // frame's values during the scan.
  if (v_count <= 0 || frames <= 0) {
    return InvalidSequenceError(v_count <= 0 ? "the sequence has no vertices"
                                             : "the sequence has no frames");
  }
  DMC_RETURN_IF_ERROR(CheckFormatLimits(v_count, frames));
  // Rate control runs whole streaming encodes (which make the checks below) per trial.
  if (HasRateTarget(options)) {
    return EncodeStreamingWithRateSearch(source, output, options, report, streaming, start);
  }
  const size_t per_frame = static_cast<size_t>(v_count) * 3;
  std::vector<float> frame0(per_frame);
  DMC_RETURN_IF_ERROR(source.ReadFrames(0, 1, frame0.data()));
  {
    MeshSequence first(v_count, triangles, 1);
    std::copy(frame0.begin(), frame0.end(), first.data());
    DMC_RETURN_IF_ERROR(ValidateSequence(first));
  }
  DMC_ASSIGN_OR_RETURN(const ConnectivityCode connectivity,
                       EncodeConnectivity(triangles, v_count, options.allow_reorder));
  // Created before the long passes so that an unwritable output fails at once.
  DMC_ASSIGN_OR_RETURN(io_internal::StagedFile file, io_internal::StagedFile::Create(output));

  // Scan: the bounding box (the residual step derives from its diagonal), finiteness, and the
  // original-only terms of the metrics.
  std::optional<StreamingDistortion> meter;
  if (options.measure) {
    DMC_ASSIGN_OR_RETURN(meter,
                         StreamingDistortion::Create(triangles, v_count, frames, frame0.data()));
  }
  frame0 = {};
  DMC_ASSIGN_OR_RETURN(const BoundingBox box,
                       ScanSource(source, meter ? &*meter : nullptr,
                                  [&](int done) { progress(EncodeStage::kScan, done); }));
  if (meter) DMC_RETURN_IF_ERROR(meter->FinishOriginal());

  const double diagonal = std::max(box.diagonal(), 1e-12);
  DMC_ASSIGN_OR_RETURN(const StreamPlan plan, PlanStream(frames, diagonal, options));
  // Released after the segments are coded: the measurement's decoder builds its own.
  MeshTopology topology = BuildTopology(connectivity.triangles, v_count);
  std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  EncodeReport local;
  EncodeReport& out = report ? *report : local;
  out = EncodeReport();

  // The measurement decodes the finished stream, so keep a copy when measuring (it is the
  // compressed size, a small fraction of the input).
  std::vector<uint8_t> stream;
  format::ChunkSizes totals;
  auto write = [&](std::span<const uint8_t> bytes) -> Status {
    if (options.measure) stream.insert(stream.end(), bytes.begin(), bytes.end());
    return file.Append(bytes);
  };
  DMC_RETURN_IF_ERROR(write(StreamPrefix(v_count, static_cast<int>(triangles.rows()), source.name(),
                                         source.frame_rate(), plan, connectivity, totals)));

  // Segments through a pipeline: read (serial, in order) -> encode (parallel, at most
  // segments_in_flight at once) -> write (serial, in order).
  Status failure = Status::Ok();
  std::atomic<bool> failed{false};
  int next_segment = 0;
  tbb::parallel_pipeline(
      static_cast<size_t>(streaming.segments_in_flight),
      tbb::make_filter<void, std::shared_ptr<SegmentWork>>(
          tbb::filter_mode::serial_in_order,
          [&](tbb::flow_control& control) -> std::shared_ptr<SegmentWork> {
            if (failed.load() || next_segment == plan.segments()) {
              control.stop();
              return nullptr;
            }
            auto work = std::make_shared<SegmentWork>();
            work->index = next_segment++;
            work->read = ReadSegmentTrajectories(source, plan.segment_first[work->index],
                                                 plan.segment_frames(work->index),
                                                 connectivity.vertex_order, work->trajectories);
            return work;
          }) &
          tbb::make_filter<std::shared_ptr<SegmentWork>, std::shared_ptr<SegmentWork>>(
              tbb::filter_mode::parallel,
              [&](std::shared_ptr<SegmentWork> work) {
                if (!work->read.ok()) {
                  work->result = work->read;
                } else if (!failed.load()) {
                  work->result = EncodeSegment(std::move(work->trajectories), topology,
                                               connectivity.triangles, vertex_order, options,
                                               plan.operator_id, diagonal, plan.residual_step,
                                               plan.segment_first[work->index], work->bytes);
                }
                work->trajectories = SegmentTrajectories();  // free before the write stage
                return work;
              }) &
          tbb::make_filter<std::shared_ptr<SegmentWork>, void>(
              tbb::filter_mode::serial_in_order, [&](std::shared_ptr<SegmentWork> work) {
                if (failed.load()) return;
                Status status = work->result.status();
                if (status.ok()) status = write(work->bytes.bytes());
                if (!status.ok()) {
                  failure = status;
                  failed.store(true);
                  return;
                }
                RecordSegment(*work->result, work->index, totals, &out);
                progress(EncodeStage::kEncode, plan.segment_first[work->index + 1]);
              }));
  DMC_RETURN_IF_ERROR(failure);
  topology = MeshTopology();
  vertex_order = {};
  DMC_RETURN_IF_ERROR(write(StreamEnd(plan, totals)));
  FillRateReport(plan, v_count, file.size(), totals, out);

  if (meter) {
    // Decode each segment with the real decoder, back in input vertex labels, and compare it with
    // the input frames it needs (the segment and the STED speed window around it).
    Decoder decoder;
    DMC_RETURN_IF_ERROR(decoder.Open(stream).WithContext("decoding the encoded stream"));
    const std::vector<int32_t>& relabel = connectivity.vertex_order;
    std::vector<float> decoded, frame_copy, original;
    const int frames_per_read = FramesPerRead(v_count, plan.frames);
    for (int s = 0; s < plan.segments(); ++s) {
      const int first = plan.segment_first[s], count = plan.segment_frames(s);
      DMC_RETURN_IF_ERROR(decoder.DecodeSegmentInto(s, [&](int) -> StatusOr<float*> {
        decoded.resize(per_frame * static_cast<size_t>(count));
        return decoded.data();
      }));
      if (!relabel.empty()) {
        // Back to input labels in place, one frame at a time through a copy of that frame: a
        // second segment-sized buffer would be the measurement's largest.
        frame_copy.resize(per_frame);
        for (size_t f = 0; f < static_cast<size_t>(count); ++f) {
          float* frame = decoded.data() + f * per_frame;
          std::copy_n(frame, per_frame, frame_copy.data());
          for (int v = 0; v < v_count; ++v) {
            std::copy_n(frame_copy.data() + 3 * static_cast<size_t>(v), 3,
                        frame + 3 * static_cast<size_t>(relabel[v]));
          }
        }
      }
      // The meter takes any consecutive frame ranges: the segment goes in read-sized blocks, so
      // the original frames in memory are one block and its speed window, not a whole segment.
      for (int block = first; block < first + count; block += frames_per_read) {
        const int block_count = std::min(frames_per_read, first + count - block);
        const auto [window_first, window_end] = meter->OriginalWindow(block, block_count);
        original.resize(per_frame * static_cast<size_t>(window_end - window_first));
        DMC_RETURN_IF_ERROR(
            source.ReadFrames(window_first, window_end - window_first, original.data()));
        DMC_RETURN_IF_ERROR(
            meter->AddSegment(block, block_count, original.data(),
                              decoded.data() + per_frame * static_cast<size_t>(block - first)));
      }
      progress(EncodeStage::kMeasure, first + count);
    }
    DMC_ASSIGN_OR_RETURN(out.distortion, meter->Report());
    out.measured = true;
  }
  DMC_RETURN_IF_ERROR(file.Commit());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace dmc
