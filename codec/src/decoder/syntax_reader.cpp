#include "decoder/syntax_reader.h"

#include <zstd.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "bitstream/syntax.h"
#include "decoder/range_decoder.h"
#include "dmc/operators.h"
#include "entropy/byte_io.h"

namespace dmc::syntax {
namespace {

// Steps and weights must be positive and at most 2^64 (anchor weights within [2^-32, 2^32]):
// every dequantised value (an integer below 2^53 times a step) and every normal-matrix entry then
// stays finite, so a hostile header cannot smuggle infinities into the solver.
using format::kMaxStep;

Status CheckFinitePositive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0 || value > kMaxStep) {
    return CorruptStreamError(std::string(field) + " must be positive and at most 2^64, got " +
                              std::to_string(value));
  }
  return Status::Ok();
}

// Operator chunk of a geometric operator: f64 grid step, then the range-coded reference frame.
Status ReadReferenceFrame(std::span<const uint8_t> payload, const MeshTopology& topology,
                          SegmentSyntax& syntax) {
  ByteReader reader(payload);
  double step;
  DMC_RETURN_IF_ERROR(reader.GetF64(&step, "reference frame step"));
  DMC_RETURN_IF_ERROR(CheckFinitePositive(step, "reference frame step"));
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload.subspan(8)));
  auto contexts = std::make_unique<format::ReferenceFrameContexts>();
  const int v_count = topology.vertex_count;
  format::ReferenceFramePredictor predictor(topology);
  constexpr int64_t kLimit = format::kMaxReferenceMagnitude;
  for (const int v : predictor.order()) {
    std::array<int64_t, 3> prediction, q;
    const bool from_neighbours = predictor.Predict(v, &prediction);
    for (int axis = 0; axis < 3; ++axis) {
      int64_t residual;
      DMC_RETURN_IF_ERROR(decoder.DecodeSigned(
          from_neighbours ? contexts->with_neighbours[axis] : contexts->without_neighbours[axis],
          &residual));
      q[axis] = prediction[axis] + residual;
      if (q[axis] > kLimit || q[axis] < -kLimit) {
        return CorruptStreamError("reference frame coordinate out of range");
      }
    }
    predictor.Record(v, q);
  }
  const std::vector<std::array<int64_t, 3>>& q = predictor.values();
  syntax.reference_frame.resize(v_count, 3);
  for (int v = 0; v < v_count; ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      syntax.reference_frame(v, axis) = static_cast<double>(q[v][axis]) * step;
    }
  }
  return decoder.CheckNotOverrun("reference frame");
}

// The range decoder's 5 bytes of state (§5.1): a payload that must be decoded and is shorter is
// truncated-stream, whatever it declares.
constexpr uint64_t kRangeCoderStartBytes = 5;

// truncated-stream when `payload_bytes` (of which `prefix_bytes` come before the range-coded part)
// cannot start decoding; corrupt-stream when its range-coded part cannot hold `decisions`.
Status CheckHolds(uint64_t payload_bytes, uint64_t prefix_bytes, uint64_t decisions,
                  const char* payload, const std::string& declared) {
  if (payload_bytes < prefix_bytes + kRangeCoderStartBytes) {
    return TruncatedStreamError(
        std::string(payload) + " payload has " + std::to_string(payload_bytes) +
        " bytes, at least " + std::to_string(prefix_bytes + kRangeCoderStartBytes) + " are needed");
  }
  if (decisions <= format::MaxDecisions(payload_bytes - prefix_bytes)) return Status::Ok();
  return CorruptStreamError(std::string(payload) + " payload of " + std::to_string(payload_bytes) +
                            " bytes cannot hold the " + std::to_string(decisions) +
                            " coded values that " + declared + " declare (at most " +
                            std::to_string(format::kMaxDecisionsPerPayloadByte) + " per byte)");
}

}  // namespace

