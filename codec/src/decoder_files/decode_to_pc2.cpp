// DecodeToPc2 (declared in dmc/decoder.h): the decoder's segments streamed into a PC2 cache and
// its connectivity mesh, in a library of its own (dmc_decoder_files) above dmc_decoder and dmc_io
// so that the decoder itself links no file-format code.
#include <tbb/parallel_pipeline.h>

#include <atomic>
#include <memory>
#include <vector>

#include "core/allocation_guard.h"
#include "dmc/decoder.h"
#include "io/pc2_stream.h"

namespace dmc {
namespace {

Status DecodeToPc2Unguarded(std::span<const uint8_t> stream, const std::filesystem::path& output,
                            const DecodeProgressCallback& progress, int segments_in_flight,
                            const DecoderOptions& options) {
  if (segments_in_flight < 1) return InvalidArgumentError("segments in flight must be >= 1");
  Decoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Open(stream, options));
  const StreamInfo& info = decoder.info();
  DMC_ASSIGN_OR_RETURN(
      io_internal::Pc2PairWriter writer,
      io_internal::Pc2PairWriter::Create(output, info.vertex_count, info.frame_count,
                                         decoder.triangles(), info.frame_rate));
  struct SegmentFrames {
    int index = 0;
    Status status = Status::Ok();
    std::vector<float> frames;  // allocated only once the segment has decoded and solved
  };
  const size_t per_frame = static_cast<size_t>(info.vertex_count) * 3;
  Status failure = Status::Ok();
  std::atomic<bool> failed{false};
  int next_segment = 0;
  // Decode (parallel, at most segments_in_flight at once) -> write (serial, in frame order).
  tbb::parallel_pipeline(
      static_cast<size_t>(segments_in_flight),
      tbb::make_filter<void, std::shared_ptr<SegmentFrames>>(
          tbb::filter_mode::serial_in_order,
          [&](tbb::flow_control& control) -> std::shared_ptr<SegmentFrames> {
            if (failed.load() || next_segment == decoder.segment_count()) {
              control.stop();
              return nullptr;
            }
            auto work = std::make_shared<SegmentFrames>();
            work->index = next_segment++;
            return work;
          }) &
          tbb::make_filter<std::shared_ptr<SegmentFrames>, std::shared_ptr<SegmentFrames>>(
              tbb::filter_mode::parallel,
              [&](std::shared_ptr<SegmentFrames> work) {
                if (failed.load()) return work;
                work->status =
                    decoder.DecodeSegmentInto(work->index, [&](int s) -> StatusOr<float*> {
                      work->frames.resize(per_frame *
                                          static_cast<size_t>(info.segments[s].frame_count));
                      return work->frames.data();
                    });
                return work;
              }) &
          tbb::make_filter<std::shared_ptr<SegmentFrames>, void>(
              tbb::filter_mode::serial_in_order, [&](std::shared_ptr<SegmentFrames> work) {
                if (failed.load()) return;
                Status status = work->status;
                if (status.ok()) {
                  status = writer.AppendFrames(work->frames.data(),
                                               info.segments[work->index].frame_count);
                }
                if (!status.ok()) {
                  failure = status;
                  failed.store(true);
                  return;
                }
                work->frames = {};
                if (progress) progress(writer.frames_written(), info.frame_count);
              }));
  DMC_RETURN_IF_ERROR(failure);
  return writer.Commit();
}

}  // namespace

Status DecodeToPc2(std::span<const uint8_t> stream, const std::filesystem::path& output,
                   const DecodeProgressCallback& progress, int segments_in_flight,
                   const DecoderOptions& options) {
  // The pipeline's buffers and the writer allocate outside the decoder's own guards; the
  // writer's temporaries are removed as the exception unwinds.
  return core_internal::GuardAllocation("decoding to " + output.string(), [&] {
    return DecodeToPc2Unguarded(stream, output, progress, segments_in_flight, options);
  });
}

}  // namespace dmc
