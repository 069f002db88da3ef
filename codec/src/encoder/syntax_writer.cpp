#include "encoder/syntax_writer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "bitstream/syntax.h"
#include "encoder/bit_cost.h"
#include "encoder/range_encoder.h"

namespace dmc::syntax {

namespace {

std::string Number(double value) { return ShortNumber(value); }

std::string Remedy(std::string_view remedy) {
  return remedy.empty() ? std::string() : ": " + std::string(remedy);
}

}  // namespace

std::string ShortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

Status CheckStep(double step, std::string_view what, std::string_view remedy) {
  if (std::isfinite(step) && step > 0.0 && step <= format::kMaxStep) return Status::Ok();
  return UnsupportedError(std::string(what) + " " + Number(step) +
                          " is outside the format's range (0, 2^64 = " + Number(format::kMaxStep) +
                          "]" + Remedy(remedy));
}

Status CheckQuantisedRange(const Eigen::Ref<const Eigen::MatrixXd>& values, double step,
                           int64_t limit, std::string_view what, std::string_view remedy) {
  if (values.size() == 0) return Status::Ok();
  const double largest = values.cwiseAbs().maxCoeff();
  // llround(x) stays within [-limit, limit] exactly when |x| < limit + 0.5; NaN fails too.
  const double steps = largest / step;
  if (steps < static_cast<double>(limit) + 0.5) return Status::Ok();
  return UnsupportedError(
      std::string(what) + " " + Number(largest) + " is " + Number(steps) +
      " quantisation steps of " + Number(step) + ", beyond the format's limit of 2^" +
      std::to_string(std::bit_width(static_cast<uint64_t>(limit)) - 1) + Remedy(remedy));
}

Status CheckSequenceHeader(const format::SequenceHeader& header) {
  if (!(std::isfinite(header.frame_rate) && header.frame_rate >= 0.0)) {
    return UnsupportedError(
        "frame rate " + Number(header.frame_rate) +
        " is not finite and non-negative, as the format requires (0 = unknown)");
  }
  return Status::Ok();
}

Status CheckSegmentHeader(const format::SegmentHeader& h, int vertex_count) {
  if (h.frame_count < 1 || h.frame_count > format::kMaxSegmentFrames ||
      h.rank > std::min<uint64_t>(format::kMaxRank, 3 * uint64_t{h.frame_count}) ||
      h.anchor_count < 1 || h.anchor_count > static_cast<uint32_t>(vertex_count)) {
    return InternalError("segment at frame " + std::to_string(h.first_frame) + ": " +
                         std::to_string(h.frame_count) + " frames, rank " + std::to_string(h.rank) +
                         ", " + std::to_string(h.anchor_count) +
                         " anchors are outside the format's ranges");
  }
  constexpr std::string_view kRescale = "rescale the input (smaller coordinates)";
  DMC_RETURN_IF_ERROR(CheckStep(h.mean_step, "the mean step", kRescale));
  DMC_RETURN_IF_ERROR(CheckStep(h.residual_step, "the residual step", kRescale));
  DMC_RETURN_IF_ERROR(CheckStep(h.anchor_step, "the anchor step", kRescale));
  if (!(h.anchor_weight >= format::kMinAnchorWeight &&
        h.anchor_weight <= format::kMaxAnchorWeight)) {
    return InternalError("anchor weight " + Number(h.anchor_weight) + " is outside [2^-32, 2^32]");
  }
  return Status::Ok();
}

Status CheckDdlWeights(const std::vector<int64_t>& weights, int weight_bits) {
  const int64_t limit = int64_t{256} << weight_bits;
  for (size_t e = 0; e < weights.size(); ++e) {
    if (weights[e] > limit || weights[e] < -limit) {
      return UnsupportedError("the DDL weight of edge " + std::to_string(e) + " is " +
                              Number(std::ldexp(static_cast<double>(weights[e]), -weight_bits)) +
                              ", beyond the format's limit of 256 in magnitude");
    }
  }
  return Status::Ok();
}

void AppendChunk(ByteWriter& out, format::ChunkType type, const std::vector<uint8_t>& payload) {
  const auto type_value = static_cast<uint8_t>(type);
  out.PutU8(type_value);
  out.PutVarU(payload.size());
  out.PutBytes(payload);
  out.PutU32(format::ChunkChecksum(type_value, payload));
}

std::vector<uint8_t> WriteSequenceHeader(const format::SequenceHeader& header) {
  ByteWriter w;
  w.PutVarU(header.vertex_count);
  w.PutVarU(header.triangle_count);
  w.PutVarU(header.frame_count);
  w.PutVarU(header.segment_count);
  w.PutF64(header.frame_rate);
  w.PutU8(header.flags);
  w.PutString(header.name.substr(0, format::kMaxNameLength));
  return w.Take();
}

std::vector<uint8_t> WriteSegmentHeader(const format::SegmentHeader& h) {
  ByteWriter w;
  w.PutVarU(h.first_frame);
  w.PutVarU(h.frame_count);
  w.PutVarU(h.rank);
  w.PutU8(h.operator_id);
  w.PutU8(h.basis_bits);
  w.PutU8(h.weight_bits);
  w.PutU8(h.weight_prediction);
  w.PutVarU(h.anchor_count);
  w.PutF64(h.mean_step);
  w.PutF64(h.residual_step);
  w.PutF64(h.anchor_step);
  w.PutF64(h.anchor_weight);
  return w.Take();
}

std::vector<uint8_t> WriteMean(const Eigen::VectorXd& mean, const format::SegmentHeader& header,
                               Eigen::VectorXd* decoded) {
  const int frames = static_cast<int>(header.frame_count);
  RangeEncoder encoder;
  format::MeanContexts contexts;
  decoded->resize(3 * frames);
  for (int axis = 0; axis < 3; ++axis) {
    int64_t previous = 0;
    for (int f = 0; f < frames; ++f) {
      const int64_t q = std::llround(mean[3 * f + axis] / header.mean_step);
      encoder.EncodeSigned(f == 0 ? contexts.first : contexts.delta, q - previous);
      previous = q;
      (*decoded)[3 * f + axis] = static_cast<double>(q) * header.mean_step;
    }
  }
  return encoder.Finish();
}

std::vector<uint8_t> WriteDdlWeights(const std::vector<double>& edge_weights,
                                     const MeshTopology& topology, int weight_bits,
                                     format::WeightPrediction prediction_mode,
                                     std::vector<int64_t>* decoded, double dead_zone) {
  RangeEncoder encoder;
  format::WeightContexts contexts;
  const int64_t unit_sum = int64_t{1} << weight_bits;
  const double scale = static_cast<double>(unit_sum);
  decoded->assign(topology.edges.size(), 0);
  std::vector<int64_t> known_sum(topology.vertex_count, 0);
  for (const format::WeightVisit& visit : format::BuildWeightSchedule(topology)) {
    const int n = static_cast<int>(visit.unknown_edges.size());
    int64_t& sum = known_sum[visit.vertex];
    for (int j = 0; j < n; ++j) {
      const int e = visit.unknown_edges[j];
      int64_t weight;
      if (j + 1 < n) {
        const int unknown = n - j;
        const int64_t prediction =
            format::PredictWeight(prediction_mode, unit_sum - sum, topology,
                                  std::span<const int32_t>(visit.unknown_edges).subspan(j));
        const double offset = edge_weights[e] * scale - static_cast<double>(prediction);
        weight = std::abs(offset) <= dead_zone ? prediction : prediction + std::llround(offset);
        encoder.EncodeSigned(contexts.by_unknown[std::min(unknown, 5) - 2], weight - prediction);
      } else {
        weight = unit_sum - sum;
      }
      (*decoded)[e] = weight;
      const int other =
          topology.edges[e][0] == visit.vertex ? topology.edges[e][1] : topology.edges[e][0];
      sum += weight;
      known_sum[other] += weight;
    }
  }
  return encoder.Finish();
}

std::vector<uint8_t> WriteReferenceFrame(const FramePositionsD& frame, const MeshTopology& topology,
                                         double step, FramePositionsD* decoded) {
  ByteWriter header;
  header.PutF64(step);
  RangeEncoder encoder;
  auto contexts = std::make_unique<format::ReferenceFrameContexts>();
  const int v_count = topology.vertex_count;
  format::ReferenceFramePredictor predictor(topology);
  for (const int v : predictor.order()) {
    std::array<int64_t, 3> prediction, q;
    const bool from_neighbours = predictor.Predict(v, &prediction);
    for (int axis = 0; axis < 3; ++axis) {
      q[axis] = std::llround(frame(v, axis) / step);
      encoder.EncodeSigned(
          from_neighbours ? contexts->with_neighbours[axis] : contexts->without_neighbours[axis],
          q[axis] - prediction[axis]);
    }
    predictor.Record(v, q);
  }
  const std::vector<std::array<int64_t, 3>>& q = predictor.values();
  decoded->resize(v_count, 3);
  for (int v = 0; v < v_count; ++v) {
    for (int axis = 0; axis < 3; ++axis)
      (*decoded)(v, axis) = static_cast<double>(q[v][axis]) * step;
  }
  std::vector<uint8_t> payload = header.Take();
  const std::vector<uint8_t> coded = encoder.Finish();
  payload.insert(payload.end(), coded.begin(), coded.end());
  return payload;
}

std::vector<uint8_t> WriteAnchors(const std::vector<int32_t>& anchors,
                                  const Eigen::MatrixXd& coefficients,
                                  const format::SegmentHeader& header,
                                  Eigen::MatrixXd* decoded_values,
                                  std::span<const int8_t> step_exponents) {
  const int rank = static_cast<int>(header.rank);
  RangeEncoder encoder;
  auto contexts = std::make_unique<format::AnchorContexts>();
  int64_t previous = -1;
  for (int32_t index : anchors) {
    encoder.EncodeUnsigned(contexts->index_gap, static_cast<uint64_t>(index - previous - 1));
    previous = index;
  }
  if (header.version_minor >= 2) {
    for (size_t a = 0; a < anchors.size(); ++a) {
      encoder.EncodeSigned(contexts->step_exponent,
                           a < step_exponents.size() ? step_exponents[a] : 0);
    }
  }
  decoded_values->resize(static_cast<Eigen::Index>(anchors.size()), rank);
  for (size_t a = 0; a < anchors.size(); ++a) {
    for (int k = 0; k < rank; ++k) {
      const int64_t q = std::llround(coefficients(anchors[a], k) / header.anchor_step);
      encoder.EncodeSigned(contexts->value[std::min(k, format::kBasisColumnGroups - 1)], q);
      (*decoded_values)(static_cast<Eigen::Index>(a), k) =
          static_cast<double>(q) * header.anchor_step;
    }
  }
  return encoder.Finish();
}

StatusOr<std::vector<uint8_t>> WriteResiduals(const Eigen::MatrixXd& delta,
                                              const MeshTopology& topology,
                                              const std::vector<int32_t>& vertex_order,
                                              const format::SegmentHeader& header,
                                              Eigen::MatrixXd* decoded, double rdo_lambda,
                                              std::span<const double> step_factors) {
  const int v_count = topology.vertex_count;
  const int rank = static_cast<int>(header.rank);
  if (decoded) decoded->resize(v_count, rank);
  if (rank == 0) return std::vector<uint8_t>();
  RangeEncoder encoder;
  // The context of each value (format::ResidualContextSelector, shared with the reader).
  format::ResidualContextSelector selector(topology, vertex_order, header.version_minor);
  for (int k = 0; k < rank; ++k) {
    for (int i = 0; i < v_count; ++i) {
      const int v = vertex_order[i];
      const double step = format::VertexResidualStep(header.residual_step, step_factors, v);
      const double steps = delta(v, k) / step;
      if (!(std::abs(steps) <= static_cast<double>(format::kMaxResidualMagnitude))) {
        return UnsupportedError(
            "the residual of vertex " + std::to_string(v) + " in component " + std::to_string(k) +
            " is " + std::to_string(steps) + " steps, beyond the format's limit of 2^40: the " +
            "operator amplifies this geometry too much for the residual step; use fewer residual " +
            "bits or another operator");
      }
      IntegerContexts& contexts = selector.Select(k, i);
      const int64_t q = RdoLevel(steps, contexts, rdo_lambda);
      encoder.EncodeSigned(contexts, q);
      selector.Record(k, i, q);
      if (decoded) (*decoded)(v, k) = static_cast<double>(q) * step;
    }
  }
  return encoder.Finish();
}

}  // namespace dmc::syntax
