// The encoder's one driver: Encode, EncodeToFile and EncodeStreaming all run RunEncoder over a
// FrameSource into a StreamSink (memory or a staged file), so there is one pipeline, one
// relabelling and one measurement.
#include "dmc/encoder.h"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/allocation_guard.h"
#include "dmc/encoder_options.h"
#include "dmc/io.h"
#include "encoder/connectivity_encoder.h"
#include "encoder/rate_control.h"
#include "encoder/segment_pipeline.h"
#include "encoder/source_reader.h"
#include "encoder/stream_measurement.h"
#include "encoder/stream_writer.h"
#include "io/pc2_stream.h"

namespace dmc {
namespace {

// Where an encode writes its stream, in order, as it is produced.
class StreamSink {
 public:
  virtual ~StreamSink() = default;
  virtual Status Append(std::span<const uint8_t> bytes) = 0;
  virtual uint64_t size() const = 0;
  // Everything appended so far when the sink keeps it in memory, else nullptr.
  virtual const std::vector<uint8_t>* retained() const { return nullptr; }
};

class MemorySink final : public StreamSink {
 public:
  Status Append(std::span<const uint8_t> bytes) override {
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
    return Status::Ok();
  }
  uint64_t size() const override { return bytes_.size(); }
  const std::vector<uint8_t>* retained() const override { return &bytes_; }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

// A temporary file beside the destination, renamed over it by Commit.
class FileSink final : public StreamSink {
 public:
  explicit FileSink(io_internal::StagedFile file) : file_(std::move(file)) {}
  Status Append(std::span<const uint8_t> bytes) override { return file_.Append(bytes); }
  uint64_t size() const override { return file_.size(); }
  Status Commit() { return file_.Commit(); }

 private:
  io_internal::StagedFile file_;
};

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// What an encode checks before any long pass: the options, the source's counts against the
// format's limits, and frame 0 as ValidateSequence checks a sequence (triangle indices, values);
// the other frames' values are checked by the scan.
Status CheckEncodeRequest(FrameSource& source, const EncoderOptions& options,
                          const StreamingEncodeOptions& streaming) {
  DMC_RETURN_IF_ERROR(ValidateOptions(options));
  if (streaming.segments_in_flight < 1) {
    return InvalidArgumentError("segments in flight must be >= 1");
  }
  if (streaming.scene.size() > format::kMaxSceneBytes) {
    return InvalidArgumentError("the scene's " + std::to_string(streaming.scene.size()) +
                                " bytes exceed the format's 2^30");
  }
  const int v_count = source.vertex_count(), frames = source.frame_count();
  if (v_count <= 0 || frames <= 0) {
    return InvalidSequenceError(v_count <= 0 ? "the sequence has no vertices"
                                             : "the sequence has no frames");
  }
  DMC_RETURN_IF_ERROR(CheckFormatLimits(v_count, frames));
  MeshSequence first(v_count, source.triangles(), 1);
  DMC_RETURN_IF_ERROR(source.ReadFrames(0, 1, first.data()));
  return ValidateSequence(first);
}

// What one encode of a source shares across the trials of rate control.
struct EncodeJob {
  FrameSource& source;
  const ConnectivityCode& connectivity;
  const StreamingEncodeOptions& streaming;
  std::vector<uint8_t> scene_payload;  // ScenePayload(streaming.scene), compressed once

