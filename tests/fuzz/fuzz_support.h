// Shared helpers of the fuzz targets.
//
// DeclaredSizesAreSmall() pre-screens a .dmc input the way a service with a memory budget would:
// the format lets a few hundred bytes declare up to 16 GiB of output (spec §6.2), which a decoder
// allocates legitimately. Fuzzing such inputs only measures the machine's memory, so the decode
// targets skip streams whose sequence header declares more than a small budget; everything else
// (every container, connectivity and segment path) is exercised in full.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <span>

#include "bitstream/format.h"
#include "decoder/syntax_reader.h"
#include "dmc/status.h"
#include "entropy/byte_io.h"

namespace dmc::fuzz {

inline constexpr uint64_t kMaxFuzzVertices = 1 << 16;
inline constexpr uint64_t kMaxFuzzPositionValues = 1 << 22;  // 16 MB of float32 output

// True when the stream is not a .dmc stream at all (the decoder rejects it cheaply) or when its
// sequence header declares a mesh within the fuzzing budget.
inline bool DeclaredSizesAreSmall(std::span<const uint8_t> stream) {
  ByteReader reader(stream);
  std::span<const uint8_t> preamble;
  uint8_t type = 0;
  uint64_t size = 0;
  std::span<const uint8_t> payload;
  if (!reader.GetBytes(7, &preamble, "").ok() || !reader.GetU8(&type, "").ok() ||
      !reader.GetVarU(&size, "").ok() || size > reader.remaining() ||
      !reader.GetBytes(static_cast<size_t>(size), &payload, "").ok()) {
    return true;
  }
  const StatusOr<format::SequenceHeader> header = syntax::ReadSequenceHeader(payload);
  if (!header.ok()) return true;
  return header->vertex_count <= kMaxFuzzVertices &&
         uint64_t{header->vertex_count} * header->frame_count * 3 <= kMaxFuzzPositionValues;
}

// Stops the fuzzer with a crash report (an invariant of a successful result was broken).
[[noreturn]] inline void InvariantBroken() { std::abort(); }

}  // namespace dmc::fuzz
