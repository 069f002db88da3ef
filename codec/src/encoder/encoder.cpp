#include "dmc/encoder.h"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/segment_reconstruction.h"
#include "dmc/decoder.h"
#include "dmc/io.h"
#include "dmc/operators.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/segment_pca.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

// Defaults chosen by measurement (see the README's rate-distortion notes).
constexpr int kDefaultSegmentFrames = 256;
constexpr int kMeanStepBits = 18;         // mean trajectory step = diagonal · 2^-18
constexpr double kAnchorFraction = 0.01;  // automatic anchor count = 1 % of the vertices,
// at most 1000 (the 1 % rule at 100k vertices): farthest-point sampling costs O(V · anchors), so
// the cap keeps it linear in V beyond that.
constexpr int kMaxAutomaticAnchors = 1000;

struct CodecOperator {
  std::string_view name;
  OperatorId id;
};
constexpr CodecOperator kCodecOperators[] = {{"ddl", OperatorId::kDdl},
                                             {"tutte", OperatorId::kTutte},
                                             {"kirchhoff", OperatorId::kKirchhoff},
                                             {"cotan", OperatorId::kCotan},
                                             {"cotan-area", OperatorId::kCotanArea},
                                             {"cotan-sym", OperatorId::kCotanSym},
                                             {"mean-value", OperatorId::kMeanValue}};

StatusOr<OperatorId> CodecOperatorId(std::string_view name) {
  for (const auto& op : kCodecOperators) {
    if (op.name == name) return op.id;
  }
  std::string names;
  for (const auto& op : kCodecOperators)
    names += (names.empty() ? "" : ", ") + std::string(op.name);
  if (FindOperator(name).ok()) {
    return UnsupportedError("operator '" + std::string(name) +
                            "' cannot be used by the codec (codec operators: " + names + ")");
  }
  return NotFoundError("unknown operator '" + std::string(name) + "' (codec operators: " + names +
                       ")");
}

Status ValidateOptions(const EncoderOptions& o) {
  auto bad = [](const std::string& what) { return InvalidArgumentError(what); };
  if (o.rank < 0 || o.rank > static_cast<int>(format::kMaxRank)) {
    return bad("--rank must be in [0, " + std::to_string(format::kMaxRank) + "], got " +
               std::to_string(o.rank));
  }
  if (o.basis_bits < 2 || o.basis_bits > 16) {
    return bad("--basis-bits must be in [2, 16], got " + std::to_string(o.basis_bits));
  }
  if (o.residual_bits < 1 || o.residual_bits > 30) {
    return bad("--residual-bits must be in [1, 30], got " + std::to_string(o.residual_bits));
  }
  if (!std::isfinite(o.residual_step) || o.residual_step < 0.0) {
    return bad("--residual-step must be a finite value >= 0");
  }
  if (!std::isfinite(o.rank_threshold) || o.rank_threshold <= 0.0) {
    return bad("--rank-threshold must be positive");
  }
  if (o.anchors < -1) return bad("--anchors must be >= 1, or -1 for automatic");
  if (!std::isfinite(o.anchor_step_ratio) || o.anchor_step_ratio <= 0.0) {
    return bad("anchor step ratio must be positive");
  }
  if (o.segment_frames < 0 || o.segment_frames > static_cast<int>(format::kMaxSegmentFrames)) {
    return bad("--segment-frames must be in [0, " + std::to_string(format::kMaxSegmentFrames) +
               "]");
  }
  if (o.reference_bits < 4 || o.reference_bits > 30) {
    return bad("--reference-bits must be in [4, 30], got " + std::to_string(o.reference_bits));
  }
  if (o.weight_bits < 2 || o.weight_bits > 20) {
    return bad("--weight-bits must be in [2, 20], got " + std::to_string(o.weight_bits));
  }
  if (!(o.ddl_dead_zone == 0.0 || o.ddl_dead_zone >= 0.5)) {
    return bad("--ddl-dead-zone must be 0 (automatic) or >= 0.5");
  }
  if (!std::isfinite(o.ddl_regularization) || o.ddl_regularization < 0.0) {
    return bad("--ddl-mu must be >= 0");
  }
  if (!std::isfinite(o.target_bpfv) || o.target_bpfv < 0.0 || !std::isfinite(o.target_sted) ||
      o.target_sted < 0.0) {
    return bad("targets must be finite and >= 0");
  }
  if (o.target_bpfv > 0.0 && o.target_sted > 0.0) {
    return bad("give --target-bpfv or --target-sted, not both");
  }
  return CodecOperatorId(o.operator_name).status();
}

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