  void Progress(EncodeStage stage, int done) const {
    if (streaming.progress) streaming.progress(stage, done, source.frame_count());
  }
};

// The scan every encode starts with: finiteness, the bounding box's diagonal (the residual step
// derives from it) and, when measuring, the metrics' original-only terms.
struct SourceScan {
  double diagonal = 0.0;
  std::optional<StreamingDistortion> meter;  // original terms complete; no segment added yet
  // Why a meter was asked for but there is none: the metrics are undefined for this source.
  std::string not_measured;
};

// The scale every step derives from: the bounding box's diagonal, so that quantisation is
// relative to the sequence's own size at any scale. A sequence of one point (every vertex in
// every frame at the same place) has none: its steps derive from the point's largest coordinate
// instead, 2^-33 of it, so that the mean codes the point to 2^-51 of its size (finer than float32),
// or from 1 when the point is the origin.
double CodingScale(const BoundingBox& box) {
  const double diagonal = box.diagonal();
  if (diagonal > 0.0) return diagonal;
  const double largest = std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff());
  return largest > 0.0 ? std::ldexp(largest, -33) : 1.0;
}

// With `with_meter`, the meter; when the source's KG and STED are undefined (kInvalidSequence
// from the metrics: a frame whose vertices all coincide, say) and `meter_optional`, none, with the
// reason, so that such a sequence (degenerate but valid) still encodes.
StatusOr<SourceScan> ScanForEncode(const EncodeJob& job, bool with_meter, bool meter_optional) {
  SourceScan scan;
  auto undefined = [&](const Status& status) {
    return meter_optional && status.code() == ErrorCode::kInvalidSequence;
  };
  if (with_meter) {
    StatusOr<StreamingDistortion> meter = CreateSourceMeter(job.source);
    if (meter.ok()) {
      scan.meter = std::move(meter).value();
    } else if (undefined(meter.status())) {
      scan.not_measured = meter.status().message();
    } else {
      return meter.status();
    }
  }
  DMC_ASSIGN_OR_RETURN(const BoundingBox box,
                       ScanSource(job.source, scan.meter ? &*scan.meter : nullptr,
                                  [&](int done) { job.Progress(EncodeStage::kScan, done); }));
  if (scan.meter) {
    const Status finished = scan.meter->FinishOriginal();
    if (undefined(finished)) {
      scan.not_measured = finished.message();
      scan.meter.reset();
    } else {
      DMC_RETURN_IF_ERROR(finished);
    }
  }
  scan.diagonal = CodingScale(box);
  return scan;
}

// One encode at fixed parameters after the scan: the prefix, the segments, the end chunk, and
// with a `meter` (the scan's, or a copy of it) the decode-and-compare pass over the finished
// stream, read back from the sink when it keeps the bytes, else from a copy taken as written;
// without one but with `decode`, that pass decodes only.
Status EncodeOnce(const EncodeJob& job, const EncoderOptions& options, double diagonal,
                  StreamingDistortion* meter, bool decode, StreamSink& sink, EncodeReport& report) {
  FrameSource& source = job.source;
  DMC_ASSIGN_OR_RETURN(const StreamPlan plan, PlanStream(source.frame_count(), diagonal, options));
  report = EncodeReport();
  decode = decode || meter != nullptr;
  const bool keep_copy = decode && !sink.retained();
  std::vector<uint8_t> copy;
  auto write = [&](std::span<const uint8_t> bytes) -> Status {
    if (keep_copy) copy.insert(copy.end(), bytes.begin(), bytes.end());
    return sink.Append(bytes);
  };
  format::ChunkSizes totals;
  DMC_ASSIGN_OR_RETURN(
      const std::vector<uint8_t> prefix,
      StreamPrefix(source.vertex_count(), static_cast<int>(source.triangles().rows()),
                   source.name(), options.fps > 0 ? options.fps : source.frame_rate(), plan,
                   job.connectivity, job.scene_payload, totals));
  DMC_RETURN_IF_ERROR(write(prefix));
  DMC_RETURN_IF_ERROR(EncodeSegments(
      source, job.connectivity, options, plan, job.streaming.segments_in_flight, write,
      [&](int done) { job.Progress(EncodeStage::kEncode, done); }, totals, report));
  DMC_RETURN_IF_ERROR(write(StreamEnd(plan, totals)));
  FillRateReport(plan, source.vertex_count(), sink.size(), totals, report);
  if (decode) {
    const std::vector<uint8_t>& stream = keep_copy ? copy : *sink.retained();
    DMC_ASSIGN_OR_RETURN(
        report.distortion,
        MeasureStream(source, stream, job.connectivity.vertex_order, plan, meter,
                      [&](int done) { job.Progress(EncodeStage::kMeasure, done); }));
    report.measured = meter != nullptr;
  }
  return Status::Ok();
}

// Rate control: one scan, then SearchResidualStep's trials, each a whole encode into memory
// (measured, with a copy of the scan's meter, only for a distortion target); the last trial that
// met the target is written to `sink`, and measured afterwards when options.measure asks for it
// and the search did not. Memory: one segment's buffers plus two compressed streams. The source
// is read once to scan, then once per trial (12), twice with a distortion target.
Status EncodeWithRateSearch(const EncodeJob& job, const EncoderOptions& options, StreamSink& sink,
                            EncodeReport& report) {
  const bool measure_trials = options.target_sted > 0.0;
  DMC_ASSIGN_OR_RETURN(SourceScan scan, ScanForEncode(job, measure_trials || options.measure,
                                                      /*meter_optional=*/!measure_trials));
  std::vector<uint8_t> best;
  EncoderOptions chosen;
  DMC_RETURN_IF_ERROR(SearchResidualStep(
      options, scan.diagonal, [&](const EncoderOptions& trial_options) -> StatusOr<bool> {
        EncoderOptions trial = trial_options;
        trial.measure = measure_trials;
        std::optional<StreamingDistortion> trial_meter;
        if (measure_trials) trial_meter = *scan.meter;
        MemorySink trial_sink;
        EncodeReport trial_report;
        DMC_RETURN_IF_ERROR(EncodeOnce(job, trial, scan.diagonal,
                                       trial_meter ? &*trial_meter : nullptr, false, trial_sink,
                                       trial_report));
        const bool meets = MeetsRateTarget(options, trial_report);
        if (meets) {
          best = trial_sink.Take();
          report = trial_report;
          chosen = trial;
        }
        return meets;
      }));
  DMC_RETURN_IF_ERROR(sink.Append(best));
  report.not_measured_reason = scan.not_measured;
  if (!options.measure || report.measured) return Status::Ok();
  DMC_ASSIGN_OR_RETURN(const StreamPlan plan,
                       PlanStream(job.source.frame_count(), scan.diagonal, chosen));
  DMC_ASSIGN_OR_RETURN(report.distortion,
                       MeasureStream(job.source, best, job.connectivity.vertex_order, plan,
                                     scan.meter ? &*scan.meter : nullptr,
                                     [&](int done) { job.Progress(EncodeStage::kMeasure, done); }));
  report.measured = scan.meter.has_value();
  return Status::Ok();
}

// The driver, after CheckEncodeRequest and the connectivity (the rest of the stream uses the
// decoder's vertex labels and topology): one encode, or rate control's search.
Status RunEncoder(FrameSource& source, const ConnectivityCode& connectivity,
                  const EncoderOptions& options, const StreamingEncodeOptions& streaming,
                  StreamSink& sink, EncodeReport& report) {
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> scene_payload, ScenePayload(streaming.scene));
  const EncodeJob job{source, connectivity, streaming, std::move(scene_payload)};
  if (HasRateTarget(options)) return EncodeWithRateSearch(job, options, sink, report);
  DMC_ASSIGN_OR_RETURN(SourceScan scan,
                       ScanForEncode(job, options.measure, /*meter_optional=*/true));
  DMC_RETURN_IF_ERROR(EncodeOnce(job, options, scan.diagonal, scan.meter ? &*scan.meter : nullptr,
                                 options.measure, sink, report));
  report.not_measured_reason = scan.not_measured;
  return Status::Ok();
}

StatusOr<ConnectivityCode> EncodeSourceConnectivity(FrameSource& source,
                                                    const EncoderOptions& options) {
  return EncodeConnectivity(source.triangles(), source.vertex_count(), options.allow_reorder);
}

StatusOr<std::vector<uint8_t>> EncodeUnguarded(const MeshSequence& sequence,
                                               const EncoderOptions& options,
                                               EncodeReport* report) {
  const auto start = Clock::now();
  EncodeReport local;
  EncodeReport& out = report ? *report : local;
  out = EncodeReport();
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  SequenceFrameSource source(sequence);
  // The whole sequence is in memory already: as many segments at once as TBB has threads.
  StreamingEncodeOptions streaming;
  streaming.segments_in_flight = std::max(1, tbb::info::default_concurrency());
  DMC_RETURN_IF_ERROR(CheckEncodeRequest(source, options, streaming));
  DMC_ASSIGN_OR_RETURN(const ConnectivityCode connectivity,
                       EncodeSourceConnectivity(source, options));
  MemorySink sink;
  DMC_RETURN_IF_ERROR(RunEncoder(source, connectivity, options, streaming, sink, out));
  out.seconds = SecondsSince(start);
  return sink.Take();
}

Status EncodeStreamingUnguarded(FrameSource& source, const std::filesystem::path& output,
                                const EncoderOptions& options, EncodeReport* report,
                                const StreamingEncodeOptions& streaming) {
  const auto start = Clock::now();
  EncodeReport local;
  EncodeReport& out = report ? *report : local;
  out = EncodeReport();
  DMC_RETURN_IF_ERROR(CheckEncodeRequest(source, options, streaming));
  DMC_ASSIGN_OR_RETURN(const ConnectivityCode connectivity,
                       EncodeSourceConnectivity(source, options));
  // Created before the long passes so that an unwritable output fails at once.
  DMC_ASSIGN_OR_RETURN(io_internal::StagedFile file, io_internal::StagedFile::Create(output));
  FileSink sink(std::move(file));
  DMC_RETURN_IF_ERROR(RunEncoder(source, connectivity, options, streaming, sink, out));
  DMC_RETURN_IF_ERROR(sink.Commit());
  out.seconds = SecondsSince(start);
  return Status::Ok();
}

}  // namespace

