// The segments of one encode through a read → encode → write pipeline: read in order (serial),
// encoded concurrently (at most `segments_in_flight` at once), written in order (serial), so the
// bytes do not depend on the concurrency.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include "bitstream/format.h"
#include "dmc/encoder.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/stream_writer.h"

namespace dmc {

// Encodes every segment of `plan` from `source` and hands each segment's bytes to `write` in
// segment order, adding its sizes to `totals` and its operator, rank and anchors to `report`.
// `progress(frames done)` after each written segment. Stops at the first failure (of a read, an
// encode or `write`) and returns it.
Status EncodeSegments(FrameSource& source, const ConnectivityCode& connectivity,
                      const EncoderOptions& options, const StreamPlan& plan, int segments_in_flight,
                      const std::function<Status(std::span<const uint8_t>)>& write,
                      const std::function<void(int)>& progress, format::ChunkSizes& totals,
                      EncodeReport& report);

}  // namespace dmc