Status CheckPayloadCapacity(const format::SegmentHeader& header, uint32_t vertex_count,
                            const SegmentPayloadSizes& sizes) {
  const uint64_t v = vertex_count, f = header.frame_count, r = header.rank, a = header.anchor_count;
  const std::string frames = "F' = " + std::to_string(f);
  DMC_RETURN_IF_ERROR(CheckHolds(sizes.mean, 0, 3 * f, "mean", frames));
  if (r > 0) {
    DMC_RETURN_IF_ERROR(CheckHolds(sizes.basis, 0, r * (1 + 3 * f), "basis",
                                   "rank " + std::to_string(r) + " and " + frames));
  }
  if (format::IsGeometricOperator(header.operator_id)) {
    // The f64 step, then the range-coded frame.
    DMC_RETURN_IF_ERROR(CheckHolds(sizes.operator_info, 8, 3 * v, "reference frame",
                                   "V = " + std::to_string(v) + " vertices"));
  }
  DMC_RETURN_IF_ERROR(CheckHolds(sizes.anchors, 0, a * (1 + r), "anchor",
                                 std::to_string(a) + " anchors at rank " + std::to_string(r)));
  if (r > 0) {
    DMC_RETURN_IF_ERROR(CheckHolds(sizes.residuals, 0, v * r, "residual",
                                   "V = " + std::to_string(v) + " and rank " + std::to_string(r)));
  }
  return Status::Ok();
}

StatusOr<format::SequenceHeader> ReadSequenceHeader(std::span<const uint8_t> payload) {
  ByteReader reader(payload);
  format::SequenceHeader header;
  uint64_t value;
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&value, 1, format::kMaxVertices, "vertex count"));
  header.vertex_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&value, 1, format::kMaxTriangles, "triangle count"));
  header.triangle_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&value, 1, format::kMaxFrames, "frame count"));
  header.frame_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&value, 1, header.frame_count, "segment count"));
  header.segment_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetF64(&header.frame_rate, "frame rate"));
  if (!std::isfinite(header.frame_rate) || header.frame_rate < 0.0) {
    return CorruptStreamError("frame rate must be finite and non-negative");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&header.flags, "sequence flags"));
  if ((header.flags & ~format::kFlagReordered) != 0) {
    return CorruptStreamError("reserved sequence flag bits are set");
  }
  DMC_RETURN_IF_ERROR(reader.GetString(&header.name, format::kMaxNameLength, "sequence name"));
  if (!reader.at_end()) return CorruptStreamError("sequence header has trailing bytes");
  return header;
}

StatusOr<SceneHeader> ReadSceneHeader(std::span<const uint8_t> payload) {
  ByteReader reader(payload);
  SceneHeader header;
  DMC_RETURN_IF_ERROR(reader.GetU8(&header.kind, "scene kind"));
  if (header.kind != format::kSceneKindGlb) {
    return CorruptStreamError("scene kind " + std::to_string(header.kind) +
                              " is not defined (1: glTF binary)");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&header.compression, "scene compression"));
  if (header.compression != format::kSceneStored && header.compression != format::kSceneZstd) {
    return CorruptStreamError("scene compression " + std::to_string(header.compression) +
                              " is not defined (0: stored, 1: zstd)");
  }
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&header.size, 1, format::kMaxSceneBytes, "scene size"));
  header.data = payload.subspan(reader.position());
  if (header.compression == format::kSceneStored && header.data.size() != header.size) {
    return CorruptStreamError("the stored scene holds " + std::to_string(header.data.size()) +
                              " bytes, its size says " + std::to_string(header.size));
  }
  return header;
}