struct DdlChoice {
  std::vector<uint8_t> operator_payload;
  std::vector<uint8_t> residual_payload;
  std::vector<int64_t> edge_weights;
};

// Fitted DDL weights cost side information (about 10 bits per vertex per segment at 2^-7); on a
// short segment they may not pay for themselves. With options.ddl_dead_zone = 0 the encoder codes
// both the fitted weights (plain rounding) and the predicted weights alone (dead zone ∞: every
// residual 0, nearly free) with the residuals each implies, and keeps the smaller. At the same
// residual step the two reconstructions measured within 5 % STED of each other (samba 0.0233 vs
// 0.0245, crane 0.0371 vs 0.0369), so rate decides. (A Lagrangian cost with the coefficient error
// as distortion was tried and rejected: that error follows KG, not STED, and picked the predicted
// weights on samba, where the fitted ones win both rate and STED.) A fixed dead zone codes once.
template <typename WriteResidualsFn>
StatusOr<DdlChoice> ChooseDdlWeights(const std::vector<double>& fitted,
                                     const MeshTopology& topology, const EncoderOptions& options,
                                     format::WeightPrediction mode, const SegmentSyntax& syntax,
                                     WriteResidualsFn write_residuals) {
  std::vector<double> dead_zones = {options.ddl_dead_zone};
  if (options.ddl_dead_zone == 0.0) dead_zones = {0.5, std::numeric_limits<double>::infinity()};
  std::vector<DdlChoice> trials;
  for (double dead_zone : dead_zones) {
    SegmentSyntax trial = syntax;
    DdlChoice choice;
    choice.operator_payload = syntax::WriteDdlWeights(fitted, topology, options.weight_bits, mode,
                                                      &trial.edge_weights, dead_zone);
    DMC_ASSIGN_OR_RETURN(choice.residual_payload, write_residuals(trial));
    choice.edge_weights = std::move(trial.edge_weights);
    trials.push_back(std::move(choice));
  }
  auto bytes = [&](size_t t) {
    return trials[t].operator_payload.size() + trials[t].residual_payload.size();
  };
  size_t best = 0;
  for (size_t t = 1; t < trials.size(); ++t) {
    if (bytes(t) < bytes(best)) best = t;
  }
  return std::move(trials[best]);
}

struct SegmentResult {
  format::ChunkSizes sizes;
  int rank = 0;
  int anchors = 0;
};

