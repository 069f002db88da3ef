#include "encoder/stream_measurement.h"

#include <algorithm>

#include "dmc/decoder.h"
#include "encoder/source_reader.h"

namespace dmc {
namespace {

// Back to input labels in place, one frame at a time through a copy of that frame: a second
// segment-sized buffer would be the measurement's largest.
void RestoreInputLabels(const std::vector<int32_t>& relabel, int vertex_count, int frame_count,
                        std::vector<float>& frames) {
  const size_t per_frame = static_cast<size_t>(vertex_count) * 3;
  std::vector<float> frame_copy(per_frame);
  for (size_t f = 0; f < static_cast<size_t>(frame_count); ++f) {
    float* frame = frames.data() + f * per_frame;
    std::copy_n(frame, per_frame, frame_copy.data());
    for (int v = 0; v < vertex_count; ++v) {
      std::copy_n(frame_copy.data() + 3 * static_cast<size_t>(v), 3,
                  frame + 3 * static_cast<size_t>(relabel[v]));
    }
  }
}

// The decoder's verdict on a stream the encoder wrote. The encoder checks every value against
// the format, so a malformed stream is its bug; a requested operator whose normal matrix cannot be
// factored on this geometry is the one rejection left to the decoding (kNumericalFailure).
Status OwnStreamStatus(const Status& status) {
  switch (status.code()) {
    case ErrorCode::kCorruptStream:
    case ErrorCode::kTruncatedStream:
    case ErrorCode::kUnsupported:
      return InternalError("the decoder rejects the encoded stream (a bug in the encoder): " +
                           status.ToString());
    case ErrorCode::kNumericalFailure:
      return status.WithContext(
          "the encoded stream does not decode (use another operator, e.g. the default ddl)");
    default:
      return status.WithContext("decoding the encoded stream");
  }
}

}  // namespace

StatusOr<StreamingDistortion> CreateSourceMeter(FrameSource& source) {
  std::vector<float> frame0(static_cast<size_t>(source.vertex_count()) * 3);
  DMC_RETURN_IF_ERROR(source.ReadFrames(0, 1, frame0.data()));
  return StreamingDistortion::Create(source.triangles(), source.vertex_count(),
                                     source.frame_count(), frame0.data());
}

StatusOr<DistortionReport> MeasureStream(FrameSource& source, std::span<const uint8_t> stream,
                                         const std::vector<int32_t>& relabel,
                                         const StreamPlan& plan, StreamingDistortion* meter,
                                         const std::function<void(int)>& progress) {
  Decoder decoder;
  // No limits: the stream's output is the encoder's own input (decoded one segment at a time),
  // and its normal matrices those the encoder's closed loop factors.
  DecoderOptions unlimited;
  unlimited.max_output_bytes = 0;
  unlimited.max_matrix_bytes = 0;
  DMC_RETURN_IF_ERROR(OwnStreamStatus(decoder.Open(stream, unlimited)));
  const int v_count = source.vertex_count();
  const size_t per_frame = static_cast<size_t>(v_count) * 3;
  std::vector<float> decoded, original;
  const int frames_per_read = FramesPerRead(v_count, plan.frames);
  for (int s = 0; s < plan.segments(); ++s) {
    const int first = plan.segment_first[s], count = plan.segment_frames(s);
    DMC_RETURN_IF_ERROR(OwnStreamStatus(decoder.DecodeSegmentInto(s, [&](int) -> StatusOr<float*> {
      decoded.resize(per_frame * static_cast<size_t>(count));
      return decoded.data();
    })));
    if (meter == nullptr) {
      progress(first + count);
      continue;
    }
    if (!relabel.empty()) RestoreInputLabels(relabel, v_count, count, decoded);
    // The meter takes any consecutive frame ranges: the segment goes in read-sized blocks, so the
    // original frames in memory are one block and its speed window, not a whole segment.
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
    progress(first + count);
  }
  if (meter == nullptr) return DistortionReport();
  return meter->Report();
}

}  // namespace dmc