StatusOr<std::vector<uint8_t>> ReadScene(const SceneHeader& header) {
  if (header.compression == format::kSceneStored) {
    return std::vector<uint8_t>(header.data.begin(), header.data.end());
  }
  // One zstd frame that states its content size, equal to the declared size, and holds nothing
  // after it. It is decompressed block by block into a buffer that grows with the output, so a
  // few hostile bytes claiming a large scene cost only what their blocks really produce.
  const unsigned long long content =
      ZSTD_getFrameContentSize(header.data.data(), header.data.size());
  if (content != header.size ||
      ZSTD_findFrameCompressedSize(header.data.data(), header.data.size()) != header.data.size()) {
    return CorruptStreamError("the scene is not one zstd frame stating its " +
                              std::to_string(header.size) + " bytes");
  }
  std::unique_ptr<ZSTD_DStream, size_t (*)(ZSTD_DStream*)> stream(ZSTD_createDStream(),
                                                                  ZSTD_freeDStream);
  std::vector<uint8_t> scene;
  ZSTD_inBuffer input{header.data.data(), header.data.size(), 0};
  constexpr size_t kGrowth = size_t{1} << 20;
  size_t result = 1;
  while (result != 0) {
    const size_t done = scene.size();
    const size_t consumed = input.pos;
    scene.resize(std::min<size_t>(static_cast<size_t>(header.size), done + kGrowth));
    ZSTD_outBuffer output{scene.data(), scene.size(), done};
    result = ZSTD_decompressStream(stream.get(), &output, &input);
    if (ZSTD_isError(result)) {
      return CorruptStreamError(std::string("the scene's zstd data is corrupt (") +
                                ZSTD_getErrorName(result) + ")");
    }
    scene.resize(output.pos);
    if (output.pos == done && input.pos == consumed) break;  // no progress: cut or oversized
  }
  if (result != 0 || scene.size() != header.size) {
    return CorruptStreamError("the scene's zstd data does not decompress to " +
                              std::to_string(header.size) + " bytes");
  }
  return scene;
}

StatusOr<format::SegmentHeader> ReadSegmentHeader(std::span<const uint8_t> payload,
                                                  uint32_t expected_first_frame,
                                                  uint32_t frames_left, uint32_t vertex_count,
                                                  uint8_t version_minor) {
  ByteReader reader(payload);
  format::SegmentHeader h;
  h.version_minor = version_minor;
  uint64_t value;
  DMC_RETURN_IF_ERROR(reader.GetVarU(&value, "segment first frame"));
  if (value != expected_first_frame) {
    return CorruptStreamError("segment starts at frame " + std::to_string(value) + ", expected " +
                              std::to_string(expected_first_frame));
  }
  h.first_frame = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(
      reader.GetVarURange(&value, 1, std::min<uint64_t>(frames_left, format::kMaxSegmentFrames),
                          "segment frame count"));
  h.frame_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetVarURange(
      &value, 0, std::min<uint64_t>(format::kMaxRank, 3ull * h.frame_count), "segment rank"));
  h.rank = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetU8(&h.operator_id, "operator ID"));
  if (!format::IsCodecOperator(h.operator_id)) {
    return UnsupportedError("operator wire ID " + std::to_string(h.operator_id) +
                            " is not a codec operator of format 1.0");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&h.basis_bits, "basis bits"));
  if (h.basis_bits < 2 || h.basis_bits > 16) {
    return CorruptStreamError("basis bits " + std::to_string(h.basis_bits) + " outside [2, 16]");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&h.weight_bits, "weight bits"));
  if (h.weight_bits < 2 || h.weight_bits > 20) {
    return CorruptStreamError("weight bits " + std::to_string(h.weight_bits) + " outside [2, 20]");
  }
  DMC_RETURN_IF_ERROR(reader.GetU8(&h.weight_prediction, "weight prediction"));
  if (h.weight_prediction > 1) {
    return CorruptStreamError("weight prediction mode " + std::to_string(h.weight_prediction) +
                              " is unknown");
  }
  DMC_RETURN_IF_ERROR(reader.GetVarURange(&value, 1, vertex_count, "anchor count"));
  h.anchor_count = static_cast<uint32_t>(value);
  DMC_RETURN_IF_ERROR(reader.GetF64(&h.mean_step, "mean step"));
  DMC_RETURN_IF_ERROR(reader.GetF64(&h.residual_step, "residual step"));
  DMC_RETURN_IF_ERROR(reader.GetF64(&h.anchor_step, "anchor step"));
  DMC_RETURN_IF_ERROR(reader.GetF64(&h.anchor_weight, "anchor weight"));
  DMC_RETURN_IF_ERROR(CheckFinitePositive(h.mean_step, "mean step"));
  DMC_RETURN_IF_ERROR(CheckFinitePositive(h.residual_step, "residual step"));
  DMC_RETURN_IF_ERROR(CheckFinitePositive(h.anchor_step, "anchor step"));
  DMC_RETURN_IF_ERROR(CheckFinitePositive(h.anchor_weight, "anchor weight"));
  if (h.anchor_weight < format::kMinAnchorWeight || h.anchor_weight > format::kMaxAnchorWeight) {
    return CorruptStreamError("anchor weight must lie in [2^-32, 2^32], got " +
                              std::to_string(h.anchor_weight));
  }
  if (!reader.at_end()) return CorruptStreamError("segment header has trailing bytes");
  return h;
}

