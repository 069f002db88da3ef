// Fuzz target: container and header parsing without reconstruction (dmc::ReadStreamInfo).
// A result must describe segments that tile the declared frames.
#include <cstddef>
#include <cstdint>
#include <span>

#include "dmc/decoder.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> stream(data, size);
  const dmc::StatusOr<dmc::StreamInfo> info = dmc::ReadStreamInfo(stream);
  if (!info.ok()) return 0;
  int next_frame = 0;
  for (const dmc::SegmentInfo& segment : info->segments) {
    if (segment.first_frame != next_frame || segment.frame_count < 1) {
      dmc::fuzz::InvariantBroken();
    }
    next_frame += segment.frame_count;
  }
  if (next_frame != info->frame_count || info->total_bytes != size) dmc::fuzz::InvariantBroken();
  return 0;
}
