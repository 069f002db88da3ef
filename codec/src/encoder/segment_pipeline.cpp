#include "encoder/segment_pipeline.h"

#include <tbb/parallel_pipeline.h>

#include <atomic>
#include <memory>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "encoder/segment_encoder.h"
#include "encoder/source_reader.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace {

// One segment travelling through the pipeline.
struct SegmentWork {
  int index = 0;
  Status read = Status::Ok();
  SegmentTrajectories trajectories;
  ByteWriter bytes;
  StatusOr<SegmentResult> result = InternalError("not encoded");
};

}  // namespace

Status EncodeSegments(FrameSource& source, const ConnectivityCode& connectivity,
                      const EncoderOptions& options, const StreamPlan& plan, int segments_in_flight,
                      const std::function<Status(std::span<const uint8_t>)>& write,
                      const std::function<void(int)>& progress, format::ChunkSizes& totals,
                      EncodeReport& report) {
  const MeshTopology topology = BuildTopology(connectivity.triangles, source.vertex_count());
  const std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  const SegmentEncoder encoder(topology, connectivity.triangles, vertex_order, options,
                               plan.operator_id, plan.diagonal, plan.residual_step);
  Status failure = Status::Ok();
  std::atomic<bool> failed{false};
  int next_segment = 0;
  auto read = [&](tbb::flow_control& control) -> std::shared_ptr<SegmentWork> {
    if (failed.load() || next_segment == plan.segments()) {
      control.stop();
      return nullptr;
    }
    auto work = std::make_shared<SegmentWork>();
    work->index = next_segment++;
    work->read = ReadSegmentTrajectories(source, plan.segment_first[work->index],
                                         plan.segment_frames(work->index),
                                         connectivity.vertex_order, work->trajectories);
    return work;
  };
  auto encode = [&](std::shared_ptr<SegmentWork> work) {
    if (!work->read.ok()) {
      work->result = work->read;
    } else if (!failed.load()) {
      work->result = encoder.Encode(std::move(work->trajectories), plan.segment_first[work->index],
                                    work->bytes);
    }
    work->trajectories = SegmentTrajectories();  // free before the write stage
    return work;
  };
  auto store = [&](std::shared_ptr<SegmentWork> work) {
    if (failed.load()) return;
    Status status = work->result.status();
    if (status.ok()) status = write(work->bytes.bytes());
    if (!status.ok()) {
      failure = status;
      failed.store(true);
      return;
    }
    RecordSegment(*work->result, work->index, plan.segment_first[work->index],
                  plan.segment_frames(work->index), totals, &report);
    progress(plan.segment_first[work->index + 1]);
  };
  using WorkPtr = std::shared_ptr<SegmentWork>;
  tbb::parallel_pipeline(
      static_cast<size_t>(segments_in_flight),
      tbb::make_filter<void, WorkPtr>(tbb::filter_mode::serial_in_order, read) &
          tbb::make_filter<WorkPtr, WorkPtr>(tbb::filter_mode::parallel, encode) &
          tbb::make_filter<WorkPtr, void>(tbb::filter_mode::serial_in_order, store));
  return failure;
}

}  // namespace dmc