// Encodes one segment into `out` in closed loop: every quantity after a quantiser uses the
// decoder's reconstruction of it.
StatusOr<SegmentResult> EncodeSegment(const MeshSequence& sequence, const MeshTopology& topology,
                                      const std::vector<int32_t>& vertex_order,
                                      const std::vector<int32_t>& relabel,
                                      const EncoderOptions& options, OperatorId operator_id,
                                      double diagonal, double residual_step, int first_frame,
                                      int frame_count, ByteWriter& out) {
  const int v_count = sequence.vertex_count();
  const SegmentTrajectories trajectories =
      GatherTrajectories(sequence, first_frame, frame_count, relabel);
  const SegmentPca pca = ComputeSegmentPca(trajectories);

  SegmentSyntax syntax;
  format::SegmentHeader& h = syntax.header;
  h.first_frame = static_cast<uint32_t>(first_frame);
  h.frame_count = static_cast<uint32_t>(frame_count);
  const int max_rank = std::min<int>(3 * frame_count, std::max(v_count - 1, 0));
  int rank = options.rank;
  if (rank == 0) {
    const double threshold = options.rank_threshold * v_count * residual_step * residual_step;
    while (rank < max_rank && pca.eigenvalues[rank] > threshold) ++rank;
  }
  rank = std::min(rank, max_rank);
  h.rank = static_cast<uint32_t>(rank);
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
  const Eigen::MatrixXd mean_shape = MeanShape(trajectories);
  if (rank > 0) anchors = ChooseAnchors(mean_shape, topology, anchor_request);
  if (anchors.empty()) anchors.push_back(0);
  h.anchor_count = static_cast<uint32_t>(anchors.size());

  // Mean and basis first: the coefficients are computed against their decoded values.
  const std::vector<uint8_t> mean_payload = syntax::WriteMean(pca.mean, h, &syntax.mean);
  const std::vector<uint8_t> basis_payload =
      syntax::WriteBasis(pca.eigenvectors.leftCols(rank), h, &syntax.basis);
  Eigen::MatrixXd coefficients(v_count, rank);
  if (rank > 0) {
    const Eigen::MatrixXd projected = ProjectTrajectories(trajectories, syntax.mean, syntax.basis);
    const Eigen::MatrixXd gram = syntax.basis.transpose() * syntax.basis;
    coefficients = gram.ldlt().solve(projected.transpose()).transpose();
  }

  // Anchors before the operator: the DDL trials below reconstruct with them.
  const std::vector<uint8_t> anchor_payload =
      syntax::WriteAnchors(anchors, coefficients, h, &syntax.anchor_values);
  syntax.anchors = anchors;
  std::vector<uint8_t> operator_payload;
  std::vector<uint8_t> residual_payload;
  auto write_residuals = [&](SegmentSyntax& target) -> StatusOr<std::vector<uint8_t>> {
    DMC_ASSIGN_OR_RETURN(LaplaceOperator laplace, RebuildSegmentOperator(topology, target));
    const Eigen::MatrixXd delta = laplace.matrix * coefficients;
    return syntax::WriteResiduals(delta, topology, vertex_order, h, &target.delta);
  };
  if (rank > 0 && operator_id == OperatorId::kDdl) {
    OperatorOptions operator_options;
    operator_options.ddl.mu = options.ddl_regularization;
    DMC_ASSIGN_OR_RETURN(
        LaplaceOperator fitted,
        FitDdlSymmetric(topology, SourceFromTrajectories(coefficients), operator_options));
    DMC_ASSIGN_OR_RETURN(
        DdlChoice choice,
        ChooseDdlWeights(fitted.weights.values, topology, options, mode, syntax, write_residuals));
    operator_payload = std::move(choice.operator_payload);
    residual_payload = std::move(choice.residual_payload);
    syntax.edge_weights = std::move(choice.edge_weights);
  } else {
    if (format::IsGeometricOperator(static_cast<uint8_t>(operator_id))) {
      // The reference frame is the segment's mean shape, coded so both sides build the same
      // geometric operator from it.
      operator_payload = syntax::WriteReferenceFrame(mean_shape, topology,
                                                     std::ldexp(diagonal, -options.reference_bits),
                                                     &syntax.reference_frame);
    } else if (operator_id == OperatorId::kDdl) {
      // Rank 0: nothing to reconstruct; send the predicted weights (all residuals zero).
      const std::vector<double> unused(topology.edges.size(), 0.0);
      operator_payload =
          syntax::WriteDdlWeights(unused, topology, options.weight_bits, mode, &syntax.edge_weights,
                                  std::numeric_limits<double>::infinity());
    }
    if (rank > 0) {
      DMC_ASSIGN_OR_RETURN(residual_payload, write_residuals(syntax));
    }
  }

  SegmentResult result;
  result.rank = rank;
  result.anchors = static_cast<int>(anchors.size());
  auto append = [&](format::ChunkType type, const std::vector<uint8_t>& payload, uint64_t* size) {
    const size_t before = out.size();
    syntax::AppendChunk(out, type, payload);
    *size += out.size() - before;
  };
  append(format::ChunkType::kSegmentHeader, syntax::WriteSegmentHeader(h), &result.sizes.header);
  append(format::ChunkType::kMean, mean_payload, &result.sizes.mean);
  append(format::ChunkType::kBasis, basis_payload, &result.sizes.basis);
  append(format::ChunkType::kOperator, operator_payload, &result.sizes.operator_info);
  append(format::ChunkType::kAnchors, anchor_payload, &result.sizes.anchors);
  append(format::ChunkType::kResiduals, residual_payload, &result.sizes.residuals);
  return result;
}

