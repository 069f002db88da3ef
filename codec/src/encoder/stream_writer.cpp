#include "encoder/stream_writer.h"

#include <zstd.h>

#include <cmath>
#include <string>

#include "encoder/codec_operators.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

constexpr int kDefaultSegmentFrames = 256;  // frames per segment unless options.segment_frames
// The scene is compressed once per encode, so the slow end of zstd's levels is affordable: level
// 19 against 3 saves a few percent of a scene's bytes.
constexpr int kSceneZstdLevel = 19;

std::string Number(double value) { return syntax::ShortNumber(value); }

// The steps every segment derives from the plan, against the format's 2^64 (spec §8.1), before
// anything is coded: far beyond float32 data at ordinary scales, so the remedy is a smaller input.
Status CheckPlannedSteps(const StreamPlan& plan, const EncoderOptions& options) {
  const std::string diagonal = "the bounding-box diagonal " + Number(plan.diagonal);
  const std::string remedy = options.residual_step > 0.0
                                 ? "use a smaller residual step"
                                 : "rescale the input: with " +
                                       std::to_string(options.residual_bits) + " residual bits, " +
                                       diagonal + " must be at most " +
                                       Number(std::ldexp(format::kMaxStep, options.residual_bits));
  DMC_RETURN_IF_ERROR(syntax::CheckStep(plan.residual_step, "the residual step", remedy));
  DMC_RETURN_IF_ERROR(syntax::CheckStep(plan.residual_step * options.anchor_step_ratio,
                                        "the anchor step", "use a smaller anchor step ratio"));
  return syntax::CheckStep(std::ldexp(plan.diagonal, -kMeanStepBits), "the mean step",
                           "rescale the input: " + diagonal + " must be at most " +
                               Number(std::ldexp(format::kMaxStep, kMeanStepBits)));
}

}  // namespace

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
  DMC_RETURN_IF_ERROR(CheckPlannedSteps(plan, options));
  return plan;
}

StatusOr<std::vector<uint8_t>> StreamPrefix(int vertex_count, int triangle_count,
                                            const std::string& name, double frame_rate,
                                            const StreamPlan& plan,
                                            const ConnectivityCode& connectivity,
                                            std::span<const uint8_t> scene_payload,
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
  DMC_RETURN_IF_ERROR(syntax::CheckSequenceHeader(header));
  syntax::AppendChunk(out, format::ChunkType::kSequenceHeader, syntax::WriteSequenceHeader(header));
  totals.header += out.size();  // includes magic and version
  const size_t before = out.size();
  syntax::AppendChunk(out, format::ChunkType::kConnectivity, connectivity.payload);
  totals.connectivity += out.size() - before;
  if (!scene_payload.empty()) {
    const size_t scene_start = out.size();
    syntax::AppendChunk(out, format::ChunkType::kScene,
                        std::vector<uint8_t>(scene_payload.begin(), scene_payload.end()));
    totals.scene += out.size() - scene_start;
  }
  return out.Take();
}

StatusOr<std::vector<uint8_t>> ScenePayload(std::span<const uint8_t> scene) {
  if (scene.empty()) return std::vector<uint8_t>();
  if (scene.size() > format::kMaxSceneBytes) {
    return InvalidArgumentError("the scene's " + std::to_string(scene.size()) +
                                " bytes exceed the format's 2^30");
  }
  ByteWriter out;
  out.PutU8(format::kSceneKindGlb);
  out.PutU8(format::kSceneZstd);
  out.PutVarU(scene.size());
  std::vector<uint8_t> payload = out.Take();
  const size_t header = payload.size();
  payload.resize(header + ZSTD_compressBound(scene.size()));
  const size_t compressed = ZSTD_compress(payload.data() + header, payload.size() - header,
                                          scene.data(), scene.size(), kSceneZstdLevel);
  if (ZSTD_isError(compressed)) {
    return InternalError(std::string("zstd failed on the scene: ") + ZSTD_getErrorName(compressed));
  }
  payload.resize(header + compressed);
  return payload;
}

std::vector<uint8_t> StreamEnd(const StreamPlan& plan, format::ChunkSizes& totals) {
  ByteWriter count;
  count.PutVarU(static_cast<uint64_t>(2 + (totals.scene > 0 ? 1 : 0) + 6 * plan.segments()));
  ByteWriter out;
  syntax::AppendChunk(out, format::ChunkType::kEnd, count.bytes());
  totals.header += out.size();
  return out.Take();
}

void RecordSegment(const SegmentResult& segment, int index, int first_frame, int frames,
                   format::ChunkSizes& totals, EncodeReport* report) {
  if (report) {
    if (index == 0) {
      report->rank = segment.rank;
      report->anchors = segment.anchors;
      report->segment_operators.clear();
      report->segment_details.clear();
    }
    report->segment_operators.emplace_back(CodecOperatorName(segment.operator_id));
    report->segment_details.push_back({first_frame, frames,
                                       std::string(CodecOperatorName(segment.operator_id)),
                                       segment.rank, segment.anchors, segment.residual_step});
  }
  totals.header += segment.sizes.header;
  totals.mean += segment.sizes.mean;
  totals.basis += segment.sizes.basis;
  totals.operator_info += segment.sizes.operator_info;
  totals.anchors += segment.sizes.anchors;
  totals.residuals += segment.sizes.residuals;
}

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
  report.scene_bytes = totals.scene;
  report.positions_bpfv = 8.0 * static_cast<double>(bytes - totals.scene) /
                          (static_cast<double>(plan.frames) * vertex_count);
  report.residual_step = plan.residual_step;
  report.residual_bits_equivalent =
      static_cast<int>(std::lround(std::log2(plan.diagonal / plan.residual_step)));
  report.segments = plan.segments();
}

Status CheckFormatLimits(int vertex_count, int frame_count) {
  const auto vertices = static_cast<uint64_t>(vertex_count);
  const auto frames = static_cast<uint64_t>(frame_count);
  if (frames > format::kMaxFrames || vertices > format::kMaxVertices) {
    return UnsupportedError("sequence exceeds the format's limits");
  }
  // Spec §6.2: a decoder refuses more than 16 GiB of float32 positions.
  if (12 * vertices * frames > (uint64_t{1} << 34)) {
    return UnsupportedError("the sequence's " + std::to_string(vertices) + " vertices × " +
                            std::to_string(frames) +
                            " frames exceed the format's 16 GiB of positions per stream: encode "
                            "it in parts (fewer frames each)");
  }
  return Status::Ok();
}

}  // namespace dmc
