// Shared helpers of the fuzz targets (and of the allocation-bound test, which damages streams the
// same way).
//
// kFuzzDecoderOptions bound what a decode target lets a stream claim the way a service with a
// memory budget would: the format lets a few hundred bytes declare up to 16 GiB of output
// (spec §6.2), which a decoder allocates legitimately. The decoder itself refuses such streams
// (resource-limit, before anything is sized by them), so every input runs in full, and
// tools/fuzz.sh's -rss_limit_mb proves that nothing else grows out of proportion.
//
// RepairChecksums() rewrites the checksum of every chunk a (possibly damaged) stream frames, so a
// mutation reaches the payload decoders instead of stopping at the checksum check.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/status.h"
#include "dmc/wire_ids.h"
#include "entropy/byte_io.h"

namespace dmc::fuzz {

inline constexpr DecoderOptions kFuzzDecoderOptions{.max_output_bytes = uint64_t{16} << 20,
                                                    .max_matrix_bytes = uint64_t{32} << 20};

// The sequence header of the stream's first chunk when it frames and parses (its checksum is not
// verified: this is what the stream claims, not what a decoder accepts); nullopt otherwise.
inline std::optional<format::SequenceHeader> DeclaredSequenceHeader(
    std::span<const uint8_t> stream) {
  ByteReader reader(stream);
  std::span<const uint8_t> preamble;
  uint8_t type = 0;
  uint64_t size = 0;
  std::span<const uint8_t> payload;
  if (!reader.GetBytes(7, &preamble, "").ok() || !reader.GetU8(&type, "").ok() ||
      !reader.GetVarU(&size, "").ok() || size > reader.remaining() ||
      !reader.GetBytes(static_cast<size_t>(size), &payload, "").ok()) {
    return std::nullopt;
  }
  StatusOr<format::SequenceHeader> header = syntax::ReadSequenceHeader(payload);
  if (!header.ok()) return std::nullopt;
  return *std::move(header);
}

// A copy of the stream with every framed chunk's checksum recomputed; bytes that do not frame as
// chunks (a damaged preamble, a size running past the end) are kept as they are.
inline std::vector<uint8_t> RepairChecksums(std::span<const uint8_t> stream) {
  std::vector<uint8_t> repaired(stream.begin(), stream.end());
  ByteReader reader(stream);
  std::span<const uint8_t> preamble;
  if (!reader.GetBytes(7, &preamble, "").ok()) return repaired;
  while (!reader.at_end()) {
    uint8_t type = 0;
    uint64_t size = 0;
    std::span<const uint8_t> payload;
    if (!reader.GetU8(&type, "").ok() || !reader.GetVarU(&size, "").ok() ||
        size > reader.remaining() ||
        !reader.GetBytes(static_cast<size_t>(size), &payload, "").ok() || reader.remaining() < 4) {
      break;
    }
    const uint32_t checksum = format::ChunkChecksum(type, payload, preamble[5]);
    for (int i = 0; i < 4; ++i) {
      repaired[reader.position() + i] = static_cast<uint8_t>(checksum >> (8 * i));
    }
    uint32_t ignored = 0;
    (void)reader.GetU32(&ignored, "");
    if (type == static_cast<uint8_t>(ChunkType::kEnd)) break;
  }
  return repaired;
}

// Stops the fuzzer with a crash report (an invariant of a successful result was broken).
[[noreturn]] inline void InvariantBroken() { std::abort(); }
// The same, saying which invariant broke (printed before the abort, so it is in the crash log).
[[noreturn]] inline void InvariantBroken(const std::string& what) {
  std::fprintf(stderr, "invariant broken: %s\n", what.c_str());
  std::abort();
}

// What every mesh-file parser promises of a result it accepts: whole xyz triples and triangles,
// and corners that index its vertices.
template <typename MeshFile>
void CheckParsedMesh(const MeshFile& mesh) {
  if (mesh.positions.size() % 3 != 0 || mesh.triangles.size() % 3 != 0) InvariantBroken();
  for (const int32_t v : mesh.triangles) {
    if (v < 0 || v >= mesh.vertex_count()) InvariantBroken();
  }
}

}  // namespace dmc::fuzz