StatusOr<std::vector<uint8_t>> EncodeOnce(const MeshSequence& sequence,
                                          const ConnectivityCode& connectivity,
                                          const MeshTopology& topology,
                                          const EncoderOptions& options, double diagonal,
                                          EncodeReport* report) {
  DMC_ASSIGN_OR_RETURN(const OperatorId operator_id, CodecOperatorId(options.operator_name));
  const double residual_step = options.residual_step > 0.0
                                   ? options.residual_step
                                   : std::ldexp(diagonal, -options.residual_bits);
  const int frames = sequence.frame_count();
  const int segment_limit =
      options.segment_frames > 0 ? options.segment_frames : kDefaultSegmentFrames;
  const int segments = (frames + segment_limit - 1) / segment_limit;

  ByteWriter out;
  for (uint8_t byte : format::kMagic) out.PutU8(byte);
  out.PutU8(format::kVersionMajor);
  out.PutU8(format::kVersionMinor);
  out.PutU8(0);  // reserved
  format::SequenceHeader header;
  header.vertex_count = static_cast<uint32_t>(sequence.vertex_count());
  header.triangle_count = static_cast<uint32_t>(sequence.triangle_count());
  header.frame_count = static_cast<uint32_t>(frames);
  header.segment_count = static_cast<uint32_t>(segments);
  header.frame_rate = sequence.frame_rate;
  header.name = sequence.name;
  if (!connectivity.vertex_order.empty()) header.flags |= format::kFlagReordered;
  format::ChunkSizes totals;
  size_t before = out.size();
  syntax::AppendChunk(out, format::ChunkType::kSequenceHeader, syntax::WriteSequenceHeader(header));
  totals.header += out.size();  // includes magic and version
  before = out.size();
  syntax::AppendChunk(out, format::ChunkType::kConnectivity, connectivity.payload);
  totals.connectivity += out.size() - before;

  const std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  // Equal-sized segments (differing by at most one frame), encoded in parallel into their own
  // buffers and concatenated in order: the bytes do not depend on the thread count.
  std::vector<int> segment_first(segments + 1, 0);
  for (int s = 0; s < segments; ++s) {
    segment_first[s + 1] = segment_first[s] + frames / segments + (s < frames % segments ? 1 : 0);
  }
  std::vector<ByteWriter> segment_bytes(segments);
  std::vector<StatusOr<SegmentResult>> segment_results(segments, InternalError("not encoded"));
  tbb::parallel_for(0, segments, [&](int s) {
    segment_results[s] = EncodeSegment(
        sequence, topology, vertex_order, connectivity.vertex_order, options, operator_id, diagonal,
        residual_step, segment_first[s], segment_first[s + 1] - segment_first[s], segment_bytes[s]);
  });
  int chunk_count = 2;
  for (int s = 0; s < segments; ++s) {
    DMC_ASSIGN_OR_RETURN(SegmentResult segment, std::move(segment_results[s]));
    out.PutBytes(segment_bytes[s].bytes());
    totals.header += segment.sizes.header;
    totals.mean += segment.sizes.mean;
    totals.basis += segment.sizes.basis;
    totals.operator_info += segment.sizes.operator_info;
    totals.anchors += segment.sizes.anchors;
    totals.residuals += segment.sizes.residuals;
    if (s == 0 && report) {
      report->rank = segment.rank;
      report->anchors = segment.anchors;
    }
    chunk_count += 6;
  }
  ByteWriter end;
  end.PutVarU(static_cast<uint64_t>(chunk_count));
  before = out.size();
  syntax::AppendChunk(out, format::ChunkType::kEnd, end.bytes());
  totals.header += out.size() - before;

  if (report) {
    report->bytes = out.size();
    report->frames = frames;
    report->vertices = sequence.vertex_count();
    report->bpfv = 8.0 * static_cast<double>(out.size()) /
                   (static_cast<double>(frames) * sequence.vertex_count());
    report->header_bytes = totals.header;
    report->connectivity_bytes = totals.connectivity;
    report->mean_bytes = totals.mean;
    report->basis_bytes = totals.basis;
    report->operator_bytes = totals.operator_info;
    report->anchor_bytes = totals.anchors;
    report->residual_bytes = totals.residuals;
    report->residual_step = residual_step;
    report->residual_bits_equivalent =
        static_cast<int>(std::lround(std::log2(diagonal / residual_step)));
    report->segments = segments;
  }
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

}  // namespace

