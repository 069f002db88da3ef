// StreamingDistortion: segment-by-segment driver of the shared metric code; see
// metrics/streaming_distortion.h.
#include "metrics/streaming_distortion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace dmc {

StatusOr<StreamingDistortion> StreamingDistortion::Create(const Triangles& triangles,
                                                          int vertex_count, int frame_count,
                                                          const float* frame0,
                                                          const StedOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateStedOptions(options));
  if (vertex_count <= 0 || frame_count <= 0) {
    return InvalidSequenceError("the sequence has no vertices or no frames");
  }
  // PrepareSted on frame 0 alone gives exactly what it gives on the whole original: the edges,
  // the neighbourhoods and D depend on the triangles and frame 0 only. (With one frame it does
  // not check D > 0; FinishOriginal does, once the first pass has read the whole original.)
  MeshSequence first_frame(vertex_count, triangles, 1);
  std::copy_n(frame0, static_cast<size_t>(vertex_count) * 3, first_frame.data());
  StreamingDistortion meter;
  DMC_ASSIGN_OR_RETURN(meter.sted_, metrics_internal::PrepareSted(first_frame, options));
  meter.vertex_count_ = vertex_count;
  meter.frame_count_ = frame_count;
  meter.sted_sums_ = metrics_internal::StartSted(meter.sted_);
  meter.box_.min.setConstant(std::numeric_limits<double>::infinity());
  meter.box_.max.setConstant(-std::numeric_limits<double>::infinity());
  return meter;
}

void StreamingDistortion::AddOriginalFrame(const float* data) {
  kg_.centroid_deviation_squared +=
      metrics_internal::FrameCentroidDeviationSquared(data, vertex_count_);
  const Eigen::Map<const FramePositions> positions(data, vertex_count_, 3);
  box_.min = box_.min.cwiseMin(positions.colwise().minCoeff().cast<double>().transpose());
  box_.max = box_.max.cwiseMax(positions.colwise().maxCoeff().cast<double>().transpose());
  ++original_frames_seen_;
}

Status StreamingDistortion::FinishOriginal() {
  if (original_frames_seen_ != frame_count_) {
    return InternalError("StreamingDistortion: " + std::to_string(original_frames_seen_) + " of " +
                         std::to_string(frame_count_) + " original frames seen");
  }
  // The in-memory meter's checks, in its order (STED's reference first, then KG's).
  DMC_RETURN_IF_ERROR(metrics_internal::CheckStedDefined(frame_count_, sted_.diameter));
  DMC_RETURN_IF_ERROR(metrics_internal::CheckKgDefined(kg_.centroid_deviation_squared));
  kg_.bounding_box_diagonal = box_.diagonal();
  return Status::Ok();
}

std::pair<int, int> StreamingDistortion::OriginalWindow(int first, int count) const {
  const int reach =
      static_cast<int>(metrics_internal::EffectiveWindow(sted_.options, frame_count_));
  return {std::max(0, first - reach), std::min(frame_count_, first + count + reach)};
}

Status StreamingDistortion::AddSegment(int first, int count, const float* original,
                                       const float* decoded) {
  if (first != next_frame_ || count <= 0 || count > frame_count_ - first) {
    return InvalidArgumentError("StreamingDistortion: segment [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") out of order (next frame " +
                                std::to_string(next_frame_) + ")");
  }
  // ValidateSequence's check of the decoded frames (the in-memory meter validates the whole
  // decoded sequence and prefixes "distorted").
  DMC_RETURN_IF_ERROR(
      CheckFiniteFrames(decoded, first, count, vertex_count_).WithContext("distorted"));
  const metrics_internal::FrameWindow original_frames{original, OriginalWindow(first, count).first,
                                                      vertex_count_, nullptr};
  const metrics_internal::FrameWindow decoded_frames{
      decoded, first, vertex_count_, first > 0 ? previous_decoded_.data() : nullptr};
  const int end = first + count;
  metrics_internal::AccumulateSted(sted_, frame_count_, original_frames, decoded_frames, first, end,
                                   sted_sums_);
  metrics_internal::AccumulateVertexErrors(original_frames, decoded_frames, first, end,
                                           error_sums_);

  const float* last_decoded = decoded_frames.frame(end - 1);
  previous_decoded_.assign(last_decoded, last_decoded + static_cast<size_t>(vertex_count_) * 3);
  next_frame_ = end;
  return Status::Ok();
}

StatusOr<DistortionReport> StreamingDistortion::Report() const {
  if (next_frame_ != frame_count_) {
    return InternalError("StreamingDistortion: " + std::to_string(next_frame_) + " of " +
                         std::to_string(frame_count_) + " frames measured");
  }
  return metrics_internal::AssembleReport(
      metrics_internal::FinishSted(sted_, sted_sums_, frame_count_), error_sums_, kg_, frame_count_,
      vertex_count_);
}

}  // namespace dmc
