// The stream around the segments: the plan every encode of a sequence derives (segments, residual
// step), the prefix (magic, version, sequence header, connectivity), the end chunk, and the
// report's rate fields and bit breakdown.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "dmc/encoder.h"
#include "dmc/wire_ids.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/segment_encoder.h"

namespace dmc {

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

// The mean trajectory's step is diagonal · 2^-kMeanStepBits (or coarser, SegmentEncoder).
inline constexpr int kMeanStepBits = 18;

// kUnsupported when the residual, anchor or mean step it implies is beyond the format's range
// (a diagonal above about 1.9e22 at 10 residual bits), naming the step and the remedy.
StatusOr<StreamPlan> PlanStream(int frames, double diagonal, const EncoderOptions& options);

// Magic, version, the sequence header chunk, the connectivity chunk and, when `scene_payload` is
// not empty, the scene chunk (ScenePayload); kUnsupported for a frame rate the format cannot carry.
StatusOr<std::vector<uint8_t>> StreamPrefix(int vertex_count, int triangle_count,
                                            const std::string& name, double frame_rate,
                                            const StreamPlan& plan,
                                            const ConnectivityCode& connectivity,
                                            std::span<const uint8_t> scene_payload,
                                            format::ChunkSizes& totals);

// The scene chunk's payload for a GLB `scene` (spec §6.3: kind 1, zstd at level 19, the size);
// empty for an empty scene. kInvalidArgument beyond format::kMaxSceneBytes.
StatusOr<std::vector<uint8_t>> ScenePayload(std::span<const uint8_t> scene);

// The end chunk: it counts the chunks before it (sequence header, connectivity, the scene when
// totals.scene says there is one, 6 per segment).
std::vector<uint8_t> StreamEnd(const StreamPlan& plan, format::ChunkSizes& totals);

// Adds segment `index` (segments in order; frames [first_frame, first_frame + frames)) to the
// totals and the report: its sizes, its header's operator, rank and step, and the rank and
// anchors rate control chose when it is the first.
void RecordSegment(const SegmentResult& segment, int index, int first_frame, int frames,
                   format::ChunkSizes& totals, EncodeReport* report);

// The report's rate fields (rank and anchors are the first segment's, set as it is added).
void FillRateReport(const StreamPlan& plan, int vertex_count, uint64_t bytes,
                    const format::ChunkSizes& totals, EncodeReport& report);

// kUnsupported when the counts exceed the format's limits.
Status CheckFormatLimits(int vertex_count, int frame_count);

}  // namespace dmc