StatusOr<std::vector<uint8_t>> Encode(const MeshSequence& sequence, const EncoderOptions& options,
                                      EncodeReport* report) {
  const auto start = std::chrono::steady_clock::now();
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_RETURN_IF_ERROR(ValidateOptions(options));
  if (static_cast<uint64_t>(sequence.frame_count()) > format::kMaxFrames ||
      static_cast<uint64_t>(sequence.vertex_count()) > format::kMaxVertices) {
    return UnsupportedError("sequence exceeds the format's limits");
  }
  // Connectivity first: the rest of the stream uses the decoder's vertex labels and topology.
  DMC_ASSIGN_OR_RETURN(
      const ConnectivityCode connectivity,
      EncodeConnectivity(sequence.triangles(), sequence.vertex_count(), options.allow_reorder));
  const MeshTopology topology = BuildTopology(connectivity.triangles, sequence.vertex_count());
  const double diagonal = std::max(ComputeBoundingBox(sequence).diagonal(), 1e-12);
  EncodeReport local;
  EncodeReport& out = report ? *report : local;
  out = EncodeReport();

  EncoderOptions chosen = options;
  std::vector<uint8_t> bytes;
  if (options.target_bpfv > 0.0 || options.target_sted > 0.0) {
    // Rate control: bisection on the residual step (rank follows it automatically). Rate falls
    // and distortion rises monotonically with the step.
    double low = 1.0, high = 24.0;  // residual bits
    bool found = false;
    std::vector<uint8_t> best;
    EncodeReport best_report;
    for (int iteration = 0; iteration < 12; ++iteration) {
      const double bits = 0.5 * (low + high);
      chosen.residual_step = std::ldexp(diagonal, 0) * std::pow(2.0, -bits);
      EncodeReport trial;
      DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> candidate,
                           EncodeOnce(sequence, connectivity, topology, chosen, diagonal, &trial));
      bool meets;
      if (options.target_bpfv > 0.0) {
        meets = trial.bpfv <= options.target_bpfv;
      } else {
        DMC_RETURN_IF_ERROR(Measure(sequence, candidate, connectivity.vertex_order, &trial));
        meets = trial.distortion.sted <= options.target_sted;
      }
      // Meeting a rate target: finer steps are better while they fit; meeting a distortion
      // target: coarser steps are better while they meet it.
      const bool prefer_finer = options.target_bpfv > 0.0;
      if (meets) {
        found = true;
        best = std::move(candidate);
        best_report = trial;
        if (prefer_finer) {
          low = bits;
        } else {
          high = bits;
        }
      } else if (prefer_finer) {
        high = bits;
      } else {
        low = bits;
      }
    }
    if (!found) {
      return InvalidArgumentError(options.target_bpfv > 0.0
                                      ? "no parameters reach the target rate"
                                      : "no parameters reach the target distortion");
    }
    bytes = std::move(best);
    out = best_report;
  } else {
    DMC_ASSIGN_OR_RETURN(bytes,
                         EncodeOnce(sequence, connectivity, topology, chosen, diagonal, &out));
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

}  // namespace dmc
