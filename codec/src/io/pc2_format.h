// Internal: PC2 point caches (Blender / 3ds Max / Maya "POINTCACHE2").
//
// Layout, little-endian: char[12] "POINTCACHE2\0", int32 version (1), int32 numPoints,
// float32 startFrame, float32 sampleRate, int32 numSamples, then numSamples x numPoints x
// float32[3]. startFrame and sampleRate are in the authoring tool's time unit, normally scene
// frames: sampleRate is the spacing of two samples (1 = one sample per frame), not a rate in Hz.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc::io_internal {

struct Pc2Header {
  int32_t point_count = 0;
  float start_frame = 0.0f;
  float sample_rate = 1.0f;
  int32_t sample_count = 0;
};

inline constexpr size_t kPc2HeaderBytes = 32;

// Little-endian 32-bit words, the byte order of every PC2 field and sample.
inline uint32_t LoadLittleEndian32(const uint8_t* bytes) {
  return static_cast<uint32_t>(bytes[0]) | static_cast<uint32_t>(bytes[1]) << 8 |
         static_cast<uint32_t>(bytes[2]) << 16 | static_cast<uint32_t>(bytes[3]) << 24;
}
inline void StoreLittleEndian32(uint32_t value, uint8_t* out) {
  for (int k = 0; k < 4; ++k) out[k] = static_cast<uint8_t>(value >> (8 * k));
}

// The header dmc writes: version 1, startFrame 0, sampleRate 1 (one sample per frame).
std::array<uint8_t, kPc2HeaderBytes> EncodePc2Header(int point_count, int sample_count);

// Parses and checks a header against the size of the file it came from: the declared samples
// must fill the file exactly (kParseError naming both sizes otherwise), version must be 1
// (kUnsupported).
StatusOr<Pc2Header> ParsePc2Header(const uint8_t* bytes, size_t size, uint64_t file_size);

// Reads and checks the header of `path`.
StatusOr<Pc2Header> ReadPc2Header(const std::filesystem::path& path);

// The whole cache for a sequence: startFrame 0, sampleRate 1, one sample per frame.
std::string EncodePc2(const MeshSequence& sequence);

}  // namespace dmc::io_internal