// Memory that runs out in the encoder's passes (Eigen, CHOLMOD, TBB throw) is resource-limit.
StatusOr<std::vector<uint8_t>> Encode(const MeshSequence& sequence, const EncoderOptions& options,
                                      EncodeReport* report) {
  return core_internal::GuardAllocation("encoding",
                                        [&] { return EncodeUnguarded(sequence, options, report); });
}

Status EncodeToFile(const MeshSequence& sequence, const std::filesystem::path& output,
                    const EncoderOptions& options, EncodeReport* report) {
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, Encode(sequence, options, report));
  return WriteFileAtomically(output, bytes);
}

Status EncodeStreaming(FrameSource& source, const std::filesystem::path& output,
                       const EncoderOptions& options, EncodeReport* report,
                       const StreamingEncodeOptions& streaming) {
  return core_internal::GuardAllocation("encoding to " + output.string(), [&] {
    return EncodeStreamingUnguarded(source, output, options, report, streaming);
  });
}

Status SequenceFrameSource::ReadFrames(int first, int count, float* out) {
  if (first < 0 || count < 0 || first > sequence_.frame_count() - count) {
    return InvalidArgumentError("frames [" + std::to_string(first) + ", " +
                                std::to_string(first + count) + ") are outside the sequence's " +
                                std::to_string(sequence_.frame_count()) + " frames");
  }
  if (count > 0) {
    const size_t per_frame = static_cast<size_t>(sequence_.vertex_count()) * 3;
    std::copy_n(sequence_.frame(first).data(), per_frame * static_cast<size_t>(count), out);
  }
  return Status::Ok();
}

std::string_view EncodeStageName(EncodeStage stage) {
  switch (stage) {
    case EncodeStage::kScan:
      return "scanning";
    case EncodeStage::kEncode:
      return "encoding";
    case EncodeStage::kMeasure:
      return "measuring";
  }
  return "?";
}

}  // namespace dmc
