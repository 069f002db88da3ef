// Distortion measurement segment by segment, for the streaming encoder: the DistortionReport of
// DistortionMeter::Measure (KG, STED, RMSE, maximum error; dmc/metrics.h) accumulated so that
// neither the original nor the decoded sequence is ever whole in memory.
//
// The result is bit for bit the in-memory meter's: both run the same code of
// metrics/metrics_internal.h (AccumulateSted, AccumulateVertexErrors, AssembleReport, ...), which
// forms every sum in one fixed order whatever the segmentation; the in-memory meter is the case
// of a single segment. The only thing a segment needs beyond itself is for STED_t: te′(f, v) at a
// segment's first frame uses the decoded frame before it (kept here from the previous segment),
// and the local speed s̄(f, v) averages the original's te over [f − s + 1, f + s], so the
// original frames of a segment's measurement reach s frames beyond it on both sides
// (OriginalWindow).
//
// Use: Create; AddOriginalFrame for every original frame in order; FinishOriginal; then
// AddSegment for consecutive segments from frame 0 to the end; Report. Memory: the topology and
// neighbourhood lists of the original, one decoded frame and per-worker O(256·s) scratch, plus
// the caller's segment buffers.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "metrics/metrics_internal.h"

namespace dmc {

class StreamingDistortion {
 public:
  // `frame0` is the original's frame 0 (V × 3 floats): it defines the diameter D. `triangles`
  // are the original's (they define the edges). kInvalidArgument for bad options,
  // kInvalidSequence when there are no vertices or no frames.
  static StatusOr<StreamingDistortion> Create(const Triangles& triangles, int vertex_count,
                                              int frame_count, const float* frame0,
                                              const StedOptions& options = {});

  // First pass: every frame of the original, frames 0, 1, ..., F − 1 in this order.
  void AddOriginalFrame(const float* positions);
  // After the first pass: kInvalidSequence when STED or KG is undefined for this original (the
  // in-memory meter's errors and messages); kInternal when not every frame was added.
  Status FinishOriginal();

  // The original frames [first, second) that AddSegment needs for frames [first, first + count).
  std::pair<int, int> OriginalWindow(int first, int count) const;

  // Second pass, segments in frame order from frame 0 without gaps. `original` holds the
  // original frames of OriginalWindow(first, count); `decoded` the segment's decoded frames
  // (count × V × 3, in the original's vertex order). kInvalidSequence for a non-finite decoded
  // coordinate, kInvalidArgument for a segment out of order.
  Status AddSegment(int first, int count, const float* original, const float* decoded);

  // After the last segment: the report DistortionMeter::Measure gives for the whole sequences.
  // kInternal before the last segment.
  StatusOr<DistortionReport> Report() const;

 private:
  StreamingDistortion() = default;

  int vertex_count_ = 0;
  int frame_count_ = 0;
  metrics_internal::StedReference sted_;  // edges, neighbourhoods N(v), D
  // Original-only quantities (first pass).
  int original_frames_seen_ = 0;
  BoundingBox box_;
  metrics_internal::KgReference kg_;  // complete after FinishOriginal
  // Accumulated over segments (second pass).
  int next_frame_ = 0;
  metrics_internal::StedSums sted_sums_;
  metrics_internal::VertexErrorSums error_sums_;
  std::vector<float> previous_decoded_;  // the last decoded frame of the previous segment
};

}  // namespace dmc