Status ReadMean(std::span<const uint8_t> payload, SegmentSyntax& syntax) {
  const int frames = static_cast<int>(syntax.header.frame_count);
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload));
  format::MeanContexts contexts;
  syntax.mean.resize(3 * frames);
  for (int axis = 0; axis < 3; ++axis) {
    int64_t q = 0;
    for (int f = 0; f < frames; ++f) {
      int64_t d;
      DMC_RETURN_IF_ERROR(decoder.DecodeSigned(f == 0 ? contexts.first : contexts.delta, &d));
      q += d;
      if (q > format::kMaxMeanMagnitude || q < -format::kMaxMeanMagnitude) {
        return CorruptStreamError("mean trajectory value out of range");
      }
      syntax.mean[3 * f + axis] = static_cast<double>(q) * syntax.header.mean_step;
    }
  }
  return decoder.CheckNotOverrun("mean chunk");
}

Status ReadOperator(std::span<const uint8_t> payload, const MeshTopology& topology,
                    SegmentSyntax& syntax) {
  const auto id = static_cast<OperatorId>(syntax.header.operator_id);
  if (format::IsGeometricOperator(syntax.header.operator_id)) {
    return ReadReferenceFrame(payload, topology, syntax);
  }
  if (id != OperatorId::kDdl) {
    if (!payload.empty()) {
      return CorruptStreamError("operator chunk must be empty for this operator");
    }
    return Status::Ok();
  }
  // Each visit codes all its unknown edges but the last, and every edge is unknown at exactly one
  // visit, so at least E - (non-isolated vertices) weights are coded: checked before the schedule
  // (whose cost grows with the mesh) is built.
  const uint64_t edges = topology.edges.size();
  const uint64_t visited_vertices =
      static_cast<uint64_t>(topology.vertex_count - topology.isolated_vertex_count);
  if (edges > visited_vertices) {
    DMC_RETURN_IF_ERROR(CheckHolds(
        payload.size(), 0, edges - visited_vertices, "DDL weight",
        std::to_string(edges) + " edges of " + std::to_string(visited_vertices) + " vertices"));
  }
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload));
  format::WeightContexts contexts;
  const int64_t unit_sum = int64_t{1} << syntax.header.weight_bits;
  const int64_t limit = unit_sum << 8;  // |w| <= 256: anything larger is not a fitted weight
  syntax.edge_weights.assign(topology.edges.size(), 0);
  std::vector<int64_t> known_sum(topology.vertex_count, 0);
  for (const format::WeightVisit& visit : format::BuildWeightSchedule(topology)) {
    const int n = static_cast<int>(visit.unknown_edges.size());
    int64_t& sum = known_sum[visit.vertex];
    for (int j = 0; j < n; ++j) {
      const int e = visit.unknown_edges[j];
      int64_t weight;
      if (j + 1 < n) {
        const int unknown = n - j;
        const int64_t prediction = format::PredictWeight(
            static_cast<format::WeightPrediction>(syntax.header.weight_prediction), unit_sum - sum,
            topology, std::span<const int32_t>(visit.unknown_edges).subspan(j));
        int64_t residual;
        DMC_RETURN_IF_ERROR(
            decoder.DecodeSigned(contexts.by_unknown[std::min(unknown, 5) - 2], &residual));
        weight = prediction + residual;
      } else {
        weight = unit_sum - sum;
      }
      if (weight > limit || weight < -limit) {
        return CorruptStreamError("DDL weight of edge " + std::to_string(e) + " out of range");
      }
      syntax.edge_weights[e] = weight;
      const int other =
          topology.edges[e][0] == visit.vertex ? topology.edges[e][1] : topology.edges[e][0];
      sum += weight;
      known_sum[other] += weight;
    }
  }
  return decoder.CheckNotOverrun("operator chunk");
}

