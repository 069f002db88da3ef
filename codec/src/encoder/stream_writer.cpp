#include "encoder/stream_writer.h"

#include <cmath>

#include "encoder/codec_operators.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

constexpr int kDefaultSegmentFrames = 256;  // frames per segment unless options.segment_frames

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
  return plan;
}

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

std::vector<uint8_t> StreamEnd(const StreamPlan& plan, format::ChunkSizes& totals) {
  ByteWriter count;
  count.PutVarU(static_cast<uint64_t>(2 + 6 * plan.segments()));
  ByteWriter out;
  syntax::AppendChunk(out, format::ChunkType::kEnd, count.bytes());
  totals.header += out.size();
  return out.Take();
}

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

Status CheckFormatLimits(int vertex_count, int frame_count) {
  if (static_cast<uint64_t>(frame_count) > format::kMaxFrames ||
      static_cast<uint64_t>(vertex_count) > format::kMaxVertices) {
    return UnsupportedError("sequence exceeds the format's limits");
  }
  return Status::Ok();
}

}  // namespace dmc
