#include "encoder/source_reader.h"

#include <algorithm>
#include <limits>

#include "dmc/sequence.h"

namespace dmc {

int FramesPerRead(int vertex_count, int frame_count) {
  constexpr size_t kReadBytes = size_t{1} << 20;
  const size_t frame_bytes = static_cast<size_t>(vertex_count) * 3 * sizeof(float);
  return static_cast<int>(
      std::clamp<size_t>(kReadBytes / frame_bytes, 1, static_cast<size_t>(frame_count)));
}

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

}  // namespace dmc