Status ReadAnchors(std::span<const uint8_t> payload, int vertex_count, SegmentSyntax& syntax) {
  const int count = static_cast<int>(syntax.header.anchor_count);
  const int rank = static_cast<int>(syntax.header.rank);
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload));
  auto contexts = std::make_unique<format::AnchorContexts>();
  syntax.anchors.resize(count);
  int64_t previous = -1;
  for (int a = 0; a < count; ++a) {
    uint64_t gap;
    DMC_RETURN_IF_ERROR(decoder.DecodeUnsigned(contexts->index_gap, &gap));
    const int64_t index = previous + 1 + static_cast<int64_t>(std::min<uint64_t>(gap, 1u << 30));
    if (index >= vertex_count) {
      return CorruptStreamError("anchor " + std::to_string(a) + " index " + std::to_string(index) +
                                " is not a vertex");
    }
    syntax.anchors[a] = static_cast<int32_t>(index);
    previous = index;
  }
  syntax.anchor_step_exponents.clear();
  if (syntax.header.version_minor >= 2) {
    syntax.anchor_step_exponents.resize(count);
    for (int a = 0; a < count; ++a) {
      int64_t e;
      DMC_RETURN_IF_ERROR(decoder.DecodeSigned(contexts->step_exponent, &e));
      if (e > format::kMaxStepExponent || e < -format::kMaxStepExponent) {
        return CorruptStreamError("step exponent " + std::to_string(e) + " of anchor " +
                                  std::to_string(a) + " beyond +-" +
                                  std::to_string(format::kMaxStepExponent));
      }
      syntax.anchor_step_exponents[a] = static_cast<int8_t>(e);
    }
  }
  syntax.anchor_values.resize(count, rank);
  for (int a = 0; a < count; ++a) {
    for (int k = 0; k < rank; ++k) {
      int64_t q;
      DMC_RETURN_IF_ERROR(
          decoder.DecodeSigned(contexts->value[std::min(k, format::kBasisColumnGroups - 1)], &q));
      syntax.anchor_values(a, k) = static_cast<double>(q) * syntax.header.anchor_step;
    }
  }
  return decoder.CheckNotOverrun("anchor chunk");
}

Status ReadResiduals(std::span<const uint8_t> payload, const MeshTopology& topology,
                     const std::vector<int32_t>& vertex_order, SegmentSyntax& syntax) {
  const int v_count = topology.vertex_count;
  const int rank = static_cast<int>(syntax.header.rank);
  syntax.delta.resize(v_count, rank);
  if (rank == 0) return Status::Ok();
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload));
  // The context of each value (format::ResidualContextSelector, shared with the writer).
  format::ResidualContextSelector selector(topology, vertex_order, syntax.header.version_minor);
  const double step = syntax.header.residual_step;
  // Format 1.2: the step of each vertex scaled by its anchor region's factor (§8.5.1).
  const std::vector<double> factors =
      format::VertexStepFactors(topology, syntax.anchors, syntax.anchor_step_exponents);
  for (int k = 0; k < rank; ++k) {
    double* delta = syntax.delta.col(k).data();
    for (int i = 0; i < v_count; ++i) {
      IntegerContexts& ctx = selector.Select(k, i);
      int64_t value;
      if (!decoder.TryDecodeSigned(ctx, &value)) return decoder.error();
      if (value > format::kMaxResidualMagnitude || value < -format::kMaxResidualMagnitude) {
        return CorruptStreamError("residual out of range");
      }
      selector.Record(k, i, value);
      const int32_t v = vertex_order[i];
      delta[v] = static_cast<double>(value) * format::VertexResidualStep(step, factors, v);
    }
    // Stop at the first column that ran past the payload: a tiny stream declaring a huge mesh
    // is reported at once instead of after decoding V × r virtual symbols.
    DMC_RETURN_IF_ERROR(decoder.CheckNotOverrun("residual chunk"));
  }
  return decoder.CheckNotOverrun("residual chunk");
}

}  // namespace dmc::syntax
