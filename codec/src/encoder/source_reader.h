// Reading a FrameSource in blocks: the scan pass (finiteness, bounding box, the metrics' original
// terms) and a segment's trajectories.
#pragma once

#include <functional>
#include <vector>

#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "fitting/segment_pca.h"
#include "metrics/streaming_distortion.h"

namespace dmc {

// Frames per read of the scan, segment and measure passes: blocks of about 1 MiB (at least one
// frame). Larger blocks read no faster from a PC2 cache, and the block is held beside the
// segment's trajectories, so it counts toward the encoder's peak memory.
int FramesPerRead(int vertex_count, int frame_count);

// Reads every frame of the source once, in blocks: checks finiteness, returns the bounding box,
// and gives each frame to `meter` (when not null) in order. `progress(frames done)` per block.
StatusOr<BoundingBox> ScanSource(FrameSource& source, StreamingDistortion* meter,
                                 const std::function<void(int)>& progress);

// Reads frames [first, first + count) of the source, in blocks, into a segment's trajectories.
// The read block lives only as long as the read: kept across segments it would sit beside the
// encode stage's buffers at their peak.
Status ReadSegmentTrajectories(FrameSource& source, int first, int count,
                               const std::vector<int32_t>& relabel,
                               SegmentTrajectories& trajectories);

}  // namespace dmc
