// The encoder's closed-loop measurement: the finished stream decoded with the real decoder,
// segment by segment, and compared with the source, so the reported KG/STED are exactly those of
// `dmc decode`'s output.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "encoder/stream_writer.h"
#include "metrics/streaming_distortion.h"

namespace dmc {

// A meter for `source` with its original-only terms still to add (ScanSource adds them).
StatusOr<StreamingDistortion> CreateSourceMeter(FrameSource& source);

// Decodes `stream` (an encode of `source` with `plan`'s segments) segment by segment, maps it back
// to input vertex labels (output vertex i is input vertex relabel[i]; empty: not reordered), and
// adds each segment to `meter`, whose original terms are complete. Memory: one segment of decoded
// frames and one read block of originals with its speed window. `progress(frames done)` per
// segment. With a null `meter` the stream is only decoded (for a source whose distortion is
// undefined), and the report is empty. A stream the decoder rejects as malformed is kInternal (the
// encoder checks what it writes: a bug in it, not a damaged input); one whose requested operator
// cannot be factored is kNumericalFailure, naming the remedy.
StatusOr<DistortionReport> MeasureStream(FrameSource& source, std::span<const uint8_t> stream,
                                         const std::vector<int32_t>& relabel,
                                         const StreamPlan& plan, StreamingDistortion* meter,
                                         const std::function<void(int)>& progress);

}  // namespace dmc
