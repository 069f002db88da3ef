// The streaming encoder's distortion measurement: the DistortionReport of
// DistortionMeter::Measure (KG, STED, RMSE, maximum error; dmc/metrics.h) accumulated segment by
// segment, so that neither the original nor the decoded sequence is ever whole in memory.
//
// Every figure accumulates exactly across segments, and the result is bit for bit the in-memory
// meter's, because every sum is formed in the same order:
//  - KG's denominator ‖A − E(A)‖² and the squared error ‖A − A′‖² are sums of per-frame sums
//    added in frame order; the bounding box and the maximum error are extrema.
//  - STED_s is a sum of per-frame sums Σ_v dev(v) added in frame order.
//  - STED_t needs more than the segment: te′(f, v) at a segment's first frame uses the decoded
//    frame before it (kept from the previous segment), and the local speed s̄(f, v) averages the
//    original's te over [f − s + 1, f + s], so the original frames of a segment's measurement
//    reach s frames beyond it on both sides (OriginalWindow). The in-memory meter sums the terms
//    per block of 256 vertices in frame order and then the blocks in order; here each block's sum
//    persists across segments, so the additions happen in the same order.
// The per-frame and per-term formulas repeat src/metrics/sted.cpp and kg.cpp expression for
// expression (they are internal to dmc_metrics); tests/unit/codec/streaming_encode_test.cpp
// checks the equality, so a change on one side that is not made on the other fails there.
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
  // are the original's (they define the edges). kInvalidArgument for bad options.
  static StatusOr<StreamingDistortion> Create(const Triangles& triangles, int vertex_count,
                                              int frame_count, const float* frame0,
                                              const StedOptions& options = {});

  // First pass: every frame of the original, frames 0, 1, ..., F − 1 in this order.
  void AddOriginalFrame(const float* positions);
  // After the first pass: kInvalidSequence when STED or KG is undefined for this original (the
  // in-memory meter's errors and messages).
  Status FinishOriginal();

  // The original frames [first, second) that AddSegment needs for frames [first, first + count).
  std::pair<int, int> OriginalWindow(int first, int count) const;

  // Second pass, segments in frame order from frame 0 without gaps. `original` holds the
  // original frames of OriginalWindow(first, count); `decoded` the segment's decoded frames
  // (count × V × 3, in the original's vertex order). kInvalidSequence for a non-finite decoded
  // coordinate, kInvalidArgument for a segment out of order.
  Status AddSegment(int first, int count, const float* original, const float* decoded);

  // After the last segment: the report DistortionMeter::Measure gives for the whole sequences.
  StatusOr<DistortionReport> Report() const;

 private:
  StreamingDistortion() = default;

  int vertex_count_ = 0;
  int frame_count_ = 0;
  metrics_internal::StedReference sted_;  // edges, neighbourhoods N(v), D
  int64_t window_ = 1;                    // s, capped at F as the in-memory meter does
  // Original-only quantities (first pass).
  int original_frames_seen_ = 0;
  double centroid_deviation_squared_ = 0.0;  // ‖A − E(A)‖²
  BoundingBox box_;
  // Accumulated over segments (second pass).
  int next_frame_ = 0;
  double spatial_total_ = 0.0;
  std::vector<double> temporal_block_sums_;
  double squared_error_sum_ = 0.0;
  double largest_squared_error_ = 0.0;
  std::vector<float> previous_decoded_;  // the last decoded frame of the previous segment
};

}  // namespace dmc
